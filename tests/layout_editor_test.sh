#!/usr/bin/env bash
# layout_editor_test.sh EDITOR CRISP_RENDER CRISP_BAKE SOURCE_DIR WORK_DIR: runs crisp-layout-editor
# under Xvfb on whatever Vulkan device there is (lavapipe in CI) with the validation layer on, and
# drives it with xdotool: pick the bgr preset, drag the red rectangle's bottom edge up 24 screen
# pixels, nudge it one step left, undo and redo the nudge, type 0.125 into its y0 field, Tab to its
# x1 field and type 0.95, Shift+Tab back to y0 and type 0.25, raise the contrast model's gamma one
# step (G), save (Ctrl+S), quit (Ctrl+Q). Checks that the saved JSON is exactly bgr with those
# edits, its numbers on the 1/96 grid exact and every number in its shortest form (0.65625, 0.95),
# and the default contrast with gamma 2.3, that
# crisp-render accepts it, that the editor exits 0 (so the validation layer stayed silent), and
# that screenshots of the display before and after the edit show the preview, the magnified pixel
# and the magnified rendered pixels, each not blank and each changed by the edit. Also: a bad
# --layout file is reported (not fatal) and the --screenshot mode writes a PNG of the window, never
# onto its own --layout or --font file; FIFOs as --font or --layout are refused without a hang.
# The window: --window WxH screenshots are that size, filled (not mostly black), with the status
# line drawn at the bottom; and the editor idles (next to no CPU) once the preview has converged.
# Files: the path field edited in place (click, Home, type, End, Backspace, Enter) and saved
# under that name; Ctrl+Q with unsaved changes asks (the prompt in a screenshot, the editor still
# running), Escape cancels, closing the window asks again, and D discards; the recent files
# written and, at the next start, Up in the path field brings the newest back and a click in the
# Recent list chooses another; a bad recent-files list is reported, not fatal. The preview: a text
# typed into its field changes the paragraphs' pixels; --text, --sizes, --colours and --zoom.
# Compare mode: candidate panels that differ where the text is, picked by a click and a key,
# left with Escape and V, the picked layout saved; --compare.
# XDG_CONFIG_HOME points into WORK_DIR: a person's own recent files are never touched.
set -uo pipefail
editor=$1 render=$2 bake=$3 source=$4 work=$5

if [ "${LAYOUT_EDITOR_TEST_INNER:-}" != 1 ]; then
  for tool in xvfb-run xdotool xwd python3; do
    command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (scripts/setup.sh installs it)" >&2; exit 1; }
  done
  rm -rf "$work" && mkdir -p "$work"
  LAYOUT_EDITOR_TEST_INNER=1 exec xvfb-run -a -s "-screen 0 1280x800x24" bash "$0" "$@"
fi

cd "$work"
export XDG_CONFIG_HOME="$work/config"
recent_list="$XDG_CONFIG_HOME/crisp/layout-editor-recent"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
geometry=$("$editor" --print-geometry) || { echo "FAIL: --print-geometry" >&2; exit 1; }
echo "$geometry" >geometry.json
# Window pixel coordinates of a widget's centre: center NAME (a preset or a command).
center() {
  python3 -c 'import json,sys; g=json.load(open("geometry.json")); n=sys.argv[1]
r=g["presets"].get(n) or g["commands"][n]; print(int(r[0]+r[2]/2), int(r[1]+r[3]/2))' "$1"
}
shot() { xwd -root -silent >"$1" || fail "xwd $1"; }
# The screenshots' reader and checks: python3 screens.py ready SHOT | compare BEFORE AFTER.
cat >screens.py <<'PY'
import json, struct, sys

def read_xwd(path):
    data = open(path, "rb").read()
    header = struct.unpack(">25I", data[:100])
    header_size, width, height = header[0], header[4], header[5]
    bits_per_pixel, bytes_per_line, byte_order = header[11], header[12], header[7]
    ncolors = header[19]
    assert bits_per_pixel == 32, bits_per_pixel
    pixels = data[header_size + 12 * ncolors:]
    masks = header[14:17]  # red, green and blue masks
    def at(x, y):
        off = y * bytes_per_line + 4 * x
        value = int.from_bytes(pixels[off:off + 4], "little" if byte_order == 0 else "big")
        return tuple((value & m) >> (m & -m).bit_length() - 1 for m in masks)
    return width, height, at

def region(g, name):
    x, y, w, h = (int(v) for v in g[name])
    return [(px, py) for py in range(y, y + h, 2) for px in range(x, x + w, 2)]

VIEWS = ("magnified_pixel", "preview", "rendered_pixels")

def blank_views(g, image):
    return [name for name in VIEWS if len(set(image(x, y) for x, y in region(g, name))) <= 20]

g = json.load(open("geometry.json"))
if sys.argv[1] == "ready":  # ready SHOT: exit 0 once every view is drawn (more than 20 colours)
    w, h, image = read_xwd(sys.argv[2])
    sys.exit(1 if blank_views(g, image) else 0)

if sys.argv[1] == "changed":  # changed NAME BEFORE AFTER: the region NAME differs
    _, _, before = read_xwd(sys.argv[3])
    _, _, after = read_xwd(sys.argv[4])
    points = region(g, sys.argv[2])
    count = sum(1 for x, y in points if max(abs(a - b) for a, b in zip(before(x, y), after(x, y))) > 40)
    print(f"{sys.argv[2]}: {count} of {len(points)} samples changed")
    sys.exit(0 if count > len(points) // 100 else 1)

if sys.argv[1] == "prompt":  # prompt SHOT: the quit prompt is drawn (its box, border and text)
    _, _, image = read_xwd(sys.argv[2])
    x, y, w, h = (int(v) for v in g["prompt"]["box"])
    inside = [image(px, py) for py in range(y + 2, y + h - 2, 2) for px in range(x + 2, x + w - 2, 2)]
    near = lambda p, q: max(abs(a - b) for a, b in zip(p, q)) <= 3
    box = sum(1 for p in inside if near(p, (30, 32, 36)))
    light = sum(1 for p in inside if min(p) > 150)
    border = [image(px, y) for px in range(x, x + w)]
    gold = sum(1 for p in border if near(p, (230, 180, 60)))
    print(f"prompt: {box} of {len(inside)} samples its colour, {light} light, border {gold} of {len(border)}")
    sys.exit(0 if box > len(inside) // 2 and light > 40 and gold > len(border) * 9 // 10 else 1)

if sys.argv[1] == "panels":  # panels SHOT yes|no: compare mode's candidate panels are shown (or not)
    _, _, image = read_xwd(sys.argv[2])
    panels = [[int(v) for v in r] for r in g["candidates"]]
    near = lambda p, q: max(abs(a - b) for a, b in zip(p, q)) <= 3
    # Each panel's label bar (the button colour) across its top.
    bars = [sum(1 for px in range(x + 2, x + w - 2, 4) if near(image(px, y + 4), (64, 68, 76))) * 4 > w * 3 // 4
            for x, y, w, h in panels]
    print(f"panels {sys.argv[2]}: label bars {bars}")
    if sys.argv[3] == "no":
        sys.exit(0 if not any(bars) else 1)
    if not all(bars):
        sys.exit(1)
    # Where the text is (below the label bar, a sample dark in either panel), every two panels
    # differ: each is rendered with its own layout. Converging samples move a pixel by less than 8.
    x0, y0, w, h = panels[0]
    offsets = [(dx, dy) for dy in range(26, h - 4) for dx in range(4, w - 4)]
    ok = True
    for i in range(len(panels)):
        for j in range(i):
            (xi, yi, _, _), (xj, yj, _, _) = panels[i], panels[j]
            ink = differ = 0
            for dx, dy in offsets:
                p, q = image(xi + dx, yi + dy), image(xj + dx, yj + dy)
                if min(p) < 200 or min(q) < 200:
                    ink += 1
                    differ += max(abs(a - b) for a, b in zip(p, q)) >= 8
            print(f"panels {i + 1} and {j + 1}: {differ} of {ink} text samples differ")
            ok = ok and ink > 1000 and differ > ink // 20
    sys.exit(0 if ok else 1)

# compare BEFORE AFTER
w0, h0, before = read_xwd(sys.argv[2])
w1, h1, after = read_xwd(sys.argv[3])
assert (w0, h0) == (w1, h1) == tuple(g["window"]), (w0, h0, w1, h1)

def changed(name):
    # A sample changed by the edit: some channel moved by more than converging samples move it.
    points = region(g, name)
    count = sum(1 for x, y in points if max(abs(a - b) for a, b in zip(before(x, y), after(x, y))) > 40)
    return count, len(points)

for label, image in (("before", before), ("after", after)):
    blank = blank_views(g, image)
    assert not blank, f"{label}: {', '.join(blank)} blank (20 colours or fewer)"
# The preview's paragraphs (not its moving line, which changes every frame) and both magnified views.
for name in ("magnified_pixel", "preview_paragraphs", "rendered_pixels"):
    count, total = changed(name)
    assert count > total // 500, f"{name}: only {count} of {total} samples changed after the edit"
    print(f"{name}: {count} of {total} samples changed")
PY
# shot_when_drawn FILE SECONDS: frames take a while on lavapipe, longer on a loaded machine, so the
# screenshot waits SECONDS for the text to converge a little, and then until every view is drawn
# (checked every 2 s, for at most a minute more; the comparison below names a view left blank).
shot_when_drawn() {
  sleep "$2"
  for _ in $(seq 1 30); do
    shot "$1"
    python3 screens.py ready "$1" && return 0
    sleep 2
  done
}

# ---- The --screenshot mode: a PNG of the window after N frames.
"$editor" --validation --frames 3 --screenshot shot.png 2>screenshot.err
code=$?
[ "$code" -eq 0 ] || fail "--screenshot: exit $code: $(head -c 600 screenshot.err)"
python3 -c 'import sys; d=open("shot.png","rb").read(); sys.exit(not (d[:8]==b"\x89PNG\r\n\x1a\n" and
int.from_bytes(d[16:20],"big")==1280 and int.from_bytes(d[20:24],"big")==800))' ||
  fail "--screenshot did not write a 1280 x 800 PNG"

# ---- --window WxH: the screenshot is that size, the widgets laid out for it (--print-geometry
# --window says where), the status line drawn inside it and the picture not mostly black. A window
# smaller than the interface needs is drawn smaller, and says so.
cat >pngcheck.py <<'PY'
import json, struct, sys, zlib
def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour == 2, (depth, colour)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, rows, stride, prev = zlib.decompress(idat), [], width * 3, bytearray(width * 3)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, lambda x, y: tuple(rows[y][3 * x:3 * x + 3])
shot, geometry, want_w, want_h = sys.argv[1], json.load(open(sys.argv[2])), int(sys.argv[3]), int(sys.argv[4])
w, h, at = read_png(shot)
assert (w, h) == (want_w, want_h) == tuple(geometry["window"]), ((w, h), (want_w, want_h), geometry["window"])
# Not mostly black: a 1280x800 picture in a larger black window was.
samples = [at(x, y) for y in range(0, h, 4) for x in range(0, w, 4)]
black = sum(1 for p in samples if max(p) < 8)
assert black < len(samples) // 3, f"{black} of {len(samples)} samples black"
# The status line: inside the picture, its bar's colour, with text (light pixels) on it.
x, y, bw, bh = (int(round(v)) for v in geometry["status"])
assert y + bh <= h and x + bw <= w, (geometry["status"], w, h)
bar = [at(px, py) for py in range(y + 1, y + bh - 1) for px in range(x + 1, x + bw - 1, 2)]
light = sum(1 for p in bar if min(p) > 150)
assert light > 50, f"the status line has {light} light pixels: not drawn"
print(f"{shot}: {w}x{h}, {black} of {len(samples)} samples black, status line {light} light pixels")
PY
for size in 1366x768 640x400 2560x1600; do
  "$editor" --window "$size" --print-geometry >"geometry-$size.json" || fail "--print-geometry --window $size"
  timeout 120 "$editor" --validation --window "$size" --frames 3 --screenshot "window-$size.png" 2>"window-$size.err"
  code=$?
  [ "$code" -eq 0 ] || fail "--window $size: exit $code: $(head -c 600 "window-$size.err")"
  python3 pngcheck.py "window-$size.png" "geometry-$size.json" "${size%x*}" "${size#*x}" ||
    fail "--window $size: the screenshot"
done
python3 -c 'import json,sys; g=json.load(open("geometry-640x400.json")); sys.exit(not abs(g["scale"] - 0.5) < 1e-6)' ||
  fail "--window 640x400 is not drawn at half size"
"$editor" --window 10x10 --print-geometry >/dev/null 2>window-small.err
code=$?
[ "$code" -eq 1 ] && grep -q -- "--window" window-small.err || fail "--window 10x10: exit $code, want 1: $(cat window-small.err)"

# ---- --screenshot onto its own --layout or --font file, under another name: refused (exit 5) before
# the window opens, the file kept (it used to be overwritten).
printf '{"name": "own", "r": [0, 0, 0.25, 1], "g": [0.25, 0, 0.75, 1], "b": [0.75, 0, 1, 1]}' >own.json
cp own.json own.kept && cp "$source/fonts/DejaVuSans.ttf" own.ttf
timeout 120 "$editor" --layout own.json --frames 1 --screenshot "$work/own.json" 2>own.err
code=$?
[ "$code" -eq 5 ] || fail "--screenshot onto --layout: exit $code, want 5: $(head -c 600 own.err)"
grep -q "it is the input" own.err || fail "--screenshot onto --layout: stderr does not say why: $(cat own.err)"
cmp -s own.json own.kept || fail "--screenshot overwrote its --layout file"
timeout 120 "$editor" --font own.ttf --frames 1 --screenshot ./own.ttf 2>own.err
code=$?
[ "$code" -eq 5 ] || fail "--screenshot onto --font: exit $code, want 5: $(head -c 600 own.err)"
cmp -s own.ttf "$source/fonts/DejaVuSans.ttf" || fail "--screenshot overwrote its --font file"
# ---- FIFOs as --font (exit 2) and --layout (reported, the editor runs) are refused at once: opening
# one used to wait for a writer for ever.
mkfifo font.fifo layout.fifo
timeout 60 "$editor" --font font.fifo --frames 1 2>fifo.err
code=$?
[ "$code" -eq 2 ] || fail "a FIFO as --font: exit $code, want 2: $(head -c 600 fifo.err)"
grep -q "not a regular file" fifo.err || fail "a FIFO as --font: $(cat fifo.err)"
timeout 120 "$editor" --validation --layout layout.fifo --frames 1 2>fifo.err
code=$?
[ "$code" -eq 0 ] || fail "a FIFO as --layout: exit $code, want 0 (reported, not fatal): $(head -c 600 fifo.err)"
grep -q "not a regular file" fifo.err || fail "a FIFO as --layout: $(cat fifo.err)"

# ---- A bad layout file: reported (stderr and window), the editor still runs; exit 0.
printf '{"r": [0, 0, 0.3, 1], "g": [0.3, 0, 0.6], "b": [0.6, 0, 1, 1]}' >bad.json
"$editor" --validation --layout bad.json --frames 2 2>bad.err
code=$?
[ "$code" -eq 0 ] || fail "bad --layout: exit $code, want 0 (the error is shown, not fatal)"
grep -q 'bad.json' bad.err && grep -q 'g' bad.err || fail "bad --layout: stderr lacks the reader's error: $(cat bad.err)"

# ---- The scripted session.
printf '{"name": "start", "r": [0, 0, 0.25, 1], "g": [0.25, 0, 0.75, 1], "b": [0.75, 0, 1, 1]}' >start.json
"$editor" --validation --layout start.json --save-to saved.json 2>editor.err &
pid=$!
window=$(timeout 60 xdotool search --sync --name '^crisp layout editor$' | head -n1)
[ -n "$window" ] || { fail "no editor window"; kill "$pid"; exit 1; }
shot_when_drawn before.xwd 6
xdotool windowfocus --sync "$window" 2>/dev/null || true
read -r bx by < <(center bgr)
xdotool mousemove "$bx" "$by" click 1
sleep 1
# The red rectangle of bgr spans x 2/3..1: its bottom edge at the centre of that span.
read -r ex ey < <(python3 -c 'import json; g=json.load(open("geometry.json")); o=g["pixel_origin"]; s=g["pixel_scale"]
print(int(o[0] + s * 5 / 6), int(o[1] + s))')
xdotool mousemove "$ex" "$ey" mousedown 1
sleep 0.3
xdotool mousemove "$ex" $((ey - 12))
sleep 0.3
xdotool mousemove "$ex" $((ey - 24))
sleep 0.3
xdotool mouseup 1
sleep 0.5
xdotool key Left
sleep 0.5
xdotool key ctrl+z
sleep 0.5
xdotool key ctrl+y
sleep 0.5
# Type exact numbers: red's top edge to 0.125, Tab on to its right edge (the keys go there) and
# 0.95, Shift+Tab back to the top edge and 0.25.
read -r fx fy < <(python3 -c 'import json; r=json.load(open("geometry.json"))["fields"]["r.y0"]
print(int(r[0] + r[2] / 2), int(r[1] + r[3] / 2))')
xdotool mousemove "$fx" "$fy" click 1
sleep 0.5
xdotool type --delay 50 0.125
xdotool key Tab
sleep 0.3
xdotool type --delay 50 0.95
xdotool key shift+Tab
sleep 0.3
xdotool type --delay 50 0.25
xdotool key Return
sleep 0.5
xdotool key g
sleep 0.5
xdotool key ctrl+s
for _ in $(seq 1 60); do [ -f saved.json ] && break; sleep 0.5; done
[ -f saved.json ] || fail "Ctrl+S wrote no saved.json"
shot_when_drawn after.xwd 6
# Idle once converged: the CPU seconds of 5 s are far below a busy loop's (about 1.5 cores on
# lavapipe, 2 cores: 7 to 8 s). Converging takes about 150 frames after the last edit.
ticks=$(getconf CLK_TCK)
# await_quit MESSAGE: gives the editor ($pid) 30 s to quit; past that, fails with MESSAGE and kills it.
await_quit() {
  for _ in $(seq 1 60); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
  if kill -0 "$pid" 2>/dev/null; then
    fail "$1"
    kill "$pid"
  fi
}
cpu_ticks() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
idle=""
for _ in $(seq 1 36); do
  before=$(cpu_ticks)
  sleep 5
  after=$(cpu_ticks)
  used=$(((after - before) * 100 / ticks))  # hundredths of a CPU second
  if [ "$used" -lt 50 ]; then idle=$used; break; fi
done
[ -n "$idle" ] && echo "idle: $idle/100 CPU seconds in 5 s" ||
  fail "the editor never idled: still $used/100 CPU seconds in 5 s after 3 minutes"
xdotool key ctrl+q
await_quit "the editor did not quit on Ctrl+Q"
wait "$pid"
code=$?
[ "$code" -eq 0 ] || fail "the editor exited $code (4: the validation layer spoke): $(head -c 1500 editor.err)"
grep -q 'validation' editor.err && fail "validation messages: $(grep validation editor.err | head -5)"

# ---- The saved layout: bgr, red's bottom edge 24 steps up, red one step left, red's
# top edge typed to 0.25 (0.125 first) and its right edge to 0.95, nothing else; exact where the
# grid is (2/3 - 1/96 is 0.65625, 1 - 24/96 is 0.75) and in the shortest form.
python3 - saved.json geometry.json <<'PY' || fail "saved layout"
import json, sys
saved = json.load(open(sys.argv[1]))
step = json.load(open(sys.argv[2]))["edit_step"]
third, two_thirds = 1 / 3, 2 / 3
want = {"name": "bgr-edited",
        "r": [two_thirds - step, 0.25, 0.95, 1 - 24 * step],
        "g": [third, 0, two_thirds, 1],
        "b": [0, 0, third, 1]}
assert saved["name"] == want["name"], saved
for channel in "rgb":
    got, expected = saved[channel], want[channel]
    assert len(got) == 4 and all(abs(a - b) < 1e-5 for a, b in zip(got, expected)), (channel, got, expected)
text = open(sys.argv[1]).read()
assert '"r": [0.65625, 0.25, 0.95, 0.75]' in text, text
print("saved layout as expected:", json.dumps(saved))
PY
# ---- The contrast the saved layout carries: crisp's default with gamma one step up (G).
python3 - saved.json <<'PY' || fail "saved contrast"
import json, sys
contrast = json.load(open(sys.argv[1])).get("contrast")
want = {"mode": "corrected", "gamma": 2.3, "contrast": 0, "stem_darkening": 0}
assert contrast == want, (contrast, want)
print("saved contrast as expected:", json.dumps(contrast))
PY
"$bake" "$source/fonts/DejaVuSans.ttf" --text "Hi" -o dejavu.crisp -q || fail "crisp-bake"
"$render" --font dejavu.crisp --text "Hi" --size 20 --origin 4,24 --canvas 48,32 --samples 16 \
  --layout saved.json -o render.png 2>render.err || fail "crisp-render refused the saved layout: $(cat render.err)"

# ---- Screenshots: each region present (not blank) and changed by the edit.
python3 screens.py compare before.xwd after.xwd || fail "screenshots"

cat >close.py <<'PY'
# close.py WINDOW: asks the window to close as a window manager's close button does (a
# WM_DELETE_WINDOW client message), through libX11 (xdotool 3.2016 has no windowclose).
import ctypes, ctypes.util, sys
x11 = ctypes.CDLL(ctypes.util.find_library("X11"))
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XInternAtom.restype = ctypes.c_ulong
x11.XInternAtom.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
x11.XSendEvent.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_long, ctypes.c_void_p]
x11.XFlush.argtypes = [ctypes.c_void_p]
x11.XCloseDisplay.argtypes = [ctypes.c_void_p]

class ClientMessage(ctypes.Structure):
    _fields_ = [("type", ctypes.c_int), ("serial", ctypes.c_ulong), ("send_event", ctypes.c_int),
                ("display", ctypes.c_void_p), ("window", ctypes.c_ulong), ("message_type", ctypes.c_ulong),
                ("format", ctypes.c_int), ("data", ctypes.c_long * 5), ("pad", ctypes.c_long * 24)]

display = x11.XOpenDisplay(None)
if not display:
    sys.exit("close.py: no display")
window = int(sys.argv[1], 0)
event = ClientMessage()
event.type = 33  # ClientMessage
event.window = window
event.message_type = x11.XInternAtom(display, b"WM_PROTOCOLS", 0)
event.format = 32
event.data[0] = x11.XInternAtom(display, b"WM_DELETE_WINDOW", 0)
event.data[1] = 0  # CurrentTime
ok = x11.XSendEvent(display, window, 0, 0, ctypes.byref(event))
x11.XFlush(display)
x11.XCloseDisplay(display)
sys.exit(0 if ok else 1)
PY

# ---- Files: the path field edited in place. Click into "name.json", Home, "my-", End, Backspace:
# saved as my-name.jso (before, the first key typed replaced the whole path).
click_rect() {  # click_rect X Y W H [DX]: clicks DX pixels into the rectangle (default its centre)
  local x=${1%.*} y=${2%.*} w=${3%.*} h=${4%.*}
  xdotool mousemove $((x + ${5:-$((w / 2))})) $((y + h / 2)) click 1
}
rect_of() {  # rect_of KEY [SUBKEY]: a widget's rectangle from geometry.json, as "x y w h"
  python3 -c 'import json,sys; g=json.load(open("geometry.json")); r=g[sys.argv[1]]
r=r[sys.argv[2]] if len(sys.argv) > 2 else r; print(*r)' "$@"
}
rm -f my-name.jso name.json
"$editor" --validation --layout rgb --save-to name.json 2>files.err &
pid=$!
window=$(timeout 60 xdotool search --sync --name '^crisp layout editor$' | head -n1)
[ -n "$window" ] || { fail "no editor window (files)"; kill "$pid"; exit 1; }
shot_when_drawn files-start.xwd 4
# shellcheck disable=SC2046
click_rect $(rect_of path_field) 30
sleep 0.5
xdotool key Home
xdotool type --delay 50 my-
xdotool key End BackSpace Return
sleep 0.5
xdotool key ctrl+s
for _ in $(seq 1 60); do [ -f my-name.jso ] && break; sleep 0.5; done
[ -f my-name.jso ] || fail "the edited path: no my-name.jso saved ($(ls))"
[ -f name.json ] && fail "the edited path: saved under the old name too"
cp my-name.jso my-name.kept 2>/dev/null
# An unsaved change, then Ctrl+Q: the editor asks and keeps running; D discards and quits.
xdotool key Right
sleep 1
xdotool key ctrl+q
sleep 4
if kill -0 "$pid" 2>/dev/null; then
  shot_when_drawn prompt.xwd 0
  python3 screens.py prompt prompt.xwd || fail "the quit prompt is not in the screenshot"
  # Escape cancels; then the close button (WM_DELETE_WINDOW, as a window manager sends it) asks
  # again, since Cancel cleared the window's close request.
  xdotool key Escape
  sleep 2
  python3 close.py "$window" || fail "close.py could not send WM_DELETE_WINDOW"
  sleep 4
  if kill -0 "$pid" 2>/dev/null; then
    shot_when_drawn prompt-close.xwd 0
    python3 screens.py prompt prompt-close.xwd || fail "closing the window: the prompt is not in the screenshot"
  else
    fail "closing the window with unsaved changes (after a Cancel) quit without asking"
  fi
  xdotool key d
  await_quit "D (Discard) did not quit"
else
  fail "Ctrl+Q with unsaved changes quit without asking"
fi
wait "$pid"
code=$?
[ "$code" -eq 0 ] || fail "files: the editor exited $code: $(head -c 1500 files.err)"
cmp -s my-name.jso my-name.kept || fail "Discard changed the saved file"
# The recent files: the ones saved or loaded, newest first, absolute.
if [ -f "$recent_list" ]; then
  [ "$(head -n1 "$recent_list")" = "$work/my-name.jso" ] || fail "recent files: $(cat "$recent_list")"
  grep -qx "$work/saved.json" "$recent_list" || fail "recent files lack saved.json: $(cat "$recent_list")"
  grep -qx "$work/start.json" "$recent_list" || fail "recent files lack start.json: $(cat "$recent_list")"
else
  fail "no recent files list at $recent_list"
fi

# ---- The next start reads them back: Up in the empty path field brings the newest, Ctrl+O loads
# it. Then the preview's text: typed into its field, the paragraphs change.
"$editor" --validation --layout rgb 2>recent.err &
pid=$!
window=$(timeout 60 xdotool search --sync --name '^crisp layout editor$' | head -n1)
[ -n "$window" ] || { fail "no editor window (recent)"; kill "$pid"; exit 1; }
shot_when_drawn text-before.xwd 6
# shellcheck disable=SC2046
click_rect $(rect_of path_field)
sleep 0.5
xdotool key Up Return
sleep 0.5
xdotool key ctrl+o
sleep 1
# The Recent button's list: its second row (saved.json) clicked is put into the file field.
# shellcheck disable=SC2046
click_rect $(rect_of recent_button)
sleep 1
read -r rx ry < <(python3 -c 'import json; r=json.load(open("geometry.json"))["recent_rows"][1]
print(int(r[0] + r[2] / 2), int(r[1] + r[3] / 2))')
xdotool mousemove "$rx" "$ry" click 1
sleep 1
# shellcheck disable=SC2046
click_rect $(rect_of preview_controls text)
sleep 0.5
xdotool key ctrl+a
xdotool type --delay 30 "Quick zephyrs blow, vexing daft Jim"
xdotool key Return
shot_when_drawn text-after.xwd 8
python3 screens.py changed preview_paragraphs text-before.xwd text-after.xwd ||
  fail "the typed preview text did not change the preview"
xdotool key ctrl+q
await_quit "the editor did not quit (recent)"
wait "$pid"
code=$?
[ "$code" -eq 0 ] || fail "recent: the editor exited $code: $(head -c 1500 recent.err)"
grep -q "Loaded $work/my-name.jso" recent.err || fail "Up did not bring back the recent file: $(cat recent.err)"
grep -q "File: $work/saved.json (Load or Save it)" recent.err ||
  fail "a click in the Recent list did not choose its file: $(cat recent.err)"

# ---- A bad recent-files list: reported, ignored, not fatal (and --frames runs do not rewrite it).
printf '/ok
not/absolute
' >"$recent_list"
cp "$recent_list" recent.kept
timeout 120 "$editor" --validation --frames 2 2>bad-recent.err
code=$?
[ "$code" -eq 0 ] || fail "a bad recent-files list: exit $code: $(head -c 600 bad-recent.err)"
grep -q "Recent files ignored: .*line 2" bad-recent.err || fail "a bad recent-files list: $(cat bad-recent.err)"
cmp -s "$recent_list" recent.kept || fail "a --frames run rewrote the recent files"

# ---- Compare mode (issue 29, item 1): the Compare button shows four candidates around rgb side by
# side, each panel rendered with its own layout (the panels differ where the text is). A click on
# panel 2 picks the order reversed (bgr), key 3 then its narrower candidate; Escape leaves, V comes
# back and V leaves again; Ctrl+S saves bgr narrowed, picked only.
"$editor" --validation --layout rgb --save-to compared.json 2>compare.err &
pid=$!
window=$(timeout 60 xdotool search --sync --name '^crisp layout editor$' | head -n1)
[ -n "$window" ] || { fail "no editor window (compare)"; kill "$pid"; exit 1; }
sleep 3
xdotool windowfocus --sync "$window" 2>/dev/null || true
# shellcheck disable=SC2046
click_rect $(rect_of preview_controls compare)
shot_when_drawn compare.xwd 12
python3 screens.py panels compare.xwd yes || fail "compare mode: the panels are not shown, or do not differ"
read -r px py < <(python3 -c 'import json; r=json.load(open("geometry.json"))["candidates"][1]
print(int(r[0] + r[2] / 2), int(r[1] + r[3] / 2))')
xdotool mousemove "$px" "$py" click 1
sleep 1
xdotool key 3
sleep 1
xdotool key Escape
sleep 2
shot compare-left.xwd
python3 screens.py panels compare-left.xwd no || fail "Escape did not leave compare mode"
xdotool key v
sleep 2
shot compare-again.xwd
python3 screens.py panels compare-again.xwd yes || fail "V did not enter compare mode"
xdotool key v
sleep 2
shot compare-off.xwd
python3 screens.py panels compare-off.xwd no || fail "V did not leave compare mode"
xdotool key ctrl+s
for _ in $(seq 1 60); do [ -f compared.json ] && break; sleep 0.5; done
[ -f compared.json ] || fail "compare: Ctrl+S wrote no compared.json"
xdotool key ctrl+q
await_quit "the editor did not quit (compare)"
wait "$pid"
code=$?
[ "$code" -eq 0 ] || fail "compare: the editor exited $code: $(head -c 1500 compare.err)"
grep -q "Picked 2: Order reversed (bgr)" compare.err || fail "compare: the click did not pick bgr: $(cat compare.err)"
grep -q "Picked 3: Narrower (bgr-edited)" compare.err || fail "compare: key 3 did not pick: $(cat compare.err)"
python3 - compared.json geometry.json <<'PY' || fail "compare: the saved layout"
import json, sys
saved = json.load(open(sys.argv[1]))
s = 4 * json.load(open(sys.argv[2]))["edit_step"]  # kCandidateSteps steps each side
want = {"r": [2 / 3 + s, 0, 1 - s, 1], "g": [1 / 3 + s, 0, 2 / 3 - s, 1], "b": [s, 0, 1 / 3 - s, 1]}
assert saved["name"] == "bgr-edited", saved
for channel, expected in want.items():
    got = saved[channel]
    assert all(abs(a - b) < 1e-5 for a, b in zip(got, expected)), (channel, got, expected)
print("compare: saved", json.dumps(saved))
PY
# --compare: the screenshot mode starts in compare mode (docs/layout-editor.md's picture).
timeout 120 "$editor" --validation --compare --frames 3 --screenshot compare.png 2>compare-shot.err ||
  fail "--compare --screenshot: $(head -c 600 compare-shot.err)"

# ---- The preview from the command line: --text, --sizes, --colours and --zoom change the
# screenshot; bad sizes and colours are usage errors that say why.
timeout 120 "$editor" --validation --frames 3 --screenshot preview-default.png 2>preview.err ||
  fail "preview default: $(head -c 600 preview.err)"
timeout 120 "$editor" --validation --frames 3 --screenshot preview-own.png --text "Hamburgefonstiv"   --sizes "12 24" --colours "#FFE27A on #1B3A8C" --zoom 2 2>preview.err ||
  fail "preview options: $(head -c 600 preview.err)"
python3 - preview-default.png preview-own.png geometry.json <<'PY' || fail "the preview options changed nothing"
import json, sys
exec(open("pngcheck.py").read().split("shot, geometry")[0])
g = json.load(open(sys.argv[3]))
_, _, a = read_png(sys.argv[1])
_, _, b = read_png(sys.argv[2])
for name in ("light_panel", "dark_panel"):
    x, y, w, h = (int(v) for v in g[name])
    points = [(px, py) for py in range(y, y + h, 3) for px in range(x, x + w, 3)]
    changed = sum(1 for p in points if max(abs(i - j) for i, j in zip(a(*p), b(*p))) > 40)
    print(f"{name}: {changed} of {len(points)} samples changed")
    assert changed > len(points) // 4, name
# The first panel's background is the colour asked for.
x, y, w, h = (int(v) for v in g["light_panel"])
assert b(x + w - 3, y + h - 3) == (0x1B, 0x3A, 0x8C), b(x + w - 3, y + h - 3)
PY
for bad in "--sizes 9,x:'x'" "--sizes 100:outside 4 to 72" "--colours #12345 #000000:is not a colour" \
  "--zoom 3:1, 2 or 4"; do
  option=${bad%%:*} want=${bad#*:}
  # shellcheck disable=SC2086
  "$editor" ${option%% *} "${option#* }" --print-geometry >/dev/null 2>bad-option.err
  code=$?
  [ "$code" -eq 1 ] && grep -q -- "$want" bad-option.err || fail "$option: exit $code: $(cat bad-option.err)"
done

if [ "$failures" -ne 0 ]; then
  echo "$failures check(s) failed; files in $work" >&2
  exit 1
fi
echo "layout editor: all checks passed"
