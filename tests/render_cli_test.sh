#!/usr/bin/env bash
# render_cli_test.sh CRISP_RENDER CRISP_BAKE SOURCE_DIR WORK_DIR: crisp-render's exit codes and
# its refusal of bad input (no GPU needed), then end-to-end renders on whatever Vulkan device there
# is (lavapipe in CI): PNG, coverage PFM and --json, every --composite mode, and scene files.
set -uo pipefail
render=$1 bake=$2 source=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
# The Python checks import read_png from beside this script.
export PYTHONPATH="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)${PYTHONPATH:+:$PYTHONPATH}"

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
expect_exit 2 "--size below the float range" -- "$render" "${base[@]}" --size 1e-46 -o x.png
expect_stderr "out of range" "--size 1e-46"
# Item 18 of issue 28: numbers past their range say so, and why; not "0", not "not a number".
expect_exit 2 "--size 1e-45 (a subnormal float)" -- "$render" "${base[@]}" --size 1e-45 -o x.png
expect_stderr "too small" "--size 1e-45"
! grep -q " is 0" "$work/err" || fail "--size 1e-45 is reported as 0: $(cat "$work/err")"
expect_exit 2 "--canvas -1,32" -- "$render" "${base[@]}" --canvas -1,32 -o x.png
expect_stderr "'-1' is negative" "--canvas -1,32"
printf '{"r": [1e308, 0, 0.34, 1], "g": [0.33, 0, 0.67, 1], "b": [0.67, 0, 1, 1]}' > "$work/huge.json"
expect_exit 6 "a layout number of 1e308" -- "$render" "${base[@]}" --layout "$work/huge.json" -o x.png
expect_stderr "r[0]: expected a number, at most 1e6 in magnitude: 1e+308 is out of range" "a layout number of 1e308"
# Bounded inputs and safe outputs (docs/limits.md), before any GPU work.
expect_exit 3 "/dev/zero as the font" -- timeout 20 "$render" "${base[@]/$font//dev/zero}" -o "$work/zero.png"
expect_stderr "not a regular file" "/dev/zero as the font"
mkfifo "$work/out.fifo"
expect_exit 4 "a FIFO as the output" -- timeout 20 "$render" "${base[@]}" -o "$work/out.fifo"
[ -p "$work/out.fifo" ] || fail "the FIFO was replaced"
cp "$font" "$work/font-copy.crisp"
expect_exit 4 "the font as the output" -- "$render" "${base[@]/$font/$work/font-copy.crisp}" -o "$work/font-copy.crisp"
cmp -s "$font" "$work/font-copy.crisp" || fail "the input asset was overwritten"
# Every output is checked before any work, and written together: a --coverage-out that cannot be
# written leaves an existing PNG as it was.
printf 'existing' > "$work/kept.png"
expect_exit 4 "an unwritable --coverage-out" -- "$render" "${base[@]}" -o "$work/kept.png" \
  --coverage-out "$work/no/such/dir/c.pfm"
[ "$(cat "$work/kept.png")" = existing ] || fail "the PNG was replaced though --coverage-out failed"
# Every input of a run, however named, is refused as an output before any work: a scene's asset
# (given relative to the scene, written through a symlinked directory or a hard link) and its layout
# file; and -o and --coverage-out that are one file (used to leave the PFM in the PNG's place).
mkdir -p "$work/scene-dir" && ln -s scene-dir "$work/scene-alias"
cp "$font" "$work/scene-dir/a.crisp" && ln "$work/scene-dir/a.crisp" "$work/hard.crisp"
printf '{"r": [0, 0, 0.34, 1], "g": [0.33, 0, 0.67, 1], "b": [0.66, 0, 1, 1]}' >"$work/scene-dir/lay.json"
printf '{"fonts": ["a.crisp"], "canvas": [48, 32], "layout": "scene-dir/lay.json", "runs": [{"text": "Hi", "size": 20, "origin": [4, 24]}]}' \
  >"$work/scene-dir/s.json"
cp "$work/scene-dir/lay.json" "$work/lay.kept"
for output in scene-dir/a.crisp scene-alias/a.crisp "$work/hard.crisp" ./scene-dir/lay.json scene-alias/s.json; do
  expect_exit 4 "the scene's input $output as the output" -- "$render" --scene scene-dir/s.json -o "$output"
  expect_stderr "it is the input" "the scene's input $output as the output"
done
cmp -s "$font" "$work/scene-dir/a.crisp" || fail "the scene's asset was overwritten"
cmp -s "$work/lay.kept" "$work/scene-dir/lay.json" || fail "the scene's layout was overwritten"
expect_exit 4 "--layout as the output" -- "$render" "${base[@]}" --layout "$work/scene-dir/lay.json" \
  -o scene-alias/lay.json
expect_exit 4 "-o and --coverage-out one file (absolute)" -- "$render" "${base[@]}" -o one.png --coverage-out "$work/one.png"
expect_stderr "also the output" "-o and --coverage-out one file (absolute)"
expect_exit 4 "-o and --coverage-out one file (a linked directory)" -- "$render" "${base[@]}" -o scene-dir/one.png \
  --coverage-out scene-alias/one.png
[ -e one.png ] || [ -e scene-dir/one.png ] && fail "an output was written though the two outputs are one file"
# FIFOs as inputs are refused at once (opening one used to wait for a writer for ever).
mkfifo "$work/in.fifo" "$work/in.fifo.json"
expect_exit 3 "a FIFO as --font" -- timeout 20 "$render" "${base[@]/$font/$work/in.fifo}" -o fifo.png
expect_stderr "not a regular file" "a FIFO as --font"
expect_exit 7 "a FIFO as --scene" -- timeout 20 "$render" --scene "$work/in.fifo" -o fifo.png
expect_stderr "not a regular file" "a FIFO as --scene"
expect_exit 6 "a FIFO as --layout" -- timeout 20 "$render" "${base[@]}" --layout "$work/in.fifo.json" -o fifo.png
expect_stderr "not a regular file" "a FIFO as --layout"
# A name longer than the file system takes fails before any work (a missing font is not reached).
long=$(printf 'n%.0s' $(seq "$(getconf NAME_MAX "$work")"))
expect_exit 4 "a name of NAME_MAX + 1 bytes" -- "$render" "${base[@]/$font/$work/missing.crisp}" -o "${long}x.png"
expect_stderr "File name too long" "a name of NAME_MAX + 1 bytes"
# More glyphs than one render lays out (4 Mi): refused, exit 7, naming the limit.
python3 - "$work/many.json" <<'PY'
import json, sys
runs = [{"text": "H" * 900000, "size": 8, "origin": [0, 8]} for _ in range(5)]
json.dump({"fonts": ["dejavu.crisp"], "canvas": [32, 32], "runs": runs}, open(sys.argv[1], "w"))
PY
expect_exit 7 "a scene of 4.5 million glyphs" -- timeout 120 "$render" --scene "$work/many.json" -o "$work/many.png"
expect_stderr "glyphs, crisp-render's limit" "a scene of 4.5 million glyphs"
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
expect_exit 2 "--path bogus" -- "$render" "${base[@]}" --path bogus -o x.png
expect_stderr "bogus" "--path bogus"
expect_exit 2 "--path with the tile path" -- "$render" "${base[@]}" --path compute -o x.png
expect_stderr "--path applies" "--path with the tile path"
expect_exit 2 "--composite bogus" -- "$render" "${base[@]}" --composite bogus -o x.png
expect_stderr "bogus" "--composite bogus"
# The first compositor's layered mode and its --layers are gone: the tile path replaced them.
expect_exit 2 "--layers" -- "$render" "${base[@]}" --layers 2 -o x.png
expect_exit 2 "--composite layered" -- "$render" "${base[@]}" --composite layered -o x.png
# --scene gives the text, fonts, canvas, colours and layout: none of those options may come with it.
for option in "--font $font" "--text Hi" "--size 20" "--origin 0,20" "--canvas 48,32" "--color 0,0,0" \
              "--background 1,1,1" "--palette 1" "--layout gray"; do
  # shellcheck disable=SC2086
  expect_exit 2 "--scene with $option" -- "$render" --scene "$work/any.json" $option -o x.png
  expect_stderr "${option%% *}" "--scene with $option"
done
# The contrast model's settings: each out of its range, or not a number, names the option and the range.
for value in 0.5 0.999 4.001 -2.2 nan inf abc ""; do
  expect_exit 2 "--gamma '$value'" -- "$render" "${base[@]}" --gamma "$value" -o x.png
  expect_stderr "--gamma" "--gamma '$value'"
done
expect_exit 2 "--gamma 0.5, the range" -- "$render" "${base[@]}" --gamma 0.5 -o x.png
expect_stderr "--gamma must be in 1..4" "--gamma 0.5, the range"
for option in --enhanced-contrast --stem-darkening; do
  for value in -0.01 4.5 1e9 nan x; do
    expect_exit 2 "$option '$value'" -- "$render" "${base[@]}" "$option" "$value" -o x.png
    expect_stderr "$option" "$option '$value'"
  done
  expect_exit 2 "$option -1, the range" -- "$render" "${base[@]}" "$option" -1 -o x.png
  expect_stderr "$option must be in 0..4" "$option -1, the range"
done
expect_exit 2 "--contrast bogus" -- "$render" "${base[@]}" --contrast srgb -o x.png
expect_stderr "--contrast" "--contrast bogus"
expect_stderr "srgb" "--contrast bogus"
for option in "--gamma 2" "--enhanced-contrast 1" "--stem-darkening 1"; do
  # shellcheck disable=SC2086
  expect_exit 2 "--contrast linear with $option" -- "$render" "${base[@]}" --contrast linear $option -o x.png
  expect_stderr "${option%% *}" "--contrast linear with $option"
done
expect_exit 2 "--scene without output" -- "$render" --scene "$work/any.json"
expect_exit 2 "--scene with an empty name" -- "$render" --scene "" -o x.png

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

# ---- Bad scene files: exit 7, with the reader's message naming the fault, and no output.
scene_run() {  # scene_run FILE RUN_JSON: a one-run scene using the baked font
  printf '{"fonts": ["dejavu.crisp"], "canvas": [48, 32], "runs": [%s]}' "$2" >"$work/$1"
}
scene_run negative-size.json '{"text": "Hi", "size": -1, "origin": [4, 24]}'
expect_exit 7 "scene run with size -1" -- "$render" --scene "$work/negative-size.json" -o "$work/scene-bad.png"
expect_stderr "runs[0].size" "scene run with size -1"
expect_stderr "negative-size.json" "scene run with size -1"
scene_run bad-font-index.json '{"font": 1, "text": "Hi", "size": 20, "origin": [4, 24]}'
expect_exit 7 "scene run with a font index out of range" -- \
  "$render" --scene "$work/bad-font-index.json" -o "$work/scene-bad.png"
expect_stderr "runs[0].font" "scene run with a font index out of range"
printf '{"fonts": ["dejavu.crisp"], "canvas": [48, 32], "runs": [{"text": "Hi",' >"$work/malformed.json"
expect_exit 7 "malformed scene JSON" -- "$render" --scene "$work/malformed.json" -o "$work/scene-bad.png"
expect_stderr "malformed.json" "malformed scene JSON"
expect_stderr "line 1, column" "malformed scene JSON"
expect_exit 7 "missing scene file" -- "$render" --scene "$work/no-such-scene.json" -o "$work/scene-bad.png"
expect_stderr "no-such-scene.json" "missing scene file"
printf '{"fonts": ["missing.crisp"], "canvas": [48, 32], "runs": []}' >"$work/missing-font.json"
expect_exit 3 "scene with a missing font" -- "$render" --scene "$work/missing-font.json" -o "$work/scene-bad.png"
expect_stderr "missing.crisp" "scene with a missing font"
printf '{"fonts": ["dejavu.crisp"], "canvas": [48, 32], "layout": "no-such-layout", "runs": []}' \
  >"$work/bad-layout.json"
expect_exit 6 "scene with an unknown layout" -- "$render" --scene "$work/bad-layout.json" -o "$work/scene-bad.png"
scene_run bad-contrast.json '{"text": "Hi", "size": 20, "origin": [4, 24], "contrast": {"gamma": 0.5}}'
expect_exit 7 "scene run with gamma 0.5" -- "$render" --scene "$work/bad-contrast.json" -o "$work/scene-bad.png"
expect_stderr "runs[0].contrast.gamma: 0.5 is not in [1, 4]" "scene run with gamma 0.5"
scene_run bad-contrast-mode.json '{"text": "Hi", "size": 20, "origin": [4, 24], "contrast": {"mode": "srgb"}}'
expect_exit 7 "scene run with contrast mode srgb" -- \
  "$render" --scene "$work/bad-contrast-mode.json" -o "$work/scene-bad.png"
expect_stderr 'runs[0].contrast.mode: expected "linear" or "corrected", got "srgb"' "scene run with contrast mode srgb"
[ ! -e "$work/scene-bad.png" ] || fail "a failed scene run wrote an output"

# ---- No Vulkan driver, or no device of that name: exit 5 naming it.
VK_ICD_FILENAMES=$work/none.json VK_DRIVER_FILES=$work/none.json \
  expect_exit 5 "no Vulkan driver" -- "$render" "${base[@]}" -o x.png
expect_exit 5 "no such device" -- "$render" "${base[@]}" --device "no such device 42" -o x.png
expect_stderr "no such device 42" "no such device"

# ---- A kill between the two renames (strace kills crisp-render as it enters its second) leaves the
# PNG new and the PFM missing, its new contents in a hidden temporary: never a new PNG beside an old PFM.
if strace -o /dev/null true 2>/dev/null; then
  printf 'old' >"$work/old.ref" && cp "$work/old.ref" "$work/pair.png" && cp "$work/old.ref" "$work/pair.pfm"
  (MESA_SHADER_CACHE_DISABLE=true strace -f -o /dev/null -e trace=rename,renameat,renameat2 \
    -e inject=rename,renameat,renameat2:signal=KILL:when=2 \
    "$render" "${base[@]}" -o "$work/pair.png" --coverage-out "$work/pair.pfm" -q) 2>/dev/null
  cmp -s "$work/old.ref" "$work/pair.png" && fail "killed at its second rename, crisp-render had not replaced the PNG"
  [ -e "$work/pair.pfm" ] && cmp -s "$work/old.ref" "$work/pair.pfm" &&
    fail "a kill between the renames left the new PNG beside the old PFM"
  find "$work" -maxdepth 1 -name '.pair.pfm.crisp-tmp-*' | grep -q . ||
    fail "the killed run's PFM is not in its hidden temporary: $(ls -A "$work" | grep pair)"
  rm -f "$work"/.pair.pfm.crisp-tmp-*  # the kill's leftover, by design: the check below is for others
else
  echo "note: strace cannot trace here: the kill between the renames is not checked" >&2
fi

# --size takes (0, 4096] as documented: below glyph keys' 1/256 px it is drawn at 1/256 px (nothing shows).
expect_exit 0 "--size 0.001" -- "$render" "${base[@]}" --size 0.001 -o "$work/tiny.png"

# ---- End to end: "Hi" at 20 px on a 48x32 canvas.
expect_exit 0 "render" -- "$render" "${base[@]}" -o "$work/hi.png" --coverage-out "$work/hi.pfm" --json
cp "$work/out" "$work/hi.json"
python3 - "$work" <<'PY' || fail "the render's outputs are wrong"
import json, struct, sys
work = sys.argv[1]
report = json.load(open(work + "/hi.json"))
assert report["frames"] > 1 and report["converged"] and report["stopped"] is None, report
assert report["samples"] == {"target": 16, "min": 16, "max": 16, "glyphs": 2, "converged_glyphs": 2}, report["samples"]
assert report["glyphs"]["drawn"] == 2 and report["glyphs"]["failed"] == 0, report["glyphs"]
assert report["canvas"] == {"width": 48, "height": 32}, report["canvas"]
assert len(report["timings"]["frame_ms"]) == report["frames"], report["timings"]
assert report["total_samples"] >= 2 * 16 and report["layout"] == "rgb", report
assert report["device"]["name"] and report["outputs"]["png"].endswith("hi.png"), report
composite = report["composite"]
# The image is the second of two frames of the same glyphs: it reuses the first one's bins.
assert composite["mode"] == "tiled" and composite["bins_reused"] is True, composite
assert composite["measured"] and composite["max_overlap"] == 1 and composite["backdrop"] == "flat", composite
assert composite["quads"] == 2 and composite["tail_pixels"] == 0, composite
tiles = composite["tiles"]
assert tiles["busy"] > 0 and tiles["exact"] == tiles["busy"] and tiles["layered"] == 0, tiles
assert report["timings"]["composite_ms"] > 0 and report["scene"] is None and report["runs"] == 1, report

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
[ -z "$(ls -A "$work" | grep -e '\.tmp' -e 'crisp-tmp')" ] || fail "temporary files were left behind"

# ---- Contrast: the default is corrected and says so; --contrast linear blends the coverage as it
# is, and black on white is then lighter (the default makes it heavier), not the same image.
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']
assert c == {'mode': 'corrected', 'gamma': 2.2, 'contrast': 0, 'stem_darkening': 0, 'own_runs': 0}, c" \
  "$work/hi.json" || fail "the default contrast is not reported as corrected, gamma 2.2"
expect_exit 0 "--contrast linear" -- "$render" "${base[@]}" --contrast linear -o "$work/hi-linear.png" --json
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']; assert c['mode'] == 'linear', c" \
  "$work/out" || fail "--contrast linear is not reported"
expect_exit 0 "--contrast corrected, every setting" -- "$render" "${base[@]}" --contrast corrected --gamma 1.8 \
  --enhanced-contrast 0.5 --stem-darkening 1 -o "$work/hi-heavier.png" --json
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']
assert c == {'mode': 'corrected', 'gamma': 1.8, 'contrast': 0.5, 'stem_darkening': 1, 'own_runs': 0}, c" \
  "$work/out" || fail "the contrast settings given are not reported"
expect_exit 0 "the ends of the contrast ranges" -- "$render" "${base[@]}" --gamma 4 --enhanced-contrast 4 \
  --stem-darkening 4 -o "$work/hi-ends.png"
expect_exit 0 "gamma 1, no enhanced contrast" -- "$render" "${base[@]}" --gamma 1 --enhanced-contrast 0 \
  --stem-darkening 0 -o "$work/hi-gamma1.png"
python3 - "$work" <<'PY' || fail "--contrast linear and the default do not differ as they should"
import sys, zlib, struct
work = sys.argv[1]
def pixels(path):  # the filtered scanlines: equal images give equal bytes (one encoder)
    data = open(path, "rb").read()
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IDAT": idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return zlib.decompress(idat)
corrected, linear = pixels(work + "/hi.png"), pixels(work + "/hi-linear.png")
heavier, gamma1 = pixels(work + "/hi-heavier.png"), pixels(work + "/hi-gamma1.png")
assert len(corrected) == len(linear) == 32 * (1 + 48 * 3)
assert corrected != linear, "--contrast linear gives the default's image"
assert heavier != corrected, "--gamma 1.8 --enhanced-contrast 0.5 --stem-darkening 1 gives the default's image"
# Gamma 1 with no enhanced contrast and no darkening is the identity: the linear image.
assert gamma1 == linear, "gamma 1, contrast 0, darkening 0 is not the linear image"
PY
# A scene's runs: their own settings (DrawOptions::contrast) over the scene's default, over the
# command line's. A linear run draws the linear image whichever way it says so.
scene_run run-linear.json '{"text": "Hi", "size": 20, "origin": [4.25, 24.5], "contrast": {"mode": "linear"}}'
printf '{"fonts": ["dejavu.crisp"], "canvas": [48, 32], "contrast": {"mode": "linear"}, "runs": [%s]}' \
  '{"text": "Hi", "size": 20, "origin": [4.25, 24.5]}' >"$work/scene-linear.json"
scene_run run-default.json '{"text": "Hi", "size": 20, "origin": [4.25, 24.5]}'
expect_exit 0 "a scene run's own linear contrast" -- "$render" --scene "$work/run-linear.json" --samples 16 \
  -o "$work/run-linear.png" --json
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']; assert c['own_runs'] == 1, c" \
  "$work/out" || fail "a scene run's own contrast is not counted"
cmp -s "$work/run-linear.png" "$work/hi-linear.png" || fail "a scene run's linear contrast is not the linear image"
expect_exit 0 "a scene's linear default" -- "$render" --scene "$work/scene-linear.json" --samples 16 \
  -o "$work/scene-linear.png" --contrast corrected --gamma 3
cmp -s "$work/scene-linear.png" "$work/hi-linear.png" || fail "a scene's linear default is not the linear image"
expect_exit 0 "--contrast linear with a scene" -- "$render" --scene "$work/run-default.json" --samples 16 \
  -o "$work/run-default-linear.png" --contrast linear
cmp -s "$work/run-default-linear.png" "$work/hi-linear.png" || fail "--contrast linear does not reach a scene's runs"
expect_exit 0 "a scene without contrast" -- "$render" --scene "$work/run-default.json" --samples 16 \
  -o "$work/run-default.png"
cmp -s "$work/run-default.png" "$work/hi.png" || fail "a scene without contrast is not drawn as the default"

# A layout file's contrast (a monitor's settings) is the renderer's unless an option gives one.
cat >"$work/rgb-linear.json" <<'JSON'
{"name": "rgb-linear", "r": [0, 0, 0.333333, 1], "g": [0.333333, 0, 0.666667, 1], "b": [0.666667, 0, 1, 1],
 "contrast": {"mode": "linear"}}
JSON
expect_exit 0 "a layout file with linear contrast" -- "$render" "${base[@]}" --layout "$work/rgb-linear.json" \
  -o "$work/layout-linear.png" --json
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']; assert c['mode'] == 'linear', c" \
  "$work/out" || fail "a layout file's linear contrast is not the renderer's"
expect_exit 0 "a layout file's contrast under --contrast corrected" -- "$render" "${base[@]}" \
  --layout "$work/rgb-linear.json" --contrast corrected -o "$work/layout-corrected.png" --json
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['contrast']; assert c['mode'] == 'corrected', c" \
  "$work/out" || fail "--contrast does not override a layout file's contrast"

# The human summary goes to stdout, nothing to stderr.
expect_exit 0 "render without --json" -- "$render" "${base[@]}" -o "$work/hi2.png"
grep -q "frames" "$work/out" || fail "no summary on stdout"
grep -q "contrast corrected, gamma 2.2, contrast 0, stem darkening 0" "$work/out" ||
  fail "the summary does not give the contrast settings: $(cat "$work/out")"
[ ! -s "$work/err" ] || fail "a good run wrote to stderr: $(head -c 400 "$work/err")"

# -q: nothing on stdout or stderr.
expect_exit 0 "render -q" -- "$render" "${base[@]}" -o "$work/quiet.png" -q
[ ! -s "$work/out" ] && [ ! -s "$work/err" ] || fail "-q printed: $(head -c 400 "$work/out" "$work/err")"
[ -s "$work/quiet.png" ] || fail "-q wrote no PNG"

# ---- Every --composite mode, on a scene of overlapping translucent runs at different depths: the
# committed example, with its font baked beside it (scene font paths are relative to the scene).
mkdir -p "$work/example" "$work/elsewhere"
cp "$source/docs/examples/overlap.json" "$work/example/"
"$bake" "$source/fonts/DejaVuSans.ttf" --text "crisptex" -o "$work/example/DejaVuSans.crisp" -q ||
  fail "crisp-bake failed for the example scene"
cd "$work/elsewhere"
for mode in tiled draw unsorted wboit exact; do
  expect_exit 0 "--scene --composite $mode" -- "$render" --scene ../example/overlap.json --samples 16 \
    --composite "$mode" -o "$work/scene-$mode.png" --json
  cp "$work/out" "$work/scene-$mode.json"
  [ ! -s "$work/err" ] || fail "--composite $mode wrote to stderr: $(head -c 400 "$work/err")"
done
cd "$work"
# The compute path runs the same per-fragment code over tiles: the very same image.
for mode in wboit exact; do
  expect_exit 0 "--scene --composite $mode --path compute" -- "$render" --scene "$work/example/overlap.json" \
    --samples 16 --composite "$mode" --path compute -o "$work/scene-$mode-compute.png"
  cmp -s "$work/scene-$mode.png" "$work/scene-$mode-compute.png" || fail "--path compute changes the $mode image"
done
python3 - "$work" <<'PY' || fail "the composite modes' outputs are wrong"
import json, sys
from read_png import read_png
work = sys.argv[1]

images = {}
for mode in ("tiled", "draw", "unsorted", "wboit", "exact"):
    report = json.load(open("%s/scene-%s.json" % (work, mode)))
    c = report["composite"]
    assert c["mode"] == mode, (mode, c)
    assert report["canvas"] == {"width": 180, "height": 64} and report["runs"] == 3, report
    assert report["scene"].endswith("overlap.json") and report["size"] is None, report
    assert report["glyphs"]["drawn"] == 14 and report["glyphs"]["missing"] == 0, report["glyphs"]
    assert c["quads"] == 14 and c["warnings"] == [], c
    if mode in ("tiled", "exact"):
        assert c["measured"] and c["max_overlap"] == 3, c
    if mode == "tiled":
        assert c["tiles"]["busy"] == c["tiles"]["exact"] > 0 and c["tiles"]["pairs"] >= c["quads"], c
    if mode == "exact":
        assert c["exact_lost_nodes"] == 0 and c["exact_dropped"] == 0, c
    images[mode] = read_png("%s/scene-%s.png" % (work, mode))
    assert images[mode][:3] == (180, 64, 3), (mode, images[mode][:3])

def max_difference(a, b):
    return max(abs(x - y) for x, y in zip(images[a][3], images[b][3]))
# The tile and draw paths are exact front to back over the same flat background. Unsorted draws in
# file order, so the green run (depth 0.5, drawn last) covers the blue one (depth 0.25, nearer): far
# from exact.
assert max_difference("tiled", "exact") <= 1, max_difference("tiled", "exact")
assert max_difference("draw", "exact") <= 1, max_difference("draw", "exact")
assert max_difference("unsorted", "exact") > 32, max_difference("unsorted", "exact")
assert max_difference("wboit", "exact") > 0, "wboit is exact: suspicious"
white = bytes([255, 255, 255])
assert images["exact"][3][:3] == white, "the top-left pixel is not the background"
assert min(images["exact"][3]) < 128, "no dark pixel: nothing was drawn"

PY

# A backdrop: the tile and draw paths put the same text over the same gradient; the reference
# modes draw over a flat background only.
for mode in tiled draw; do
  expect_exit 0 "--backdrop gradient --composite $mode" -- "$render" --scene "$work/example/overlap.json" \
    --samples 16 --composite "$mode" --backdrop gradient -o "$work/gradient-$mode.png"
done
python3 - "$work" <<'PY' || fail "the backdrop images are wrong"
import sys, zlib, struct
work = sys.argv[1]
def pixels(path):
    data = open(path, "rb").read()
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR": width = struct.unpack(">I", data[pos + 8:pos + 12])[0]
        if kind == b"IDAT": idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return zlib.decompress(idat), width
tiled, width = pixels(work + "/gradient-tiled.png")
drawn, _ = pixels(work + "/gradient-draw.png")
flat, _ = pixels(work + "/scene-tiled.png")
assert len(tiled) == len(drawn) == len(flat)
assert tiled != flat, "the gradient backdrop looks like the flat background"
PY
expect_exit 2 "--backdrop with a reference mode" -- "$render" --scene "$work/example/overlap.json" \
  --composite exact --backdrop photo -o x.png
expect_stderr "--backdrop" "--backdrop with a reference mode"
expect_exit 2 "--backdrop bogus" -- "$render" "${base[@]}" --backdrop bogus -o x.png

# The exact mode keeps at most 64 fragments per pixel: 70 runs of one glyph over each other drop
# some, and the run says so on stderr (and still succeeds).
python3 - "$work/pile.json" <<'PY'
import json, sys
runs = [{"text": "H", "size": 20, "origin": [4, 24], "color": [0, 0, 0, 0.05]} for _ in range(70)]
json.dump({"fonts": ["dejavu.crisp"], "canvas": [32, 32], "runs": runs}, open(sys.argv[1], "w"))
PY
expect_exit 0 "exact past 64 fragments a pixel" -- "$render" --scene "$work/pile.json" --samples 16 \
  --composite exact -o "$work/pile.png" --json
expect_stderr "dropped" "exact past 64 fragments a pixel"
python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['composite']; assert c['exact_dropped'] > 0, c" \
  "$work/out" || fail "the exact mode's dropped fragments are not reported"

# ---- Colour glyphs: COLRv1 layers drawn by default and counted in the report; --no-colour draws the
# plain outlines; --palette and a scene's "palette" choose the CPAL palette.
"$bake" "$source/tests/fonts/colour/colrv1.ttf" --codepoints U+E000-E004 -o "$work/colrv1.crisp" -q ||
  fail "crisp-bake colrv1.ttf failed"
colr=(--font "$work/colrv1.crisp" --text "$(printf '\xee\x80\x80\xee\x80\x82\xee\x80\x83\xee\x80\x84')" --size 24
  --origin 2,24 --canvas 104,32 --samples 16)
expect_exit 2 "--palette 256" -- "$render" "${colr[@]}" --palette 256 -o x.png
expect_stderr "--palette" "--palette 256"
expect_exit 0 "colour glyphs" -- "$render" "${colr[@]}" -o "$work/colr.png"
expect_stdout_line() {  # expect_stdout_line TEXT DESCRIPTION: the last command's stdout holds TEXT
  grep -qF -- "$1" "$work/out" || fail "$2: stdout lacks '$1': $(head -c 600 "$work/out")"
}
expect_stdout_line "colour   4 glyphs as 5 layers (5 drawn, 3 paints), 0 bitmap uploads, 0 missed" "colour glyphs"
for variant in "--no-colour" "--palette 1"; do
  # shellcheck disable=SC2086
  expect_exit 0 "colour glyphs $variant" -- "$render" "${colr[@]}" $variant -o "$work/colr${variant// /}.png" --json
  cp "$work/out" "$work/colr${variant// /}.json"
done
scene_run colr-scene.json "{\"text\": \"$(printf '\xee\x80\x80')\", \"size\": 24, \"origin\": [2, 24], \"palette\": 1}"
sed -i "s|dejavu.crisp|colrv1.crisp|" "$work/colr-scene.json"
expect_exit 0 "a scene run's palette" -- "$render" --scene "$work/colr-scene.json" --samples 16 -o "$work/colr-scene.png"
expect_exit 0 "--palette 1 on one glyph" -- "$render" "${colr[@]/$(printf '\xee\x80\x80\xee\x80\x82\xee\x80\x83\xee\x80\x84')/$(printf '\xee\x80\x80')}" \
  --canvas 48,32 --palette 1 -o "$work/colr-palette1.png"
scene_run colr-bad-palette.json '{"text": "Hi", "size": 20, "origin": [4, 24], "palette": 256}'
expect_exit 7 "a scene run's palette 256" -- "$render" --scene "$work/colr-bad-palette.json" -o x.png
expect_stderr "runs[0].palette" "a scene run's palette 256"
python3 - "$work" <<'PY' || fail "colour glyphs are not drawn or counted as they should be"
import json, sys
work = sys.argv[1]
plain = json.load(open(work + "/colr--no-colour.json"))["colour"]
assert plain == {"enabled": False, "glyphs": 0, "layers": 0, "drawn_layers": 0, "paints": 0,
                 "bitmap_uploads": 0, "bitmap_misses": 0}, plain
other = json.load(open(work + "/colr--palette1.json"))
assert other["colour"]["glyphs"] == 4 and other["colour"]["drawn_layers"] == 5, other["colour"]
assert other["glyphs"]["drawn"] == 5, other["glyphs"]
read = lambda name: open("%s/%s.png" % (work, name), "rb").read()
assert read("colr") != read("colr--no-colour"), "--no-colour draws the same image"
assert read("colr") != read("colr--palette1"), "palette 1 draws the same image as palette 0"
assert read("colr-scene") == read("colr-palette1"), "a scene run's palette 1 is not --palette 1"
PY

# Bitmap emoji (Noto Color Emoji, CBDT) after a text font in the fallback chain: the emoji take the
# colour font, each image uploaded once.
noto=/usr/share/fonts/truetype/noto/NotoColorEmoji.ttf
if [ -f "$noto" ]; then
  "$bake" "$noto" --text "😀👍🏽" -o "$work/noto.crisp" -q || fail "crisp-bake of a Noto Color Emoji subset failed"
  emoji=(--font "$font" --font "$work/noto.crisp" --text "Hi 😀👍🏽" --size 24 --origin 2,26 --canvas 96,32
    --samples 16)
  expect_exit 0 "bitmap emoji" -- "$render" "${emoji[@]}" -o "$work/emoji.png" --json
  cp "$work/out" "$work/emoji.json"
  expect_exit 0 "bitmap emoji --no-colour" -- "$render" "${emoji[@]}" --no-colour -o "$work/emoji-plain.png"
  expect_exit 0 "bitmap emoji, the report" -- "$render" "${emoji[@]}" -o "$work/emoji.png"
  expect_stdout_line "colour   2 glyphs as 2 layers (2 drawn" "bitmap emoji"
  expect_stdout_line "2 bitmap uploads, 0 missed" "bitmap emoji"
  python3 - "$work" <<'PY' || fail "bitmap emoji are not drawn or counted as they should be"
import json, sys
from read_png import read_png
work = sys.argv[1]
c = json.load(open(work + "/emoji.json"))["colour"]
assert c["glyphs"] == 2 and c["layers"] == 2 and c["drawn_layers"] == 2, c
assert c["bitmap_uploads"] == 2 and c["bitmap_misses"] == 0, c
_, _, channels, colour = read_png(work + "/emoji.png")
plain = read_png(work + "/emoji-plain.png")[3]
assert colour != plain, "--no-colour draws the same image"
# The emoji's yellow face: a pixel far from grey, which black text on white never makes.
saturated = lambda px: max(px) - min(px) > 96
pixels = [colour[i:i + 3] for i in range(0, len(colour), channels)]
assert sum(1 for px in pixels if saturated(px)) > 50, "no colourful pixels: the emoji are not drawn in colour"
PY
fi

# ---- --transform A,B,C,D (docs/transforms.md): a 2x2 about --origin, y down. Bad values are usage
# errors naming the option; a good one turns the ink.
for value in 1,0,0 1,0,0,1,0 a,b,c,d 1,0,0,x "" 1,,0,1 nan,0,0,1 1,inf,0,1 70000,0,0,1 0,0,0,0 1,2,2,4 1e-3,0,0,1e-3; do
  expect_exit 2 "--transform '$value'" -- "$render" "${base[@]}" --transform "$value" -o x.png
  expect_stderr "--transform" "--transform '$value'"
done
expect_exit 2 "--transform 1,0,0" -- "$render" "${base[@]}" --transform 1,0,0 -o x.png
expect_stderr "--transform takes A,B,C,D" "--transform 1,0,0"
expect_exit 2 "--transform 1,2,2,4" -- "$render" "${base[@]}" --transform 1,2,2,4 -o x.png
expect_stderr "|A D - B C| at least 2^-16" "--transform 1,2,2,4"
printf '{"fonts": ["dejavu.crisp"], "canvas": [8, 8], "runs": []}' > "$work/transform-any.json"
expect_exit 2 "--scene with --transform" -- "$render" --scene "$work/transform-any.json" --transform 0,-1,1,0 -o x.png
expect_stderr "--transform must not be given with it" "--scene with --transform"
# "Hi" upright is wider than tall; turned 90 degrees clockwise (y down) about its origin, taller than
# wide and right of the origin; mirrored in x, left of it. A scene run's "transform" is the same draw.
turn=(--font "$font" --text "Hi" --size 16 --origin 32,20 --canvas 64,64 --samples 16 --layout gray)
expect_exit 0 "render upright" -- "$render" "${turn[@]}" -o "$work/upright.png"
expect_exit 0 "render --transform 0,-1,1,0" -- "$render" "${turn[@]}" --transform 0,-1,1,0 -o "$work/turned.png"
expect_exit 0 "render --transform -1,0,0,1" -- "$render" "${turn[@]}" --transform -1,0,0,1 -o "$work/mirrored.png"
printf '{"fonts": ["dejavu.crisp"], "canvas": [64, 64], "layout": "gray", "runs": [
  {"text": "Hi", "size": 16, "origin": [32, 20], "transform": [0, -1, 1, 0]}]}' > "$work/turned.json"
expect_exit 0 "render a scene run's transform" -- "$render" --scene "$work/turned.json" --samples 16 \
  -o "$work/turned-scene.png"
python3 - "$work" <<'PY' || fail "--transform does not turn the ink as it should"
import sys
from read_png import read_png
def ink(name):
    width, height, channels, data = read_png(sys.argv[1] + "/" + name)
    xs, ys = [], []
    for y in range(height):
        for x in range(width):
            if min(data[(y * width + x) * channels:(y * width + x) * channels + 3]) < 128:
                xs.append(x)
                ys.append(y)
    assert xs, name + " has no ink"
    return min(xs), min(ys), max(xs) + 1, max(ys) + 1
x0, y0, x1, y1 = ink("upright.png")
assert x1 - x0 > y1 - y0 and x0 >= 32 and y1 <= 21, ("upright", x0, y0, x1, y1)
for name in ("turned.png", "turned-scene.png"):
    t0, u0, t1, u1 = ink(name)
    assert u1 - u0 > t1 - t0, (name, "not taller than wide", t0, u0, t1, u1)
    assert t0 >= 31 and u0 >= 19 and abs((u1 - u0) - (x1 - x0)) <= 2, (name, t0, u0, t1, u1, x0, x1)
m0, n0, m1, n1 = ink("mirrored.png")
assert m1 <= 33 and abs((m1 - m0) - (x1 - x0)) <= 2 and (n0, n1) == (y0, y1), ("mirrored", m0, n0, m1, n1)
PY
cmp -s "$work/turned.png" "$work/turned-scene.png" || fail "a scene run's transform differs from --transform"

# ---- Effects (docs/effects.md): --outline, --shadow, --weight. Bad values are usage errors that
# name the option; a scene's run says the same in "outline", "shadow" and "weight".
for value in -1 nan 1,2,0,0 1,0,0 1,0,0,0,0,0 5000; do
  expect_exit 2 "--outline '$value'" -- "$render" "${base[@]}" --outline "$value" -o x.png
  expect_stderr "--outline" "--outline '$value'"
done
expect_exit 2 "--outline 90 at 20 px" -- "$render" "${base[@]}" --outline 90 -o x.png
expect_stderr "outline width 90 px reaches past 4 em at 20 px per em" "--outline 90 at 20 px"
for value in 1 1,1 nan,0,0 1,1,0,0,0 9000,0,0; do
  expect_exit 2 "--shadow '$value'" -- "$render" "${base[@]}" --shadow "$value" -o x.png
  expect_stderr "--shadow" "--shadow '$value'"
done
for value in 0 -1 200 nan 2,1,0 2,1,0,0,0,0; do
  expect_exit 2 "--glow '$value'" -- "$render" "${base[@]}" --glow "$value" -o x.png
  expect_stderr "--glow" "--glow '$value'"
done
expect_exit 2 "--shadow with BLUR 200" -- "$render" "${base[@]}" --shadow 1,1,200 -o x.png
expect_stderr "--shadow" "--shadow with BLUR 200"
for value in nan 1,2 -5000; do
  expect_exit 2 "--weight '$value'" -- "$render" "${base[@]}" --weight "$value" -o x.png
  expect_stderr "--weight" "--weight '$value'"
done
expect_exit 2 "--outline-join without --outline" -- "$render" "${base[@]}" --outline-join miter -o x.png
expect_stderr "give it too" "--outline-join without --outline"
expect_exit 2 "--outline-placement sideways" -- "$render" "${base[@]}" --outline 1 --outline-placement sideways -o x.png
expect_exit 2 "--miter-limit 0.5" -- "$render" "${base[@]}" --outline 1 --miter-limit 0.5 -o x.png
expect_exit 2 "--scene with --outline" -- "$render" --scene "$work/transform-any.json" --outline 1 -o x.png
expect_stderr "--outline" "--scene with --outline"
# Black "Hi" on white with a red outline and a blue shadow: red ink rings the black, blue lies
# down and right of it; --weight 1 darkens more pixels than the plain text. The same run from a
# scene is the same image.
fx=(--font "$font" --text "Hi" --size 16 --origin 6,22 --canvas 48,32 --samples 16 --layout gray)
expect_exit 0 "render plain" -- "$render" "${fx[@]}" -o "$work/fx-plain.png"
expect_exit 0 "render --outline --shadow" -- "$render" "${fx[@]}" --outline 2,1,0,0 --outline-join miter \
  --shadow 4,3,0,0,0,1,1 -o "$work/fx-outlined.png" --json
python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['effects']; assert e['layers']==4 and e['failed']==0 and e['derived_glyphs']==4 and e['texels']>0, e" \
  "$work/out" || fail "--json does not count the effect layers"
expect_exit 0 "render --weight 1" -- "$render" "${fx[@]}" --weight 1 -o "$work/fx-bold.png"
printf '{"fonts": ["dejavu.crisp"], "canvas": [48, 32], "layout": "gray", "runs": [
  {"text": "Hi", "size": 16, "origin": [6, 22], "outline": {"width": 2, "join": "miter", "color": [1, 0, 0]},
   "shadow": {"offset": [4, 3], "color": [0, 0, 1]}}]}' > "$work/fx.json"
expect_exit 0 "render a scene run's effects" -- "$render" --scene "$work/fx.json" --samples 16 -o "$work/fx-scene.png"
cmp -s "$work/fx-outlined.png" "$work/fx-scene.png" || fail "a scene run's effects differ from the options'"
python3 - "$work" <<'PY' || fail "the effects do not land where they should"
import sys
from read_png import read_png
def pixels(name):
    width, height, channels, data = read_png(sys.argv[1] + "/" + name)
    return width, height, [tuple(data[i * channels:i * channels + 3]) for i in range(width * height)]
w, h, plain = pixels("fx-plain.png")
_, _, fx = pixels("fx-outlined.png")
_, _, bold = pixels("fx-bold.png")
dark = lambda p: max(p) < 96
red = lambda p: p[0] > 160 and p[1] < 96 and p[2] < 96
blue = lambda p: p[2] > 160 and p[0] < 96 and p[1] < 96
inked = [i for i, p in enumerate(plain) if dark(p)]
assert inked, "no ink"
# The glyph's own ink stays dark (the outline lies outside it, under it).
assert sum(dark(fx[i]) for i in inked) >= 0.9 * len(inked), "the face lost its ink"
reds = [i for i, p in enumerate(fx) if red(p)]
blues = [i for i, p in enumerate(fx) if blue(p)]
assert len(reds) > len(inked) // 2, ("too little outline", len(reds), len(inked))
assert blues, "no shadow"
cx = lambda ids: sum(i % w for i in ids) / len(ids)
cy = lambda ids: sum(i // w for i in ids) / len(ids)
assert cx(blues) > cx(inked) + 2 and cy(blues) > cy(inked) + 1.5, ("shadow not down and right", cx(blues), cx(inked))
assert sum(dark(p) for p in bold) > 1.2 * len(inked), "--weight 1 did not embolden"
PY

# With the validation layer (when installed), a clean run stays clean.
if [ -n "$(find /usr/share/vulkan /etc/vulkan -name 'VkLayer_khronos_validation.json' 2>/dev/null)" ]; then
  expect_exit 0 "render --validate" -- "$render" "${base[@]}" --layout gray --background 1,1,1,0.5 \
    -o "$work/validated.png" --validate --json
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['validation']=={'warnings':0,'errors':0}, r" \
    "$work/out" || fail "--validate --json does not report zero messages"
  python3 -c "import sys,struct; d=open(sys.argv[1],'rb').read(); assert struct.unpack('>B',d[25:26])[0]==6" \
    "$work/validated.png" || fail "a translucent background did not give an RGBA PNG"
  for mode in tiled draw unsorted wboit exact; do
    expect_exit 0 "render --validate --composite $mode" -- "$render" --scene "$work/example/overlap.json" \
      --samples 16 --composite "$mode" -o "$work/validated-$mode.png" --validate -q
  done
fi

# Issue 27: a scene run's spans. "nun" is underlined (without ink skipping, a solid line) and
# "mum" struck through in red; the underline and the strikethrough are painted beneath the text,
# the rows between and below the letters stay white elsewhere, and a reference mode says it leaves
# them out.
"$bake" "$source/fonts/DejaVuSans.ttf" --text "num " -o "$work/spans.crisp" -q || fail "crisp-bake num failed"
printf '%s' '{"fonts": ["spans.crisp"], "canvas": [160, 40], "runs": [{"text": "nun mum", "size": 24,
  "origin": [8, 24], "spans": [{"begin": 0, "end": 3, "underline": true, "skip_ink": false},
  {"begin": 4, "end": 7, "strikethrough": true, "color": [1, 0, 0]}]}]}' >"$work/spans.json"
expect_exit 0 "a scene with spans" -- "$render" --scene "$work/spans.json" -o "$work/spans.png" -q
python3 - "$work" <<'PY' || fail "the scene's underline and strikethrough are not where they should be"
import sys
from read_png import read_png
width, height, channels, data = read_png(sys.argv[1] + "/spans.png")
pixel = lambda x, y: data[(y * width + x) * channels:(y * width + x) * channels + 3]
# A line about a pixel thick lands on two rows, each about half covered: ink is anything not white.
dark = lambda x, y: max(pixel(x, y)) < 220
red = lambda x, y: pixel(x, y)[0] > 200 and pixel(x, y)[1] < 90
# "nun" lies over x 10 to about 51; on and below its baseline (y 24) only the underline.
under = [y for y in range(24, 32) if sum(dark(x, y) for x in range(10, 50)) >= 38]
assert under, "no underline below the baseline of nun"
assert not any(dark(x, y) for y in under for x in range(62, 160)), "the underline runs under mum"
# "mum" (from about x 60): a red row through the middle of its letters, across their gaps too.
struck = [y for y in range(8, 22) if sum(red(x, y) for x in range(62, 110)) > 40]
assert struck, "no strikethrough through mum"
PY
expect_exit 0 "a scene with spans, --composite exact" -- "$render" --scene "$work/spans.json" --composite exact \
  -o "$work/spans-exact.png"
expect_stderr "underlines and strikethroughs are not drawn" "a reference mode with decorations"

# The canvas is composited in bands of at most 32 MiB of target (issue 28, item 16): a 4096 x 4096
# canvas held whole copies of 256 MiB each (the image, its backdrop, the upload and readback, the
# PNG's pixels) and peaked at 1.07 GB of RSS on lavapipe; in bands 0.40 GB, as much as 8192 x 8192
# (was 3.43 GB), most of it the driver's and the renderer's. Held under a fifth of one canvas copy.
if [ -x /usr/bin/time ]; then
  expect_exit 0 "a 4096 x 4096 canvas" -- /usr/bin/time -f "%M" -o "$work/canvas-rss" \
    "$render" --font "$font" --text "Hi" --size 20 --origin 4,24 --canvas 4096,4096 --samples 1 -q -o "$work/big.png" \
    --coverage-out "$work/big.pfm"
  canvas_kib=$(tail -n 1 "$work/canvas-rss")
  [ "$canvas_kib" -lt $((600 * 1024)) ] || fail "a 4096 x 4096 canvas took $canvas_kib KiB, 600 MiB or more"
  [ "$(stat -c %s "$work/big.pfm")" -eq $((4096 * 4096 * 12 + 18)) ] || fail "the 4096 x 4096 PFM's size"
  rm -f "$work/big.pfm"
fi
# Bands change nothing: every mode's image (and the coverage) in bands of 16 rows is the whole
# canvas's, byte for byte, over a translucent background with an underline, an outline, a blurred
# shadow and a colour glyph's gradients crossing band edges.
cat >"$work/bands.json" <<'JSON'
{"fonts": ["dejavu.crisp", "colrv1.crisp"], "canvas": [100, 90], "background": [1, 1, 1, 0.6],
 "runs": [{"text": "Hi Hi", "size": 22, "origin": [3.3, 20.7], "underline": true, "color": [0.1, 0.2, 0.6]},
          {"text": "Hi", "size": 44, "origin": [10.5, 70.25], "outline": {"width": 1.5},
           "shadow": {"offset": [2, 2], "blur": 2}},
          {"font": 1, "text": "\ue000\ue002", "size": 30, "origin": [50, 85]}]}
JSON
for mode in tiled draw exact wboit unsorted; do
  expect_exit 0 "bands.json, $mode" -- "$render" --scene "$work/bands.json" --composite "$mode" --samples 8 -q \
    -o "$work/bands-whole.png" --coverage-out "$work/bands-whole.pfm"
  expect_exit 0 "bands.json, $mode, --band-rows 16" -- "$render" --scene "$work/bands.json" --composite "$mode" \
    --samples 8 -q --band-rows 16 -o "$work/bands-16.png" --coverage-out "$work/bands-16.pfm"
  cmp -s "$work/bands-whole.png" "$work/bands-16.png" || fail "$mode: the image in bands of 16 rows differs"
  cmp -s "$work/bands-whole.pfm" "$work/bands-16.pfm" || fail "$mode: the coverage in bands of 16 rows differs"
done
expect_exit 2 "--band-rows 20" -- "$render" "${base[@]}" --band-rows 20 -o x.png
expect_stderr "multiple of 16" "--band-rows 20"

if [ "$failures" -ne 0 ]; then
  echo "$failures crisp-render checks failed" >&2
  exit 1
fi
echo "all crisp-render checks passed"
