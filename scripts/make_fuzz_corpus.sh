#!/usr/bin/env bash
# Regenerates the seed corpora of the fuzz targets from the bundled fonts (needs hb-subset from
# Debian's libharfbuzz-bin and a built crisp-bake):   scripts/make_fuzz_corpus.sh build/tools/crisp-bake
# The font seeds are tiny subsets with the name table dropped (test data derived from the
# fonts in fonts/ under their licences); the asset seeds are those subsets baked. Crash inputs
# found later go to fuzz/corpus/*/regression-* and are never regenerated.
set -euo pipefail
cd "$(dirname "$0")/.."
bake=$1
fonts=fuzz/corpus/font assets=fuzz/corpus/asset
mkdir -p "$fonts" "$assets"
subset() { hb-subset "$1" --text="Ag1 fi" --name-IDs="" --drop-tables+=name -o "$fonts/$2"; }
subset fonts/DejaVuSans.ttf dejavu-subset.ttf
subset fonts/Inter-Regular.otf inter-cff-subset.otf
subset fonts/Inter-roman.var.ttf inter-var-subset.ttf
for font in "$fonts"/*-subset.*; do
  name=$(basename "${font%.*}")
  "$bake" "$font" -q -o "$assets/$name.crisp"
done
"$bake" "$fonts/inter-var-subset.ttf" --var wght=900 -q -o "$assets/inter-var-subset-wght900.crisp"
"$bake" "$fonts/inter-cff-subset.otf" --split-y-extrema --tolerance 0.01 -q -o "$assets/inter-cff-subset-split.crisp"
# Colour glyphs (asset version 2's colour sections): crisp's own COLRv0 and COLRv1 test fonts.
for name in colrv0 colrv1; do
  cp "tests/fonts/colour/$name.ttf" "$fonts/$name.ttf"
  "$bake" "$fonts/$name.ttf" -q -o "$assets/$name.crisp"
done
