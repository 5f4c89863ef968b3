#!/usr/bin/env bash
# font_faults_test.sh CRISP_BAKE SOURCE_DIR WORK_DIR: faults of a font (issue 28, items 17-19) are
# refused with the exit code of a bad input and a message naming the glyph, the table or the
# limit, never as "the baked asset does not validate (a crisp bug)"; names from the font are
# printed escaped. The fonts are made by make_font_faults.py.
set -uo pipefail
bake=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$(dirname "${BASH_SOURCE[0]}")/cli_common.sh"
/usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/make_font_faults.py" "$source" "$work" ||  # Debian's python3 has fontTools
  { echo "make_font_faults.py failed" >&2; exit 1; }

# expect_fault CODE FONT TEXT...: crisp-bake FONT exits CODE and its stderr holds every TEXT.
expect_fault() {
  local code=$1 font=$2; shift 2
  expect_exit "$code" "$font" -- "$bake" "$work/$font" -o "$work/out.crisp" -q
  for text in "$@"; do expect_stderr "$text" "$font"; done
  ! grep -q "crisp bug" "$work/err" || fail "$font is reported as a crisp bug: $(cat "$work/err")"
  [ ! -e "$work/out.crisp" ] || fail "$font left an asset"
}

expect_fault 3 upem15.ttf "units per em is 15, outside the 16 to 16384 OpenType allows"
expect_fault 3 upem16385.ttf "units per em is 16385, outside the 16 to 16384 OpenType allows"
expect_fault 5 advance.ttf "glyph 1: advance 4095.938 em, beyond the asset's +-64 em"
expect_fault 5 bearing.otf "glyph 1: bearing_x -1875 em, beyond the asset's +-64 em"
expect_fault 3 maxp-cff.otf "maxp says the face has 7 glyphs, but the CFF table's CharStrings hold 2"
expect_fault 3 maxp-loca.ttf "maxp says the face has" "but loca's offsets hold"
expect_fault 3 bare.cff "a bare CFF font"

# A truncated font is an error naming the table it cuts (it baked its glyphs empty, or lost its axes).
size=$(stat -c %s "$source/fonts/Inter-roman.var.ttf")
for percent in 25 50 90; do
  head -c $((size * percent / 100)) "$source/fonts/Inter-roman.var.ttf" >"$work/cut$percent.ttf"
  expect_fault 3 "cut$percent.ttf" "table (" "runs past the font's end ($((size * percent / 100)) bytes): the font is truncated"
done
head -c 30 "$source/fonts/DejaVuSans.ttf" >"$work/cut-directory.ttf"
expect_fault 3 cut-directory.ttf "records run past the font's end (30 bytes)"

# An axis tag of ESC [ 2 J (it clears the terminal) is shown escaped by the report, --check and the
# refusal of an axis the font lacks.
expect_exit 0 "escape axis" -- "$bake" "$work/escape-axis.ttf" --text a -o "$work/escape.crisp"
grep -qF 'axes          \x1b[2J=' "$work/out" || fail "the report does not show the escaped tag: $(cat -v "$work/out")"
expect_exit 0 "check escape axis" -- "$bake" --check "$work/escape.crisp"
grep -qF 'axes        \x1b[2J=' "$work/out" || fail "--check does not show the escaped tag: $(cat -v "$work/out")"
expect_exit 3 "escape axis, no wght" -- "$bake" "$work/escape-axis.ttf" --var wght=400 -o "$work/x.crisp"
expect_stderr 'its axes are \x1b[2J' "escape axis, no wght"
if grep -q $'\x1b' "$work/out" "$work/err"; then fail "a raw ESC was printed"; fi

# Axis values past a float's range say so.
expect_exit 2 "--var wght=1e39" -- "$bake" "$source/fonts/Inter-roman.var.ttf" --var wght=1e39 -o "$work/x.crisp"
expect_stderr "is out of range for a 32-bit float" "--var wght=1e39"
# A font path with control characters is echoed escaped.
expect_exit 3 "a path with ESC" -- "$bake" "$work/"$'\x1b]0;title\x07'".ttf" -o "$work/x.crisp"
if grep -q $'\x1b' "$work/err"; then fail "a raw ESC from the path was printed: $(cat -v "$work/err")"; fi

if [ "$failures" -ne 0 ]; then
  echo "$failures font fault checks failed" >&2
  exit 1
fi
echo "all font fault checks passed"
