#!/usr/bin/env bash
# The compositing sweep of docs/benchmarks-compositing.md, one command per machine:
#
#   scripts/bench_compositing.sh BIN_DIR OUT_DIR gpu       # a GPU: 3840x2160, and 32 layers at 1920x1080
#   scripts/bench_compositing.sh BIN_DIR OUT_DIR lavapipe  # the CPU driver: 512x256
#
# BIN_DIR holds crisp-bench (a Release build), whose compositing suite runs; it runs from the
# repository root (the font path). Each run writes OUT_DIR/<name>.md and .json; progress goes to
# OUT_DIR/<name>.log.
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 BIN_DIR OUT_DIR gpu|lavapipe" >&2; exit 64; }
bin=$1/crisp-bench
out=$2
mkdir -p "$out"
run() {
  local name=$1
  shift
  echo "== $name: $*" >&2
  "$bin" --suite compositing --no-files "$@" --json-out "$out/$name.json" > "$out/$name.md" 2> "$out/$name.log"
}
case $3 in
  gpu)
    # 100 timed frames a mode: medians of at least 100 frames. 32 layers at 1920x1080: at 3840x2160
    # their CPU reference alone takes minutes.
    run gpu-3840x2160 --canvas 3840,2160 --layers 1,4 --alphas 0.9 --frames 100
    run gpu-1920x1080-32 --canvas 1920,1080 --layers 32 --alphas 0.9 --frames 100 \
      --modes tiled,tiled-rebin,tiled-rgba8,frame,draw,exact,wboit,unsorted
    ;;
  lavapipe)
    run lavapipe-512x256 --canvas 512,256 --layers 1,4,32 --alphas 0.9 --frames 10
    ;;
  *)
    echo "$0: gpu or lavapipe, not '$3'" >&2
    exit 64
    ;;
esac
