#!/usr/bin/env bash
# render_cli_test.sh CRISP_RENDER CRISP_BAKE SOURCE_DIR WORK_DIR: crisp-render's exit codes and
# its refusal of bad input (no GPU needed), then one end-to-end render on whatever Vulkan device
# there is (lavapipe in CI): PNG, coverage PFM and --json.
set -uo pipefail
render=$1 bake=$2 source=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
expect_exit() {  # expect_exit CODE DESCRIPTION -- COMMAND...
  local want=$1 what=$2; shift 3
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  [ "$got" -eq "$want" ] || fail "$what: exit $got, want $want; stderr: $(head -c 400 "$work/err")"
}
expect_stderr() {  # expect_stderr TEXT DESCRIPTION: the last command's stderr holds TEXT
  grep -qF -- "$1" "$work/err" || fail "$2: stderr lacks '$1': $(head -c 400 "$work/err")"
}

"$bake" "$source/fonts/DejaVuSans.ttf" --text "Hi" -o "$work/dejavu.crisp" -q || { echo "crisp-bake failed" >&2; exit 1; }
font=$work/dejavu.crisp
# Everything a render needs but the output; each check below changes one thing.
base=(--font "$font" --text "Hi" --size 20 --origin 4.25,24.5 --canvas 48,32 --samples 16)

# ---- Usage errors: exit 2, before any file or GPU is touched.
expect_exit 0 "--help" -- "$render" --help
grep -q "exit codes" "$work/out" || fail "--help does not list the exit codes"
expect_exit 2 "no arguments" -- "$render"
expect_exit 2 "unknown option" -- "$render" "${base[@]}" -o x.png --frobnicate
expect_exit 2 "stray argument" -- "$render" "${base[@]}" -o x.png extra
expect_exit 2 "option without its value" -- "$render" "${base[@]}" -o
expect_exit 2 "no font" -- "$render" --text Hi --size 20 --origin 0,20 --canvas 48,32 -o x.png
expect_stderr "--font" "no font"
expect_exit 2 "no text" -- "$render" --font "$font" --size 20 --origin 0,20 --canvas 48,32 -o x.png
expect_exit 2 "no size" -- "$render" --font "$font" --text Hi --origin 0,20 --canvas 48,32 -o x.png
expect_exit 2 "no origin" -- "$render" --font "$font" --text Hi --size 20 --canvas 48,32 -o x.png
expect_exit 2 "no canvas" -- "$render" --font "$font" --text Hi --size 20 --origin 0,20 -o x.png
expect_exit 2 "no output" -- "$render" "${base[@]}"
for size in 0 -3 4096.5 1e9 abc nan inf ""; do
  expect_exit 2 "--size '$size'" -- "$render" "${base[@]}" --size "$size" -o x.png
done
for canvas in 0,32 48,0 16385,32 48 48,32,1 -1,32 a,b 48.5,32; do
  expect_exit 2 "--canvas $canvas" -- "$render" "${base[@]}" --canvas "$canvas" -o x.png
done
for origin in inf,0 0,nan 1 1,2,3 x,1; do
  expect_exit 2 "--origin $origin" -- "$render" "${base[@]}" --origin "$origin" -o x.png
done
for samples in 0 1024 -1 1.5; do
  expect_exit 2 "--samples $samples" -- "$render" "${base[@]}" --samples "$samples" -o x.png
done
for colour in 1.5,0,0 255,0,0 -0.1,0,0 1,0 1,0,0,0,1 1,0,0,2 red; do
  expect_exit 2 "--color $colour" -- "$render" "${base[@]}" --color "$colour" -o x.png
  expect_exit 2 "--background $colour" -- "$render" "${base[@]}" --background "$colour" -o x.png
done
seventeen=()
for _ in $(seq 17); do seventeen+=(--font "$font"); done
expect_exit 2 "17 fonts" -- "$render" "${seventeen[@]}" --text Hi --size 20 --origin 0,20 --canvas 48,32 -o x.png
expect_exit 2 "one file for both outputs" -- "$render" "${base[@]}" -o same.out --coverage-out ./same.out

# ---- Outputs that cannot be written: exit 4, checked before rendering.
expect_exit 4 "output directory missing" -- "$render" "${base[@]}" -o "$work/no/such/dir/x.png"
expect_stderr "no/such/dir" "output directory missing"
expect_exit 4 "coverage directory missing" -- "$render" "${base[@]}" -o x.png --coverage-out "$work/none/x.pfm"
mkdir -p "$work/a-directory.png"
expect_exit 4 "output is a directory" -- "$render" "${base[@]}" -o "$work/a-directory.png"

# ---- Fonts that cannot be loaded: exit 3, with the loader's message.
expect_exit 3 "missing font" -- "$render" "${base[@]}" --font "$work/missing.crisp" -o x.png
expect_stderr "missing.crisp" "missing font"
head -c 5000 /dev/urandom >"$work/noise.crisp"
expect_exit 3 "noise as a font" -- "$render" "${base[@]}" --font "$work/noise.crisp" -o x.png
expect_exit 3 "a .ttf, not an asset" -- "$render" "${base[@]}" --font "$source/fonts/DejaVuSans.ttf" -o x.png
head -c 1000 "$font" >"$work/truncated.crisp"
expect_exit 3 "truncated asset" -- "$render" "${base[@]}" --font "$work/truncated.crisp" -o x.png
expect_stderr "truncated" "truncated asset"

# ---- Bad subpixel layouts: exit 6.
expect_exit 6 "unknown layout" -- "$render" "${base[@]}" --layout no-such-layout -o x.png
printf '{"r": [0, 0, 0.5, 1], "g": [0.5, 0, 0.25, 1], "b": [0, 0, 1, 1]}' >"$work/inverted.json"
expect_exit 6 "inverted layout rectangle" -- "$render" "${base[@]}" --layout "$work/inverted.json" -o x.png
expect_stderr "g" "inverted layout rectangle"
printf '{"r": [0, 0' >"$work/broken.json"
expect_exit 6 "broken layout JSON" -- "$render" "${base[@]}" --layout "$work/broken.json" -o x.png
[ ! -e "$work/x.png" ] || fail "a failed run wrote an output"

# ---- No Vulkan driver, or no device of that name: exit 5 naming it.
VK_ICD_FILENAMES=$work/none.json VK_DRIVER_FILES=$work/none.json \
  expect_exit 5 "no Vulkan driver" -- "$render" "${base[@]}" -o x.png
expect_exit 5 "no such device" -- "$render" "${base[@]}" --device "no such device 42" -o x.png
expect_stderr "no such device 42" "no such device"

# ---- End to end: "Hi" at 20 px on a 48x32 canvas.
expect_exit 0 "render" -- "$render" "${base[@]}" -o "$work/hi.png" --coverage-out "$work/hi.pfm" --json
cp "$work/out" "$work/hi.json"
python3 - "$work" <<'PY' || fail "the render's outputs are wrong"
import json, struct, sys
work = sys.argv[1]
report = json.load(open(work + "/hi.json"))
assert report["frames"] > 1 and report["converged"], report
assert report["samples"] == {"target": 16, "min": 16, "max": 16}, report["samples"]
assert report["glyphs"]["drawn"] == 2 and report["glyphs"]["failed"] == 0, report["glyphs"]
assert report["canvas"] == {"width": 48, "height": 32}, report["canvas"]
assert len(report["timings"]["frame_ms"]) == report["frames"], report["timings"]
assert report["total_samples"] >= 2 * 16 and report["layout"] == "rgb", report
assert report["device"]["name"] and report["outputs"]["png"].endswith("hi.png"), report

png = open(work + "/hi.png", "rb").read()
assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
width, height, depth, colour = struct.unpack(">IIBB", png[16:26])
assert (width, height, depth, colour) == (48, 32, 8, 2), (width, height, depth, colour)
assert b"sRGB" in png, "no sRGB chunk"

pfm = open(work + "/hi.pfm", "rb").read()
magic, size, scale, data = pfm.split(b"\n", 3)
assert magic == b"PF" and size == b"48 32" and float(scale) < 0, pfm[:20]
assert len(data) == 48 * 32 * 3 * 4, len(data)
values = struct.unpack("<%df" % (48 * 32 * 3), data)
rows = [values[r * 48 * 3:(r + 1) * 48 * 3] for r in range(32)][::-1]  # the file's rows run bottom to top
pixel = lambda x, y: rows[y][x * 3:x * 3 + 3]
assert all(0.0 <= v <= 1.0 for v in values), "coverage outside [0, 1]"
assert sum(1 for v in values if v > 0.5) > 50, "too little coverage"
for x, y in ((0, 0), (47, 0), (0, 31), (47, 31)):
    assert pixel(x, y) == (0.0, 0.0, 0.0), (x, y, pixel(x, y))
# The baseline is at y = 24.5: the H's stems reach it and stop there, so the row below is empty and
# the row the baseline cuts is about half covered.
assert max(max(pixel(x, 25)) for x in range(48)) == 0.0, "coverage below the baseline"
stem_row = [max(pixel(x, 24)) for x in range(48)]
assert 0.4 < max(stem_row) < 0.6, stem_row
PY
[ -z "$(ls -A "$work" | grep -F '.tmp')" ] || fail "temporary files were left behind"

# The human summary goes to stdout, nothing to stderr.
expect_exit 0 "render without --json" -- "$render" "${base[@]}" -o "$work/hi2.png"
grep -q "frames" "$work/out" || fail "no summary on stdout"
[ ! -s "$work/err" ] || fail "a good run wrote to stderr: $(head -c 400 "$work/err")"

# With the validation layer (when installed), a clean run stays clean.
if [ -n "$(find /usr/share/vulkan /etc/vulkan -name 'VkLayer_khronos_validation.json' 2>/dev/null)" ]; then
  expect_exit 0 "render --validate" -- "$render" "${base[@]}" --layout gray --background 1,1,1,0.5 \
    -o "$work/validated.png" --validate --json
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['validation']=={'warnings':0,'errors':0}, r" \
    "$work/out" || fail "--validate --json does not report zero messages"
  python3 -c "import sys,struct; d=open(sys.argv[1],'rb').read(); assert struct.unpack('>B',d[25:26])[0]==6" \
    "$work/validated.png" || fail "a translucent background did not give an RGBA PNG"
fi

if [ "$failures" -ne 0 ]; then
  echo "$failures crisp-render checks failed" >&2
  exit 1
fi
echo "all crisp-render checks passed"
