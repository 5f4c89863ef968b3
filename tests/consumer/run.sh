#!/usr/bin/env bash
# run.sh CMAKE BUILD_DIR WORK_DIR SOURCE_DIR: installs the build into WORK_DIR/prefix, then
# checks that every tool built is installed (and that the installed layout editor runs), then
# configures, builds and runs two projects against it with find_package(crisp CONFIG):
#   engine/  links crisp::crisp alone, as an engine does: it loads an asset the installed
#            crisp-bake made and lays out text. It is configured with FreeType and libpng hidden
#            from find_package, and neither its build commands, nor the undefined symbols of the
#            installed crisp library, nor (shared) the libraries they need, name either.
#   bake/    links crisp::bake and bakes a font.
set -euo pipefail
cmake=$1 build=$2 work=$3 source=$4
prefix=$work/prefix
rm -rf "$work"
mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
for tool in nm readelf; do
  command -v "$tool" >/dev/null || fail "$tool is missing (binutils)"
done
"$cmake" --install "$build" --prefix "$prefix" >/dev/null
test -f "$prefix/lib/cmake/crisp/crispConfig.cmake"
test -f "$prefix/lib/cmake/crisp/crispConfigVersion.cmake"
test -x "$prefix/bin/crisp-bake"
for tool in crisp-render crisp-bench crisp-layout-editor; do  # every tool this build made is installed
  [ ! -x "$build/tools/$tool" ] || [ -x "$prefix/bin/$tool" ] || fail "$tool is built but not installed"
done
# The installed editor runs from the prefix: its headless export needs no display, font or device.
if [ -x "$prefix/bin/crisp-layout-editor" ]; then
  env -u DISPLAY -u WAYLAND_DISPLAY "$prefix/bin/crisp-layout-editor" --layout bgr --export fontconfig \
    >"$work/editor-export.xml" || fail "the installed crisp-layout-editor --export fontconfig failed"
  grep -q "<const>bgr</const>" "$work/editor-export.xml" || fail "the installed editor's export: $(cat "$work/editor-export.xml")"
fi
test ! -e "$prefix/include/crisp/../bands.hpp"   # nothing private is installed
test ! -e "$prefix/lib/libcrisp_support.a"       # nor the tools' support library

# ---- The run time: no FreeType, no libpng.
if [ -e "$prefix/lib/libcrisp.so" ]; then library=$prefix/lib/libcrisp.so; else library=$prefix/lib/libcrisp.a; fi
nm -u "$library" >"$work/crisp-undefined.txt"
! grep -E ' (FT_|png_)' "$work/crisp-undefined.txt" || fail "$library references FreeType or libpng (above)"
"$prefix/bin/crisp-bake" "$source/fonts/DejaVuSans.ttf" --text crisp -q -o "$work/DejaVuSans-crisp.crisp"
# A shared crisp's config looks neither up: --no-warn-unused-cli keeps CMake from saying so.
"$cmake" -S "$source/tests/consumer/engine" -B "$work/engine" -DCMAKE_PREFIX_PATH="$prefix" --no-warn-unused-cli \
  -DCMAKE_DISABLE_FIND_PACKAGE_Freetype=ON -DCMAKE_DISABLE_FIND_PACKAGE_PNG=ON >"$work/engine-configure.log"
"$cmake" --build "$work/engine" -v >"$work/engine-build.log"
# Every compile and link command, with the two directories (whatever their names) taken out.
sed -e "s|$work|WORK|g" -e "s|$source|SOURCE|g" "$work/engine-build.log" >"$work/engine-commands.log"
grep -q -- "-o engine_consumer .*libcrisp" "$work/engine-commands.log" || fail "no link command in $work/engine-build.log"
! grep -i -E 'freetype|png' "$work/engine-commands.log" || fail "the engine consumer's build names FreeType or libpng (above)"
if [ -e "$prefix/lib/libcrisp.so" ]; then
  for binary in "$library" "$work/engine/engine_consumer"; do
    ! readelf -d "$binary" | grep NEEDED | grep -i -E 'freetype|png' || fail "$binary needs FreeType or libpng (above)"
  done
fi
"$work/engine/engine_consumer" "$work/DejaVuSans-crisp.crisp"

# ---- The baker.
"$cmake" -S "$source/tests/consumer/bake" -B "$work/bake" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
"$cmake" --build "$work/bake" >/dev/null
"$work/bake/bake_consumer" "$source/fonts/DejaVuSans.ttf"
