#!/usr/bin/env bash
# run.sh CMAKE BUILD_DIR WORK_DIR SOURCE_DIR: installs the build into WORK_DIR/prefix, then
# configures, builds and runs tests/consumer against it with find_package(crisp CONFIG).
set -euo pipefail
cmake=$1 build=$2 work=$3 source=$4
rm -rf "$work"
mkdir -p "$work"
"$cmake" --install "$build" --prefix "$work/prefix" >/dev/null
test -f "$work/prefix/lib/cmake/crisp/crispConfig.cmake"
test -f "$work/prefix/lib/cmake/crisp/crispConfigVersion.cmake"
test -x "$work/prefix/bin/crisp-bake"
test ! -e "$work/prefix/include/crisp/../bands.hpp"   # nothing private is installed
"$cmake" -S "$source/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
"$cmake" --build "$work/build" >/dev/null
"$work/build/consumer" "$source/fonts/DejaVuSans.ttf"
