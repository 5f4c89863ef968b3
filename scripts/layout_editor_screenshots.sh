#!/usr/bin/env bash
# Regenerates the screenshots in docs/layout-editor.md with the editor's own --screenshot mode
# under Xvfb: scripts/layout_editor_screenshots.sh [BUILD_DIR] (default build).
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
# A layout file with a fault: crisp's reader's error, shown in the window.
printf '{"name": "broken", "r": [0, 0, 0.3, 1], "g": [0.3, 0, 0.6], "b": [0.6, 0, 1, 1]}\n' >"$work/broken.json"
(cd "$work" && shoot "$images/layout-editor-bad-file.png" 3 --layout broken.json)
