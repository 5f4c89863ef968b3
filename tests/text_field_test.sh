#!/usr/bin/env bash
# text_field_test.sh EXAMPLE WORK_DIR: the text field of crisp-engine-example (examples/engine,
# docs/integration.md) under Xvfb, driven by xdotool (mouse and keys) and XTEST (typed text, see
# type_text below), with the validation layer on.
#
# One session with a steady caret (--caret-blink 0): after each step F9 takes a snapshot (the
# report and the screenshot of the next frame, --snapshots), and the test waits for it before the
# next step. Steps: the field as it starts (no focus, no caret); a click after the text's end;
# typing Latin and Arabic; Backspace; Shift+Left twice; a mouse drag over the start; Shift+click
# farther right; a click in the Arabic word, then Right and Left, which move the caret that way on
# screen; Ctrl+A and typing, which replaces all; "e" and a combining accent, which one Backspace
# removes; Home, Delete, End, Ctrl+Left, Shift+End; End and typing past the field's width, which
# scrolls; Escape, after which typed keys leave the text alone. Each snapshot's report is checked
# (text, caret, selection), and its screenshot: text ink inside the field, the selection colour
# filling each of the report's selection rects, the caret's colour in its rect when the report says
# it is shown and not when not. Ctrl+Q ends it, exit code 0 (the validation layer said nothing). A
# second session (--caret-blink 150) samples the caret over a second or two: it is seen both shown
# and hidden, and the pixels agree with the report each time.
set -uo pipefail
example=$(realpath "$1") work=$(realpath -m "$2")
if [ "${TEXT_FIELD_TEST_INNER:-}" != 1 ]; then
  for tool in xvfb-run xdotool python3; do
    command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (scripts/setup.sh installs it)" >&2; exit 1; }
  done
  rm -rf "$work" && mkdir -p "$work"
  # -n: start looking for a free display away from the other Xvfb tests, which may run at once.
  TEXT_FIELD_TEST_INNER=1 exec xvfb-run -a -n 190 -s "-screen 0 1024x768x24" bash "$0" "$@"
fi

cp "$(dirname "$(realpath "$0")")/png_rgb.py" "$work/" || { echo "FAIL: no png_rgb.py beside $0" >&2; exit 1; }
cd "$work"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
cat >check_field.py <<'PY'
#!/usr/bin/env python3
"""Checks one snapshot of crisp-engine-example's text field (tests/text_field_test.sh).

check_field.py PREFIX-N EXPECT_JSON: PREFIX-N.json's field against EXPECT_JSON (keys: text, caret,
selection, focused, each where given; caret_in [lo, hi]; selection_end_in [lo, hi]), then
PREFIX-N.png: text ink inside the field's box, the selection colour over each selection rect, the
caret's colour filling the caret rect when shown and not when hidden. Prints each failure;
exit status 1 when there is one.
"""
import json
import sys

from png_rgb import read_png


def selection_colour(p):  # linear (0.05, 0.20, 0.60) is sRGB about (63, 124, 203)
    return abs(p[0] - 63) <= 12 and abs(p[1] - 124) <= 12 and abs(p[2] - 203) <= 12


def caret_colour(p):  # linear (1.0, 0.45, 0.05) is sRGB about (255, 178, 63)
    return p[0] >= 235 and 160 <= p[1] <= 196 and 40 <= p[2] <= 90


def light(p):
    return max(p) >= 150


def main():
    stem, expect = sys.argv[1], json.loads(sys.argv[2])
    field = json.load(open(stem + ".json"))["field"]
    width, height, pixels = read_png(stem + ".png")
    failures = []

    def region(rect, inset=0):
        x0, y0 = max(int(rect["x"] + inset), 0), max(int(rect["y"] + inset), 0)
        x1 = min(int(rect["x"] + rect["width"] - inset + 0.999), width)
        y1 = min(int(rect["y"] + rect["height"] - inset + 0.999), height)
        return [pixels[(y * width + x) * 3:(y * width + x) * 3 + 3] for y in range(y0, y1) for x in range(x0, x1)]

    for key in ("text", "caret", "selection", "focused", "caret_visible"):
        if key in expect and field[key] != expect[key]:
            failures.append(f"{key} is {field[key]!r}, want {expect[key]!r}")
    for key, value in (("caret_in", field["caret"]), ("selection_end_in", field["selection"][1])):
        if key in expect and not expect[key][0] <= value <= expect[key][1]:
            failures.append(f"{key}: {value} not in {expect[key]}")
    if field["bytes"] != len(field["text"].encode()):
        failures.append(f"bytes {field['bytes']} for a text of {len(field['text'].encode())}")
    begin, end = field["selection"]
    if begin != min(field["anchor"], field["caret"]) or end != max(field["anchor"], field["caret"]):
        failures.append(f"selection {field['selection']} is not anchor {field['anchor']} to caret {field['caret']}")
    if (begin == end) != (not field["selection_rects"]):
        failures.append(f"selection {field['selection']} with {len(field['selection_rects'])} rects")

    box = field["box"]
    inner = region(box, 3)
    ink = sum(1 for p in inner if light(p))
    # Text covers a few percent of the field; a short text about 40 pixels a character at 15 px.
    if field["text"] and not min(0.03 * len(inner), 20 * len(field["text"])) <= ink <= 0.6 * len(inner):
        failures.append(f"{ink} of {len(inner)} pixels in the field are text-light")
    for rect in field["selection_rects"]:
        if not (box["x"] <= rect["x"] and rect["x"] + rect["width"] <= box["x"] + box["width"]):
            failures.append(f"selection rect {rect} leaves the field {box}")
        shown = region(rect, 0.5)
        # Text over the highlight takes some of its pixels; most keep its colour.
        if sum(1 for p in shown if selection_colour(p)) < 0.4 * len(shown):
            failures.append(f"selection rect {rect}: {sum(1 for p in shown if selection_colour(p))} "
                            f"of {len(shown)} pixels in the highlight's colour")
    caret = field["caret_rect"]
    if not (box["x"] <= caret["x"] and caret["x"] + caret["width"] <= box["x"] + box["width"]):
        failures.append(f"caret rect {caret} leaves the field {box}")
    if field["caret_visible"]:
        on = sum(1 for p in region(caret) if caret_colour(p))
        if on < 0.5 * max(len(region(caret)), 1):
            failures.append(f"caret rect {caret}: {on} of {len(region(caret))} pixels in the caret's colour")
        if not (box["y"] <= caret["y"] and caret["y"] + caret["height"] <= box["y"] + box["height"]):
            failures.append(f"caret rect {caret} leaves the field {box}")
    elif sum(1 for p in region(caret) if caret_colour(p)) > 0.2 * len(region(caret)):
        # Subpixel anti-aliasing tints the edges of white text, some of them orange: only a run
        # of the caret's colour down its rect is a caret.
        failures.append(f"the caret is hidden, yet its rect {caret} is in its colour")
    for failure in failures:
        print(f"check_field {stem}: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
PY

# type_text TEXT: each character of TEXT pressed and released through XTEST, on a keycode bound to
# its Unicode keysym for good. (xdotool type binds a character that is not on the keyboard to a
# spare keycode only while it types it and unbinds it at once, so that a program that reads its
# events once a frame, as the example does, finds the keycode unbound or bound to a later
# character when it looks the key up: Arabic came out missing or repeated.)
cat >type_text.py <<'PY'
import ctypes, sys, time
x11, xtest = ctypes.CDLL("libX11.so.6"), ctypes.CDLL("libXtst.so.6")
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XGetKeyboardMapping.restype = ctypes.POINTER(ctypes.c_ulong)
x11.XGetKeyboardMapping.argtypes = [ctypes.c_void_p, ctypes.c_ubyte, ctypes.c_int, ctypes.POINTER(ctypes.c_int)]
x11.XChangeKeyboardMapping.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.POINTER(ctypes.c_ulong),
                                       ctypes.c_int]
x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
xtest.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
display = x11.XOpenDisplay(None)
assert display, "no display"
per = ctypes.c_int()
table = x11.XGetKeyboardMapping(display, 8, 248, ctypes.byref(per))
row = lambda i: [table[i * per.value + j] for j in range(per.value)]
# Keycodes this script bound before (one Unicode keysym alone), and the unbound ones (9 and up).
bound = {chr(row(i)[0] - 0x1000000): 8 + i for i in range(248)
         if row(i)[0] >= 0x1000000 and not any(row(i)[1:])}
free = [8 + i for i in range(1, 248) if not any(row(i))]
for c in dict.fromkeys(sys.argv[1]):
    if c not in bound:
        bound[c] = free.pop(0)
        x11.XChangeKeyboardMapping(display, bound[c], 1, (ctypes.c_ulong * 1)(0x1000000 + ord(c)), 1)
x11.XSync(display, 0)
for c in sys.argv[1]:
    xtest.XTestFakeKeyEvent(display, bound[c], 1, 0)
    xtest.XTestFakeKeyEvent(display, bound[c], 0, 0)
    x11.XSync(display, 0)
    time.sleep(0.04)
PY
type_text() { python3 type_text.py "$1" || fail "type_text $1"; }

# session PREFIX ARGS...: starts the example in a 640x400 window with the validation layer, taking
# snapshots PREFIX-N, and waits for its window.
session() {
  prefix=$1
  shift
  "$example" --validation --size 640x400 --snapshots "$prefix" "$@" 2>"$prefix.err" &
  pid=$!
  window=$(timeout 60 xdotool search --sync --name '^crisp engine example$' | head -n1)
  [ -n "$window" ] || { fail "no window: $(head -c 2000 "$prefix.err")"; kill "$pid"; exit 1; }
  xdotool mousemove --window "$window" 400 100
  xdotool windowfocus --sync "$window" 2>/dev/null || true
  taken=0
}
# snapshot: F9, then wait until PREFIX-N.json is there (every earlier event is in it).
snapshot() {
  taken=$((taken + 1))
  xdotool key F9
  for _ in $(seq 1 600); do [ -f "$prefix-$taken.json" ] && return 0; sleep 0.1; done
  fail "snapshot $taken never came: $(head -c 2000 "$prefix.err")"
  kill "$pid"
  exit 1
}
# check EXPECT_JSON: the last snapshot.
check() { python3 check_field.py "$prefix-$taken" "$1" || fail "$prefix-$taken"; }
# field KEY: a number from the last snapshot's field (box.x and the like: dotted).
field() {
  python3 -c 'import json,sys
value = json.load(open(sys.argv[1]))["field"]
for key in sys.argv[2].split("."): value = value[int(key)] if isinstance(value, list) else value[key]
print(int(round(value)))' "$prefix-$taken.json" "$1"
}
# end: Ctrl+Q, then the exit code (0: the validation layer said nothing, teardown included).
end() {
  xdotool key ctrl+q
  for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
  kill -0 "$pid" 2>/dev/null && { fail "the example did not quit on Ctrl+Q"; kill "$pid"; }
  wait "$pid"
  local code=$?
  [ "$code" -eq 0 ] || fail "the example exited $code (4: the validation layer spoke): $(head -c 2000 "$prefix.err")"
}

start_text='Type here: مرحبا بالعالم and more'
start_bytes=$(printf '%s' "$start_text" | wc -c)
arabic_begin=$(printf '%s' 'Type here: ' | wc -c)
arabic_end=$(printf '%s' 'Type here: مرحبا بالعالم' | wc -c)
typed=' سلام ok'
after_typing="$start_text$typed"
typed_bytes=$(printf '%s' "$after_typing" | wc -c)
json() { python3 -c 'import json,sys; print(json.dumps(dict(zip(sys.argv[1::2], map(json.loads, sys.argv[2::2])))))' "$@"; }
quote() { python3 -c 'import json,sys; print(json.dumps(sys.argv[1]))' "$1"; }

# ---- The steady session.
session step --caret-blink 0
snapshot
check "$(json text "$(quote "$start_text")" focused false caret_visible false selection "[$start_bytes, $start_bytes]")"
bx=$(field box.x) by=$(field box.y) bw=$(field box.width) bh=$(field box.height) tx=$(field text_x)
mid=$((by + bh / 2))
# A click right of the text's end puts the caret there.
xdotool mousemove --window "$window" $((bx + bw - 4)) "$mid" click 1
snapshot
check "$(json focused true caret "$start_bytes" selection "[$start_bytes, $start_bytes]" caret_visible true)"
type_text "$typed"
snapshot
check "$(json text "$(quote "$after_typing")" caret "$typed_bytes" selection "[$typed_bytes, $typed_bytes]")"
xdotool key BackSpace
snapshot
check "$(json text "$(quote "${after_typing%k}")" caret $((typed_bytes - 1)))"
# " o" after the Arabic word reads left to right (the paragraph's direction): Left goes back in it.
xdotool key shift+Left shift+Left
snapshot
check "$(json selection "[$((typed_bytes - 3)), $((typed_bytes - 1))]" caret $((typed_bytes - 3)))"
# A drag from the text's start over about "Type h" selects from 0.
xdotool mousemove --window "$window" $((tx + 1)) "$mid" mousedown 1
xdotool mousemove --window "$window" $((tx + 20)) "$mid"
xdotool mousemove --window "$window" $((tx + 44)) "$mid" mouseup 1
snapshot
check "$(json selection_end_in "[4, 8]" caret_in "[4, 8]")"
[ "$(field selection.0)" = 0 ] || fail "the drag's selection starts at $(field selection.0), want 0"
dragged=$(field caret)
xdotool keydown shift mousemove --window "$window" $((tx + 84)) "$mid" click 1 keyup shift
snapshot
# TEXT_FIELD_PICTURE=PATH.png: this snapshot's field, twice its size, for docs/integration.md.
if [ -n "${TEXT_FIELD_PICTURE:-}" ]; then
  python3 - "$prefix-$taken" "$TEXT_FIELD_PICTURE" <<'PY' || fail "TEXT_FIELD_PICTURE"
import json, struct, sys, zlib
from png_rgb import read_png
width, _, pixels = read_png(sys.argv[1] + ".png")
box = json.load(open(sys.argv[1] + ".json"))["field"]["box"]
x0, y0, x1, y1 = int(box["x"]) - 8, int(box["y"]) - 8, int(box["x"] + box["width"]) + 8, int(box["y"] + box["height"]) + 8
rows = []
for y in range(y0, y1):
    row = b"".join(pixels[(y * width + x) * 3:(y * width + x) * 3 + 3] * 2 for x in range(x0, x1))
    rows += [row, row]
chunk = lambda kind, body: struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
header = struct.pack(">IIBBBBB", 2 * (x1 - x0), len(rows), 8, 2, 0, 0, 0)
data = zlib.compress(b"".join(b"\0" + row for row in rows), 9)
open(sys.argv[2], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", data) + chunk(b"IEND", b""))
PY
fi
[ "$(field selection.0)" = 0 ] || fail "Shift+click: the selection starts at $(field selection.0), want 0"
[ "$(field caret)" -gt "$dragged" ] || fail "Shift+click: caret $(field caret), not past the drag's $dragged"
check '{}'
# A click inside the Arabic words puts the caret between their characters.
ax=$(python3 -c 'import json,sys
rects = json.load(open(sys.argv[1]))["field"]["selection_rects"]
print(int(rects[0]["x"] + rects[0]["width"]) + 30)' "$prefix-$taken.json")
xdotool mousemove --window "$window" "$ax" "$mid" click 1
snapshot
check "$(json caret_in "[$((arabic_begin + 2)), $((arabic_end - 2))]")"
# Right and Left move the caret on screen: in the Arabic, Right goes back through the text.
clicked=$(field caret) clicked_x=$(field caret_rect.x)
xdotool key Right
snapshot
check '{}'
[ "$(field caret_rect.x)" -gt "$clicked_x" ] && [ "$(field caret)" -lt "$clicked" ] ||
  fail "Right in the Arabic: caret $(field caret) at x $(field caret_rect.x), from $clicked at x $clicked_x"
xdotool key Left Left
snapshot
check '{}'
[ "$(field caret_rect.x)" -lt "$clicked_x" ] && [ "$(field caret)" -gt "$clicked" ] ||
  fail "Left twice in the Arabic: caret $(field caret) at x $(field caret_rect.x), from $clicked at x $clicked_x"
xdotool key ctrl+a
type_text done
snapshot
check "$(json text '"done"' caret 4 selection '[4, 4]')"
# "e" and a combining acute accent are one grapheme: one Backspace takes both.
type_text $'e\xcc\x81'
snapshot
check "$(json text "$(quote $'donee\xcc\x81')" caret 7)"
xdotool key BackSpace
snapshot
check "$(json text '"done"' caret 4)"
xdotool key Home Delete End ctrl+Left shift+End
snapshot
check "$(json text '"one"' caret 3 selection '[0, 3]')"
# Typing past the field's width scrolls the text: the caret stays inside the field.
long=$(printf 'w%.0s' $(seq 1 40))
xdotool key End
type_text "$long"
snapshot
check "$(json text "\"one$long\"" caret 43 selection '[43, 43]' caret_visible true)"
[ "$(field text_x)" -lt "$tx" ] || fail "the long text did not scroll: it starts at $(field text_x), the field's text at $tx"
xdotool key Escape
type_text xy
snapshot
check "$(json text "\"one$long\"" focused false caret_visible false)"
end

# ---- The blinking caret: shown and hidden in turn, the pixels as the report says.
session blink --caret-blink 150
snapshot
bx=$(field box.x) by=$(field box.y) bw=$(field box.width) bh=$(field box.height)
xdotool mousemove --window "$window" $((bx + bw - 4)) $((by + bh / 2)) click 1
shown=0 hidden=0
for _ in $(seq 1 12); do
  sleep 0.11
  snapshot
  check '{"focused": true}'
  if [ "$(field caret_visible)" = 1 ]; then shown=$((shown + 1)); else hidden=$((hidden + 1)); fi
done
[ "$shown" -gt 0 ] && [ "$hidden" -gt 0 ] || fail "the caret did not blink: shown in $shown snapshots, hidden in $hidden"
end

if [ "$failures" -ne 0 ]; then
  echo "text_field_test: $failures failure(s); files in $work" >&2
  exit 1
fi
echo "text_field_test: ok"
