#!/usr/bin/env bash
# The demo: installs what is missing, builds crisp, bakes the bundled fonts (showing each bake's
# report), renders a paragraph with subpixel anti-aliasing into a PNG on the GPU (lavapipe when
# there is no GPU), composites a scene of overlapping translucent text with layered
# order-independent transparency and, to compare, unsorted, and prints where the images are.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh build >/dev/null
out=build/demo
mkdir -p "$out"
echo "== crisp-bake: a TrueType face (DejaVu Sans)"
build/tools/crisp-bake fonts/DejaVuSans.ttf -o "$out/DejaVuSans.crisp"
echo
echo "== crisp-bake: an OpenType CFF face (Inter), cubics lowered to quadratics"
build/tools/crisp-bake fonts/Inter-Regular.otf -o "$out/Inter-Regular.crisp"
echo
echo "== crisp-bake: a variable face (Inter) at wght=700"
build/tools/crisp-bake fonts/Inter-roman.var.ttf --var wght=700 -o "$out/Inter-Bold.crisp"
echo
echo "== crisp-bake --check"
build/tools/crisp-bake --check "$out/DejaVuSans.crisp"
echo
echo "== crisp-render: a paragraph of DejaVu Sans, rgb subpixel layout, 512 samples per glyph"
paragraph="crisp rasterizes glyph outlines on the GPU into an atlas
where every glyph keeps collecting subpixel samples while it
stays on screen: sharp, accurate and cheap once text is still.
The quick brown fox jumps over the lazy dog. 0123456789 (fi fl)"
build/tools/crisp-render --font "$out/DejaVuSans.crisp" --text "$paragraph" --size 17 --origin 12.3,26.6 \
  --canvas 560,110 --layout rgb -o "$out/paragraph-rgb.png" --coverage-out "$out/paragraph-rgb.pfm"
build/tools/crisp-render --font "$out/DejaVuSans.crisp" --text "$paragraph" --size 17 --origin 12.3,26.6 \
  --canvas 560,110 --layout gray -o "$out/paragraph-gray.png" >/dev/null
echo
echo "== crisp-render --scene: overlapping translucent runs at three depths, layered OIT and unsorted"
cp docs/examples/overlap.json "$out/overlap.json"  # its font path is relative to the scene file
build/tools/crisp-render --scene "$out/overlap.json" --composite layered -o "$out/overlap-layered.png"
build/tools/crisp-render --scene "$out/overlap.json" --composite unsorted -o "$out/overlap-unsorted.png" >/dev/null
echo
echo "The assets are in $(pwd)/$out:"
ls -1 "$(pwd)/$out"/*.crisp
echo "The rendered paragraph (subpixel rgb, and grayscale to compare):"
echo "$(pwd)/$out/paragraph-rgb.png"
echo "$(pwd)/$out/paragraph-gray.png"
echo "The scene, composited in depth order (layered) and in draw order (unsorted):"
echo "$(pwd)/$out/overlap-layered.png"
echo "$(pwd)/$out/overlap-unsorted.png"
