#!/usr/bin/env bash
# render_bound_test.sh CRISP_RENDER CRISP_BAKE SOURCE_DIR WORK_DIR BARS_FONT: crisp-render's run is
# bounded (issue 28, item 14): small hostile inputs that took minutes to converge on lavapipe stop
# at --max-seconds or --max-frames, write what they have and say so, with exit 0. BARS_FONT is
# make_many_curves_font.py's 'H' of 1024 full-height bars (2048 curves in every band).
set -uo pipefail
render=$1 bake=$2 source=$3 work=$4 bars_font=$5
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
export PYTHONPATH="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)${PYTHONPATH:+:$PYTHONPATH}"

"$bake" "$source/fonts/DejaVuSans.ttf" --text "HeloW" -o dejavu.crisp -q || { echo "crisp-bake failed" >&2; exit 1; }
"$bake" "$bars_font" --text "H" -o bars.crisp -q || { echo "crisp-bake of the bars font failed" >&2; exit 1; }

# ---- Usage errors: exit 2 before any work.
small=(--font dejavu.crisp --text Hi --size 20 --origin 4,24 --canvas 48,32 --samples 16)
for value in -1 86401 abc; do
  expect_exit 2 "--max-seconds $value" -- "$render" "${small[@]}" -o x.png --max-seconds "$value"
  expect_stderr "--max-seconds" "--max-seconds $value"
done
for value in 0 100001; do
  expect_exit 2 "--max-frames $value" -- "$render" "${small[@]}" -o x.png --max-frames "$value"
  expect_stderr "--max-frames" "--max-frames $value"
done
expect_exit 0 "--help" -- "$render" --help
grep -q -- "--max-seconds S" out || fail "--help does not describe --max-seconds"
grep -q -- "--max-frames" out || fail "--help does not describe --max-frames"

# check_stopped REPORT REASON FRAMES_AT_MOST PNG: the JSON report says rendering stopped for REASON,
# short of convergence, after at most FRAMES_AT_MOST frames (0: any), with a sample in every drawn
# glyph, and the PNG (unless "-": a large one is slow to decode in Python) holds ink.
check_stopped() {
  python3 - "$@" <<'PY' || fail "report of $1: see above"
import json, sys
from read_png import read_png
report, reason, most, png = json.load(open(sys.argv[1])), sys.argv[2], int(sys.argv[3]), sys.argv[4]
problems = []
if report["converged"] or report["stopped"] != reason:
    problems.append(f"converged {report['converged']}, stopped {report['stopped']!r}, want {reason!r}")
if most and report["frames"] > most:
    problems.append(f"{report['frames']} frames, want at most {most}")
if report["samples"]["min"] < 1 or report["samples"]["converged_glyphs"] >= report["samples"]["glyphs"]:
    problems.append(f"samples {report['samples']}: want every drawn glyph with a sample and some short")
if png != "-" and min(read_png(png)[3]) > 200:
    problems.append(f"{png} holds no ink")
for p in problems:
    print(f"{sys.argv[1]}: {p}", file=sys.stderr)
sys.exit(1 if problems else 0)
PY
}

# ---- One 4096-curve glyph at 48 px on 40x44 (89 s to converge before; 200 s on a loaded machine).
bars=(--font bars.crisp --text H --size 48 --origin 0,40 --canvas 40,44)
expect_exit 0 "the bars glyph with --max-seconds 1" -- timeout 60 "$render" "${bars[@]}" -o bars.png --max-seconds 1 --json
cp out bars.json
expect_stderr "crisp-render: warning: stopped after" "the bars glyph with --max-seconds 1"
expect_stderr "0 of 1 glyphs converged; --max-seconds to change" "the bars glyph with --max-seconds 1"
check_stopped bars.json max-seconds 0 bars.png
# The same with -q: no warning, the same exit.
expect_exit 0 "the bars glyph with --max-seconds 1 -q" -- timeout 60 "$render" "${bars[@]}" -o bars-q.png --max-seconds 1 -q
[ -s err ] && fail "-q still warns: $(head -c 300 err)"
# A frame budget bounds each frame; --max-frames gives the same partial image every time.
expect_exit 0 "the bars glyph with --max-frames 2" -- timeout 60 "$render" "${bars[@]}" -o frames-a.png --max-frames 2 --json
cp out frames.json
expect_stderr "stopped after 2 frames" "the bars glyph with --max-frames 2"
expect_stderr "--max-frames to change" "the bars glyph with --max-frames 2"
check_stopped frames.json max-frames 2 frames-a.png
expect_exit 0 "the bars glyph with --max-frames 2, again" -- timeout 60 "$render" "${bars[@]}" -o frames-b.png --max-frames 2 -q
cmp -s frames-a.png frames-b.png || fail "--max-frames 2 gave two different images"
# A reference mode whose first composite frame ends past the limit is read back from that frame.
expect_exit 0 "the bars glyph, exact, --max-seconds 0.5" -- timeout 60 "$render" "${bars[@]}" -o exact.png \
  --composite exact --max-seconds 0.5 --json
cp out exact.json
check_stopped exact.json max-seconds 0 exact.png

# ---- One 'W' at 2000 px on a 2048x2048 canvas (over 300 s before).
expect_exit 0 "a 2000 px W with --max-seconds 2" -- timeout 60 "$render" --font dejavu.crisp --text W --size 2000 \
  --origin 0,1800 --canvas 2048,2048 -o w.png --max-seconds 2 --json
cp out w.json
check_stopped w.json max-seconds 0 -

# ---- A scene of 2000 runs of "Hello" at distinct subpixel offsets (137 s before).
python3 - <<'PY'
import json
runs = [{"text": "Hello", "size": 16, "origin": [4 + (i % 20) * 50 + (i % 256) / 256, 20 + (i // 20 % 50) * 20 + i // 256 / 256]}
        for i in range(2000)]
json.dump({"fonts": ["dejavu.crisp"], "canvas": [1024, 1024], "runs": runs}, open("hello-2000.json", "w"))
PY
expect_exit 0 "2000 runs of Hello with --max-seconds 2" -- timeout 60 "$render" --scene hello-2000.json -o hello.png \
  --max-seconds 2 --json
cp out hello.json
check_stopped hello.json max-seconds 0 hello.png

# ---- Text that converges in time says nothing and reports no stop; --max-seconds 0 is no limit.
for limit in 30 0; do
  expect_exit 0 "small text with --max-seconds $limit" -- timeout 60 "$render" "${small[@]}" -o small.png \
    --max-seconds "$limit" --json
  [ -s err ] && fail "small text with --max-seconds $limit warns: $(head -c 300 err)"
  python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); sys.exit(not (r["converged"] and r["stopped"] is None))' \
    out || fail "small text with --max-seconds $limit: not converged: $(head -c 300 out)"
done

[ "$failures" -eq 0 ] || { echo "$failures failures" >&2; exit 1; }
echo "all crisp-render bound checks passed"
