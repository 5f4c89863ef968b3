#!/usr/bin/env bash
# Regenerates the screenshots in docs/layout-editor.md with the editor's own --screenshot mode
# under Xvfb, and three of the window driven with xdotool (xwd's picture of the display, made a
# PNG with PIL): scripts/layout_editor_screenshots.sh [BUILD_DIR] (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
editor=$PWD/$build/tools/crisp-layout-editor
images=$PWD/docs/images
[ -x "$editor" ] || { echo "no $editor: build first (./scripts/build.sh $build)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The pictures never show the person's own recent files (nor a note about them).
export XDG_CONFIG_HOME="$work/config"
shoot() {  # shoot OUTPUT FRAMES [editor options...]
  local out=$1 frames=$2; shift 2
  xvfb-run -a -s "-screen 0 1280x800x24" "$editor" --validation --frames "$frames" --screenshot "$out" "$@"
}
# Converged (256 samples a glyph after about 70 frames), from rgb and from QD-OLED's triangles.
shoot docs/images/layout-editor-rgb.png 80 --layout rgb
shoot docs/images/layout-editor-qd-oled.png 80 --layout qd-oled
# A custom layout three frames after it was loaded: the preview still converging.
shoot docs/images/layout-editor-converging.png 3 --layout docs/examples/layout-bgr-short-red.json
# A layout file with its monitor's contrast settings: lighter gamma, enhanced contrast, stem darkening.
printf '{"name": "bgr-heavy", "r": [0.6666667, 0, 1, 1], "g": [0.33333334, 0, 0.6666667, 1], "b": [0, 0, 0.33333334, 1], "contrast": {"mode": "corrected", "gamma": 1.8, "contrast": 1, "stem_darkening": 1}}\n' >"$work/bgr-heavy.json"
(cd "$work" && shoot "$images/layout-editor-contrast.png" 80 --layout bgr-heavy.json)
# The preview with a text, sizes and colours of its own, zoomed 4x: the right panel shows the
# outlined pixels of the left one magnified.
shoot docs/images/layout-editor-preview.png 80 --layout rgb --text "Hamburgefonstiv: the quick brown fox, 0123456789" \
  --sizes "12 24" --colours yellow-on-blue --zoom 4
# Compare mode: rgb's candidates side by side (itself, the order reversed, narrower, wider).
shoot docs/images/layout-editor-compare.png 100 --layout rgb --compare
# A layout file with a fault: crisp's reader's error, shown in the window.
printf '{"name": "broken", "r": [0, 0, 0.3, 1], "g": [0.3, 0, 0.6], "b": [0.6, 0, 1, 1]}\n' >"$work/broken.json"
(cd "$work" && shoot "$images/layout-editor-bad-file.png" 3 --layout broken.json)
# Driven with xdotool (the prompt and the fields' editing need input; --frames runs never ask): the
# recent files' list, the preview's text field selected with Ctrl+A, and the quit prompt.
cat >"$work/interactive.sh" <<'SH'
set -euo pipefail
editor=$1 images=$2 work=$3
cd "$work"
# xwd's picture of the display as a PNG (the 32-bit TrueColor Xvfb gives).
snap() {
  xwd -root -silent >"$work/snap.xwd"
  /usr/bin/python3 - "$work/snap.xwd" "$1" <<'PY'
import struct, sys
from PIL import Image
data = open(sys.argv[1], "rb").read()
header = struct.unpack(">25I", data[:100])
size, width, height, order, bpl, ncolors = header[0], header[4], header[5], header[7], header[12], header[19]
masks = header[14:17]
pixels = data[size + 12 * ncolors:]
image = Image.new("RGB", (width, height))
out = image.load()
for y in range(height):
    row = pixels[y * bpl:(y + 1) * bpl]
    for x in range(width):
        value = int.from_bytes(row[4 * x:4 * x + 4], "little" if order == 0 else "big")
        out[x, y] = tuple((value & m) >> ((m & -m).bit_length() - 1) for m in masks)
image.save(sys.argv[2])
PY
}
centre() {  # centre KEY [SUBKEY]: a widget's centre from --print-geometry
  "$editor" --print-geometry | python3 -c 'import json,sys; g=json.load(sys.stdin); r=g[sys.argv[1]]
r=r[sys.argv[2]] if len(sys.argv) > 2 else r; print(int(r[0] + r[2] / 2), int(r[1] + r[3] / 2))' "$@"
}
"$editor" --validation --layout rgb --save-to my-monitor.json &
pid=$!
xdotool search --sync --name '^crisp layout editor$' >/dev/null
sleep 40  # converged on lavapipe
read -r x y < <(centre recent_button)
xdotool mousemove "$x" "$y" click 1
sleep 3
snap "$images/layout-editor-recent.png"
xdotool key Escape
read -r x y < <(centre preview_controls text)
xdotool mousemove "$x" "$y" click 1
xdotool key ctrl+a
sleep 3
snap "$images/layout-editor-field.png"
xdotool key Escape Right
sleep 2
xdotool key ctrl+q
sleep 3
snap "$images/layout-editor-quit-prompt.png"
xdotool key d
wait "$pid"
SH
# A list of recent files of its own, as a person's would be after a few saves (the paths made up).
mkdir -p "$XDG_CONFIG_HOME/crisp"
printf '%s\n' /home/you/layouts/my-monitor.json /home/you/layouts/office-qd-oled.json \
  /home/you/layouts/laptop-bgr.json >"$XDG_CONFIG_HOME/crisp/layout-editor-recent"
xvfb-run -a -s "-screen 0 1280x800x24" bash "$work/interactive.sh" "$editor" "$images" "$work"
