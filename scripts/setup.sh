#!/usr/bin/env bash
# Installs what crisp needs to build, test and run, from Debian 12's archive. Idempotent: when
# everything is present it only asks dpkg and returns. Needs root (or sudo) only to install.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git   # the toolchain (CMake 3.25 on Debian 12)
  libfreetype-dev                        # font outlines for the baker
  libharfbuzz-dev                        # shaping, GSUB closure for subset bakes, asset font checks
  libfribidi-dev                         # the Unicode bidirectional algorithm for mixed-direction text
  libicu-dev                             # grapheme cluster and word boundaries for caret motion (UAX #29)
  libvulkan-dev                          # the Vulkan loader and headers
  mesa-vulkan-drivers                    # lavapipe, the CPU Vulkan driver the GPU tests run on
  vulkan-validationlayers                # the validation layer the tests turn on
  glslang-tools                          # glslangValidator: GLSL to SPIR-V at build time
  libglm-dev                             # vector math shared by tools and tests
  libpng-dev                             # PNG output of crisp-render
  zlib1g-dev                             # the asset's bitmap glyphs are zlib streams
  libgtest-dev                           # GoogleTest
  clang libclang-rt-14-dev               # libFuzzer for the fuzz targets
  clang-format                           # the format check (scripts/check_format.sh)
  python3                                # the CLI tests check --json output with it
  python3-matplotlib                     # crisp-bench's plots (scripts/plot_bench.py)
  python3-fonttools                      # tests derive a 16384 units-per-em font from DejaVu Sans
  fonts-noto-cjk                         # tests: a CJK collection (.ttc, CFF, 1000 units per em)
  fonts-cantarell                        # tests: a CFF face with 1000 units per em
  fonts-noto-color-emoji                 # tests: colour bitmap glyphs (CBDT), no outlines
  fonts-dejavu-extra                     # crisp-bench's coverage suite: an italic face
  libglfw3-dev                           # the layout editor's and the engine example's window and input
  libvulkan-volk-dev                     # the engine example loads Vulkan with volk, as engines do
  xvfb xauth                             # the layout editor test: a virtual X display (xvfb-run)
  xdotool                                # the layout editor test: scripted mouse and keys
  x11-apps                               # the layout editor test: xwd, screenshots of the display
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "crisp setup: installing ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "crisp setup: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
