#!/usr/bin/env bash
# engine_example_test.sh: tests crisp-engine-example (examples/engine, docs/integration.md).
#
#   engine_example_test.sh run EXAMPLE WORK_DIR
#     In a window under Xvfb on whatever Vulkan device there is (lavapipe in CI), with the
#     validation layer and synchronization validation on: the command line (help, bad arguments,
#     a missing font, no display); two identical runs give the same screenshot, bit for bit; the
#     screenshot shows text where the report says it was drawn (HUD paragraph, counter, list rows
#     clipped to their box, one hovered label, each label above the shape it names, the spinner
#     below the HUD turned to the angle the report gives, the sign in its colour on the cube's face
#     where the report projects it, and only their glyphs transformed); a run that
#     drops every 7th frame (recorded, then abandoned), is resized twice and minimized once ends
#     on the very image of the run that only resized: Renderer::abandon_frame() and
#     Compositor::abandon_frame() leave no trace, and minimizing draws nothing.
#
#   engine_example_test.sh standalone CMAKE PREFIX SOURCE_DIR WORK_DIR
#     Builds examples/engine on its own against the crisp installed in PREFIX (find_package), with
#     warnings as errors, and runs it for a few frames under Xvfb.
set -uo pipefail
mode=$1
shift

if [ "$mode" = standalone ]; then
  cmake=$1 prefix=$2 source=$3 work=$4
  set -e
  rm -rf "$work" && mkdir -p "$work"
  test -f "$prefix/lib/cmake/crisp/crispConfig.cmake" || { echo "FAIL: no installed crisp in $prefix" >&2; exit 1; }
  "$cmake" -S "$source/examples/engine" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_COMPILE_WARNING_AS_ERROR=ON >"$work/configure.log"
  grep -q "^crisp_DIR:PATH=$prefix/lib/cmake/crisp\$" "$work/build/CMakeCache.txt" ||
    { echo "FAIL: the standalone build did not find the installed crisp" >&2; exit 1; }
  "$cmake" --build "$work/build" -j "$(nproc 2>/dev/null || echo 2)" >"$work/build.log" ||
    { tail -40 "$work/build.log" >&2; exit 1; }
  "$work/build/crisp-engine-example" --help | grep -q -- "--drop-every"
  # -n: start looking for a free display away from the other Xvfb tests, which may run at once.
  xvfb-run -a -n 160 -s "-screen 0 640x480x24" "$work/build/crisp-engine-example" --validation --frames 3 --size 320x240
  echo "standalone build of crisp-engine-example against $prefix: ok"
  exit 0
fi

[ "$mode" = run ] || { echo "usage: $0 run EXAMPLE WORK_DIR | standalone CMAKE PREFIX SOURCE_DIR WORK_DIR" >&2; exit 2; }
example=$(realpath "$1") work=$(realpath -m "$2")
if [ "${ENGINE_EXAMPLE_TEST_INNER:-}" != 1 ]; then
  for tool in xvfb-run python3 cmp; do
    command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (scripts/setup.sh installs it)" >&2; exit 1; }
  done
  rm -rf "$work" && mkdir -p "$work"
  # Without a display the example says so, and exits 3.
  env -u DISPLAY -u WAYLAND_DISPLAY "$example" --frames 1 2>"$work/nodisplay.err"
  code=$?
  [ "$code" -eq 3 ] && grep -q "display" "$work/nodisplay.err" ||
    { echo "FAIL: without a display: exit $code, $(cat "$work/nodisplay.err")" >&2; exit 1; }
  ENGINE_EXAMPLE_TEST_INNER=1 exec xvfb-run -a -n 130 -s "-screen 0 1024x768x24" bash "$0" run "$@"
fi

cp "$(dirname "$(realpath "$0")")/png_rgb.py" "$work/" || { echo "FAIL: no png_rgb.py beside $0" >&2; exit 1; }
cd "$work"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
cat >check_screenshot.py <<'PY'
#!/usr/bin/env python3
"""Checks a crisp-engine-example screenshot against its --report (tests/engine_example_test.sh).

check_screenshot.py SHOT.png REPORT.json: text is where the report says it was drawn (enough ink
in the HUD's paragraph, counter and list, and in every label), the list's rows are clipped to the
list box, exactly one label wears the hover colour, each label stands above the shape it names
(pixels of that shape's colour just below its anchor), the spinner's ink is centred on its pivot
and lies along the angle the report gives (the principal axis of its pixels), and the sign's ink
lies on the cube's face as the report projects it. Exit status 0 when all hold; each failure is
printed. Pure Python (zlib), so it needs nothing beyond Debian's python3.
"""
import json
import math
import sys

from png_rgb import read_png


class Image:
    def __init__(self, path):
        self.width, self.height, self.pixels = read_png(path)

    def region(self, x0, y0, x1, y1):
        """Pixels (r, g, b) of the rectangle, clamped to the image."""
        x0, y0 = max(int(x0), 0), max(int(y0), 0)
        x1, y1 = min(int(x1), self.width), min(int(y1), self.height)
        for y in range(y0, y1):
            base = y * self.width * 3
            for x in range(x0, x1):
                i = base + x * 3
                yield self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]


def light(p):  # text on the dark panels: light grey, white, yellow, green
    return max(p) >= 150


def white_ink(p):  # the labels' colour, sRGB (0.94, 0.95, 0.97), where coverage is high
    return min(p) >= 190


def hover_ink(p):  # the hover colour, sRGB (1.0, 0.78, 0.22), where coverage is high
    return p[0] >= 200 and 150 <= p[1] <= 230 and p[2] <= 110


def sign_ink(p):  # the sign's colour, sRGB (0.55, 0.93, 1.0), over the cube's red (the octahedron is darker)
    return p[1] >= 170 and p[2] >= 170 and p[2] >= p[0] + 20


SHAPE_COLOURS = {  # what the lit shapes look like: the dominant channel
    "Cube": lambda p: p[0] > p[1] + 40 and p[0] > p[2] + 40,
    "Octahedron": lambda p: p[2] > p[0] + 40 and p[2] > p[1] + 10,
    "Pyramid": lambda p: p[1] > p[0] + 40 and p[1] > p[2] + 40,
}


def main():
    image = Image(sys.argv[1])
    report = json.load(open(sys.argv[2]))
    failures = []
    if (image.width, image.height) != (report["width"], report["height"]):
        failures.append(f"image is {image.width}x{image.height}, report says {report['width']}x{report['height']}")
    boxes = {box["name"]: box for box in report["text"]}

    def ink(box, margin=0, test=light):
        pixels = list(image.region(box["x"] - margin, box["y"] - margin,
                                   box["x"] + box["width"] + margin, box["y"] + box["height"] + margin))
        return sum(1 for p in pixels if test(p)), len(pixels)

    for name in ("paragraph", "counter", "list"):
        count, total = ink(boxes[name])
        # Text covers roughly 10-30% of a paragraph's box; a blank or solid box fails.
        if not (0.04 * total <= count <= 0.6 * total):
            failures.append(f"{name}: {count} of {total} pixels are text-light")
    # Clipping: between the list box and the HUD panel's bottom edge there is no text.
    hud, rows = boxes["hud"], boxes["list"]
    below = {"x": rows["x"], "y": rows["y"] + rows["height"] + 1, "width": rows["width"],
             "height": hud["y"] + hud["height"] - (rows["y"] + rows["height"]) - 2}
    leaked, _ = ink(below)
    if leaked:
        failures.append(f"list rows leak below the list box: {leaked} light pixels")
    counter = boxes["counter"]
    above = {"x": rows["x"], "y": counter["y"] + counter["height"] + 1, "width": rows["width"],
             "height": rows["y"] - (counter["y"] + counter["height"]) - 2}
    leaked, _ = ink(above)
    if leaked:
        failures.append(f"list rows leak above the list box: {leaked} light pixels")

    labels = [box for box in report["text"] if box["name"].startswith("label:")]
    if len(labels) != 3:
        failures.append(f"{len(labels)} labels drawn, want 3")
    if sum(1 for box in labels if box["hovered"]) != 1:
        failures.append("not exactly one hovered label")
    for box in labels:
        shape = box["name"][len("label:"):]
        count, total = ink(box)
        if not (0.04 * total <= count <= 0.6 * total):
            failures.append(f"{box['name']}: {count} of {total} pixels are text-light")
        # Subpixel anti-aliasing tints the edges of white text too: compare the two colours' counts.
        hovered, _ = ink(box, test=hover_ink)
        white, _ = ink(box, test=white_ink)
        if box["hovered"] and not (hovered >= 20 and hovered > 4 * white):
            failures.append(f"{box['name']} is hovered, yet {hovered} pixels are in its colour and {white} white")
        if not box["hovered"] and not (white >= 20 and white > 4 * hovered):
            failures.append(f"{box['name']} is not hovered, yet {white} pixels are white and {hovered} in the hover colour")
        # The shape itself: its colour just below the anchor the label points at.
        ax, ay = box["anchor"]
        shape_pixels = sum(1 for p in image.region(ax - 30, ay + 4, ax + 30, ay + 70) if SHAPE_COLOURS[shape](p))
        if shape_pixels < 300:
            failures.append(f"{box['name']}: only {shape_pixels} {shape}-coloured pixels below its anchor")
    spinner = boxes.get("spinner")
    if spinner is None:
        failures.append("no spinner in the report")
    else:
        failures += check_spinner(image, spinner)
    sign = boxes.get("sign")
    if sign is None:
        failures.append("no sign in the report (the cube's face is turned to the camera in these frames)")
    else:
        failures += check_sign(image, sign)
    for failure in failures:
        print(f"check_screenshot {sys.argv[1]}: {failure}")
    return 1 if failures else 0


def check_spinner(image, box):
    """The spinner's light pixels, inside the circle it turns in: centred on the box's centre, and
    their principal axis (of the second moments, y down) at the report's angle, modulo 180."""
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    radius = math.hypot(box["width"], box["height"]) / 2 + 1
    points = []
    for y in range(int(cy - radius), int(cy + radius) + 1):
        for x in range(int(cx - radius), int(cx + radius) + 1):
            if math.hypot(x + 0.5 - cx, y + 0.5 - cy) <= radius and 0 <= x < image.width and 0 <= y < image.height:
                i = (y * image.width + x) * 3
                if light(image.pixels[i:i + 3]):
                    points.append((x + 0.5, y + 0.5))
    if len(points) < 60:
        return [f"spinner: {len(points)} light pixels"]
    mx = sum(p[0] for p in points) / len(points)
    my = sum(p[1] for p in points) / len(points)
    xx = sum((p[0] - mx) ** 2 for p in points) / len(points)
    yy = sum((p[1] - my) ** 2 for p in points) / len(points)
    xy = sum((p[0] - mx) * (p[1] - my) for p in points) / len(points)
    failures = []
    if math.hypot(mx - cx, my - cy) > 3:
        failures.append(f"spinner: its ink is centred at ({mx:.1f}, {my:.1f}), its pivot at ({cx:.1f}, {cy:.1f})")
    axis = math.degrees(0.5 * math.atan2(2 * xy, xx - yy))
    off = (axis - box["angle"] + 90) % 180 - 90
    spread = math.sqrt(((xx - yy) / 2) ** 2 + xy ** 2)
    elongation = ((xx + yy) / 2 + spread) / max((xx + yy) / 2 - spread, 1e-6)
    if abs(off) > 4 or elongation < 6:
        failures.append(f"spinner: its ink lies at {axis:.1f} degrees (elongation {elongation:.1f}), "
                        f"the report says {box['angle']}")
    return failures


def check_sign(image, box):
    """The sign's colour on the cube's face: inside the face's projected quad, which is mostly the
    cube's red, and hardly anywhere around it."""
    quad = box["quad"]

    def inside(x, y):
        sides = [(quad[(i + 1) % 4][0] - quad[i][0]) * (y - quad[i][1]) -
                 (quad[(i + 1) % 4][1] - quad[i][1]) * (x - quad[i][0]) for i in range(4)]
        return all(s > 0 for s in sides) or all(s < 0 for s in sides)

    ink_in = ink_out = red = area = 0
    margin = 16
    for y in range(max(int(box["y"]) - margin, 0), min(int(box["y"] + box["height"]) + margin, image.height)):
        for x in range(max(int(box["x"]) - margin, 0), min(int(box["x"] + box["width"]) + margin, image.width)):
            i = (y * image.width + x) * 3
            p = image.pixels[i:i + 3]
            if inside(x + 0.5, y + 0.5):
                area += 1
                ink_in += sign_ink(p)
                red += SHAPE_COLOURS["Cube"](p)
            else:
                ink_out += sign_ink(p)
    failures = []
    if red < 0.3 * area:
        failures.append(f"sign: only {red} of the {area} pixels of its face are the cube's colour")
    if ink_in < 60 or ink_out > 0.05 * ink_in:
        failures.append(f"sign: {ink_in} pixels of its colour on its face, {ink_out} around it")
    return failures


if __name__ == "__main__":
    sys.exit(main())
PY

# ---- The command line.
"$example" --help >help.txt || fail "--help exited $?"
for option in --frames --screenshot --validation --drop-every --resize-at --minimize-at --font --emoji-font \
  --report --caret-blink --snapshots; do
  grep -q -- "$option" help.txt || fail "--help does not mention $option"
done
"$example" --frames 2>/dev/null; [ $? -eq 1 ] || fail "--frames without a value: want exit 1"
"$example" --resize-at 5:100 2>/dev/null; [ $? -eq 1 ] || fail "--resize-at 5:100: want exit 1"
"$example" --bogus 2>/dev/null; [ $? -eq 1 ] || fail "an unknown option: want exit 1"
"$example" --caret-blink 60001 2>/dev/null; [ $? -eq 1 ] || fail "--caret-blink 60001: want exit 1"
"$example" --snapshots 2>/dev/null; [ $? -eq 1 ] || fail "--snapshots without a value: want exit 1"
"$example" --font does-not-exist.ttf --frames 1 2>font.err; code=$?
[ "$code" -eq 2 ] && grep -q "does-not-exist.ttf" font.err || fail "a missing font: exit $code, $(cat font.err)"
"$example" --emoji-font no-emoji.ttf --frames 1 2>emoji.err; code=$?
[ "$code" -eq 2 ] && grep -q -- "--emoji-font no-emoji.ttf" emoji.err ||
  fail "a missing emoji font: exit $code, $(cat emoji.err)"

# run NAME ARGS...: one validated run at 640x400 writing NAME.png and NAME.json; exit code 0 means
# the validation layer reported nothing, teardown included.
run() {
  local name=$1
  shift
  "$example" --validation --size 640x400 --screenshot "$name.png" --report "$name.json" "$@" 2>"$name.err"
  local code=$?
  [ "$code" -eq 0 ] && return 0
  fail "$name: exit $code (4: the validation layer spoke): $(head -c 2000 "$name.err")"
  echo "engine_example_test: $failures failure(s), stopped at the first failed run; files in $work" >&2
  exit 1
}
# field NAME KEY: a number from NAME's report.
field() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1.json" "$2"; }

# ---- Determinism: the animation follows the frame index, and crisp's output depends only on
# what was drawn, so two runs give one image.
run plain --frames 40
run plain_again --frames 40
cmp -s plain.png plain_again.png || fail "two identical runs gave different screenshots"
python3 check_screenshot.py plain.png plain.json || fail "plain.png: text missing or misplaced"
[ "$(field plain presented)" = 40 ] || fail "plain: $(field plain presented) frames presented, want 40"
# Only the spinner's 8 glyphs ("rotating") and the sign's 5 are drawn at a
# transform; both turn every frame, so they are drawn as moving.
python3 - plain.json <<'PY' || fail "plain: the transformed glyphs are not the spinner's and the sign's"
import json, sys
glyphs = json.load(open(sys.argv[1]))["glyphs"]
assert glyphs["transformed"] == 13 and glyphs["moving"] >= 13 and glyphs["projective"] <= 13, glyphs
PY
# With Noto Color Emoji installed (the default --emoji-font), the title ends in a yellow face: the
# HUD above its paragraph, white text on a dark panel otherwise, has pixels of its yellow.
if [ -f /usr/share/fonts/truetype/noto/NotoColorEmoji.ttf ]; then
  python3 - plain.png plain.json <<'PY' || fail "plain.png: no colour emoji in the HUD's title"
import json, sys
from check_screenshot import read_png
width, height, pixels = read_png(sys.argv[1])
boxes = {box["name"]: box for box in json.load(open(sys.argv[2]))["text"]}
hud, paragraph = boxes["hud"], boxes["paragraph"]
yellow = 0
for y in range(int(hud["y"]), int(paragraph["y"])):
    for x in range(int(hud["x"]), int(hud["x"] + hud["width"])):
        r, g, b = pixels[(y * width + x) * 3:(y * width + x) * 3 + 3]
        yellow += r > 200 and g > 150 and b < 100
assert yellow > 40, f"{yellow} yellow pixels in the title"
PY
fi

# ---- Dropped frames, resizes and a minimized window: the run with drops must end on the image of
# the run without them. Frames count presented frames, so both animate the same 60 frames; every
# 7th frame begun in the first run is recorded in full (rasterization, scene, compositing) and
# abandoned, 9 of them; the window goes to 500x300 before frame 20 and back before frame 40, and
# is minimized for 5 polls before frame 30.
schedule=(--frames 60 --resize-at 20:500x300 --resize-at 40:640x400)
run dropped "${schedule[@]}" --drop-every 7 --minimize-at 30:5
run resized "${schedule[@]}"
[ "$(field dropped dropped)" = 9 ] || fail "dropped: $(field dropped dropped) frames dropped, want 9"
[ "$(field dropped minimized_polls)" = 5 ] || fail "dropped: $(field dropped minimized_polls) minimized polls, want 5"
for name in dropped resized; do
  [ "$(field $name presented)" = 60 ] || fail "$name: $(field $name presented) frames presented, want 60"
  [ "$(field $name resizes)" = 2 ] || fail "$name: $(field $name resizes) resizes, want 2"
  [ "$(field $name recreations)" -ge 2 ] || fail "$name: the swapchain was made again $(field $name recreations) times, want 2"
  [ "$(field $name width)x$(field $name height)" = 640x400 ] || fail "$name: the last frame was not 640x400"
  python3 check_screenshot.py $name.png $name.json || fail "$name.png: text missing or misplaced"
done
cmp -s dropped.png resized.png || fail "the run that dropped frames ended on another image than the one that did not"
# The spinner turns: 20 frames after plain's last frame its square holds other pixels (30 degrees
# further on; check_screenshot.py found each at its own angle).
python3 - plain.png resized.png resized.json <<'PY' || fail "the spinner did not turn between frames 39 and 59"
import json, sys
from check_screenshot import Image
box = {b["name"]: b for b in json.load(open(sys.argv[3]))["text"]}["spinner"]
square = (box["x"], box["y"] + box["height"] / 2 - box["width"] / 2,
          box["x"] + box["width"], box["y"] + box["height"] / 2 + box["width"] / 2)
a, b = (list(Image(path).region(*square)) for path in sys.argv[1:3])
changed = sum(1 for p, q in zip(a, b) if max(abs(x - y) for x, y in zip(p, q)) > 60)
assert changed > 100, f"{changed} pixels changed"
PY

if [ "$failures" -ne 0 ]; then
  echo "engine_example_test: $failures failure(s); files in $work" >&2
  exit 1
fi
echo "engine_example_test: ok"
