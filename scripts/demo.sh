#!/usr/bin/env bash
# The demo: installs what is missing, builds crisp, bakes the bundled fonts and shows the report.
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
echo "The assets are in $(pwd)/$out:"
ls -1 "$(pwd)/$out"/*.crisp
