#!/usr/bin/env bash
# The demo: installs what is missing, builds crisp, bakes the bundled fonts (showing each bake's
# report), renders a paragraph with subpixel anti-aliasing into a PNG on the GPU (lavapipe when
# there is no GPU), composites it over a photo-like backdrop and a gradient with the tile path,
# composites a scene of overlapping translucent text with the tiled
# order-independent transparency and, to compare, unsorted, draws a line of colour glyphs (bitmap
# emoji and COLRv1 gradients) and a title with an outline and a shadow, and prints where the images are.
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
echo "== crisp-bake: colour glyphs, a dozen bitmap emoji of Noto Color Emoji (CBDT) and COLRv1 gradients"
emoji_text="😀👍🏽❤️🇺🇸🎉🚀🌈🍕✨🐱"
build/tools/crisp-bake /usr/share/fonts/truetype/noto/NotoColorEmoji.ttf --text "$emoji_text" \
  -o "$out/NotoColorEmoji.crisp"
build/tools/crisp-bake tests/fonts/colour/colrv1.ttf --codepoints U+E002-E004 -o "$out/colrv1.crisp" -q
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
echo "== crisp-render: the same paragraph composited by the tile path over a photo-like backdrop and a"
echo "   gradient, with rgb, bgr and vrgb subpixel layouts (coverage stays per channel over any scene)"
for layout in rgb bgr vrgb; do
  build/tools/crisp-render --font "$out/DejaVuSans.crisp" --text "$paragraph" --size 17 --origin 12.3,26.6 \
    --canvas 560,110 --layout "$layout" --color 1,1,1,1 --background 0.1,0.2,0.4 --backdrop photo \
    -o "$out/paragraph-photo-$layout.png" >/dev/null
done
build/tools/crisp-render --font "$out/DejaVuSans.crisp" --text "$paragraph" --size 17 --origin 12.3,26.6 \
  --canvas 560,110 --layout rgb --color 0.05,0.05,0.1 --background 0.95,0.8,0.5 --backdrop gradient \
  -o "$out/paragraph-gradient-rgb.png"
echo
echo "== crisp-render --scene: overlapping translucent runs at three depths, tiled (exact order) and unsorted"
cp docs/examples/overlap.json "$out/overlap.json"  # its font path is relative to the scene file
build/tools/crisp-render --scene "$out/overlap.json" --composite tiled -o "$out/overlap-tiled.png"
build/tools/crisp-render --scene "$out/overlap.json" --composite unsorted -o "$out/overlap-unsorted.png" >/dev/null
echo
echo "== crisp-render: colour glyphs after a text font in the fallback chain (emoji presentation picks the"
echo "   colour font), bitmap emoji and COLRv1 linear, radial and sweep gradients"
build/tools/crisp-render --font "$out/DejaVuSans.crisp" --font "$out/NotoColorEmoji.crisp" --font "$out/colrv1.crisp" \
  --text "Colour glyphs: 😀 👍🏽 ❤️ 🇺🇸 and COLRv1 gradients $(printf '\xee\x80\x82 \xee\x80\x83 \xee\x80\x84')
The baked subset: $emoji_text" --size 24 --origin 12,34 --canvas 720,90 -o "$out/emoji.png"
echo
echo "== crisp-render: a title with an outline and a blurred drop shadow (effects, exact at every size), a"
echo "   glow, and text emboldened by --weight"
build/tools/crisp-render --font "$out/Inter-Bold.crisp" --text "Outlined Title" --size 56 --origin 16,70 \
  --canvas 480,100 --color 1,0.85,0.2 --background 0.25,0.35,0.55 --backdrop gradient \
  --outline 3,0.1,0.05,0 --shadow 4,4,3,0,0,0,0.6 -o "$out/title.png"
build/tools/crisp-render --font "$out/Inter-Bold.crisp" --text "Glowing" --size 48 --origin 16,60 \
  --canvas 260,84 --color 1,1,1 --background 0.05,0.05,0.15 --glow 6,0.3,0.7,1,0.9 -o "$out/glow.png" >/dev/null
build/tools/crisp-render --font "$out/DejaVuSans.crisp" --text "Emboldened by --weight 0.6 px" --size 20 \
  --origin 10,28 --canvas 320,40 --weight 0.6 -o "$out/weight.png" >/dev/null
echo
echo "The assets are in $(pwd)/$out:"
ls -1 "$(pwd)/$out"/*.crisp
echo "The rendered paragraph (subpixel rgb, and grayscale to compare):"
echo "$(pwd)/$out/paragraph-rgb.png"
echo "$(pwd)/$out/paragraph-gray.png"
echo "Over a photo-like backdrop (rgb, bgr, vrgb) and a gradient (rgb):"
for layout in rgb bgr vrgb; do echo "$(pwd)/$out/paragraph-photo-$layout.png"; done
echo "$(pwd)/$out/paragraph-gradient-rgb.png"
echo "The scene, composited in depth order (tiled) and in draw order (unsorted):"
echo "$(pwd)/$out/overlap-tiled.png"
echo "$(pwd)/$out/overlap-unsorted.png"
echo "Colour glyphs (bitmap emoji and COLRv1 gradients):"
echo "$(pwd)/$out/emoji.png"
echo "A title with an outline and a blurred shadow, a glow, and emboldened text:"
echo "$(pwd)/$out/title.png"
echo "$(pwd)/$out/glow.png"
echo "$(pwd)/$out/weight.png"
