#!/usr/bin/env bash
# layout_editor_cli_test.sh EDITOR WORK_DIR: crisp-layout-editor's headless modes, with no display
# at all ($DISPLAY and $WAYLAND_DISPLAY unset, so a window would fail with exit 3). --export
# fontconfig prints well-formed fontconfig XML with the layout's rgba and lcdfilter, --export
# freetype FT_Library_SetLcdGeometry's positions; what a form cannot express is a note on stderr
# and the exit code stays 0; a bad --export value, a --layout that does not load (a mistyped preset
# named with the presets) and --export with window options are usage errors (exit 1); stdout that
# cannot be written is exit 5.
set -uo pipefail
editor=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
command -v python3 >/dev/null || { echo "FAIL: python3 is missing (scripts/setup.sh installs it)" >&2; exit 1; }
unset DISPLAY WAYLAND_DISPLAY

# The fontconfig XML parses, and its rgba and lcdfilter constants are: xml_constants FILE.
xml_constants() {
  python3 -c 'import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == "fontconfig", root.tag
match = root.find("match")
assert match.get("target") == "font", match.attrib
edits = {e.get("name"): (e.get("mode"), e.find("const").text) for e in match.findall("edit")}
assert all(mode == "assign" for mode, _ in edits.values()), edits
print(edits["rgba"][1], edits["lcdfilter"][1])' "$1"
}

# ---- fontconfig: the stripes map to their constant with no note; a triangle to none, said.
for preset in rgb bgr vrgb vbgr; do
  expect_exit 0 "--layout $preset --export fontconfig" -- "$editor" --layout "$preset" --export fontconfig
  [ "$(xml_constants "$work/out")" = "$preset lcddefault" ] || fail "$preset: $(cat "$work/out")"
  [ ! -s "$work/err" ] || fail "$preset: a note where the form expresses everything: $(cat "$work/err")"
done
expect_exit 0 "--layout qd-oled --export fontconfig" -- "$editor" --layout qd-oled --export fontconfig
[ "$(xml_constants "$work/out")" = "none lcdnone" ] || fail "qd-oled: $(cat "$work/out")"
expect_stderr "note: the channels are neither side by side nor stacked" "qd-oled's triangle"
grep -q "<!-- Not expressed: the channels are neither" "$work/out" || fail "qd-oled: no comment in the XML"

# ---- freetype: the centres in 1/64 pixel, y up.
expect_exit 0 "--layout rgb --export freetype" -- "$editor" --layout rgb --export freetype
grep -qF "FT_Vector sub[3] = {{-21, 0}, {0, 0}, {21, 0}};" "$work/out" || fail "rgb freetype: $(cat "$work/out")"
expect_stderr "note: the rectangles' sizes are not expressed" "rgb freetype"
expect_exit 0 "--layout qd-oled --export freetype" -- "$editor" --layout qd-oled --export freetype
grep -qF "FT_Vector sub[3] = {{-16, -16}, {0, 16}, {16, -16}};" "$work/out" || fail "qd-oled freetype: $(cat "$work/out")"

# ---- A layout file, with contrast settings neither form has.
cat >"$work/monitor.json" <<'JSON'
{"name": "monitor", "r": [0.5, 0, 1, 1], "g": [0.25, 0, 0.5, 1], "b": [0, 0, 0.25, 1],
 "contrast": {"gamma": 1.8}}
JSON
expect_exit 0 "--export fontconfig of a file" -- "$editor" --layout "$work/monitor.json" --export fontconfig
[ "$(xml_constants "$work/out")" = "bgr lcddefault" ] || fail "monitor.json: $(cat "$work/out")"
expect_stderr "the stripes' widths and positions are not expressed" "monitor.json's uneven stripes"
expect_stderr "the contrast settings (mode corrected, gamma 1.8" "monitor.json's contrast"
grep -q '"monitor", exported by crisp-layout-editor' "$work/out" || fail "monitor.json: the name is not said"

# ---- Usage errors: exit 1, the message names what is wrong.
expect_exit 1 "--export xft" -- "$editor" --layout rgb --export xft
expect_stderr "--export takes fontconfig or freetype, not 'xft'" "--export xft"
[ ! -s "$work/out" ] || fail "--export xft printed: $(cat "$work/out")"
expect_exit 1 "--export of a missing file" -- "$editor" --layout "$work/missing.json" --export fontconfig
expect_stderr "missing.json" "--export of a missing file"
expect_exit 1 "--export of a mistyped preset" -- "$editor" --layout qd-olde --export fontconfig
expect_stderr "nor is it a preset (gray, rgb, bgr, vrgb, vbgr, qd-oled, woled, pentile)" "--layout qd-olde"
printf '{"r": [0, 0, 1, 1]' >"$work/truncated.json"
expect_exit 1 "--export of a truncated file" -- "$editor" --layout "$work/truncated.json" --export freetype
expect_stderr "truncated.json" "--export of a truncated file"
expect_exit 1 "--export with --frames" -- "$editor" --export fontconfig --frames 1
expect_stderr "--export prints and quits" "--export with --frames"

# ---- stdout that cannot be written.
if [ -w /dev/full ]; then
  "$editor" --layout rgb --export fontconfig >/dev/full 2>"$work/err"
  code=$?
  [ "$code" -eq 5 ] || fail "--export onto /dev/full: exit $code, want 5"
  expect_stderr "stdout could not be written" "--export onto /dev/full"
fi

[ "$failures" -eq 0 ] || { echo "$failures failures" >&2; exit 1; }
echo "crisp-layout-editor headless: all checks passed"
