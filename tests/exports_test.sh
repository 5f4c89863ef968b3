#!/usr/bin/env bash
# exports_test.sh HEADERS_DIR LIBRARY...: each LIBRARY (static or shared) gives default visibility,
# which a shared build exports, only to what the public headers in HEADERS_DIR declare. Every
# global symbol of namespace crisp that is not hidden must name, as its first part after crisp::,
# a class, struct or function declared there: crisp::Renderer::record passes, crisp::json::parse or
# crisp::vk::create_buffer fails.
set -euo pipefail
headers=$1
shift
declarations=$(cat "$headers"/*.hpp)
status=0
for library in "$@"; do
  names=$(readelf -sW -C "$library" |
    awk '$5 == "GLOBAL" && $6 == "DEFAULT" && $7 != "UND" { $1 = $2 = $3 = $4 = $5 = $6 = $7 = ""; print }' |
    sed -e 's/^ *//' | grep '^crisp::' | sed -e 's/(.*//' -e 's/\[abi:[a-z0-9]*\]//g' -e 's/<.*//' | sort -u)
  [ -n "$names" ] || { echo "FAIL: $library exports nothing of crisp (not a crisp library?)"; status=1; }
  while read -r name; do
    rest=${name#crisp::}
    first=${rest%%::*}
    if ! grep -qE "(class|struct) (CRISP_API )?$first\b|\b$first\(" <<<"$declarations"; then
      echo "FAIL: $library exports $name, which no public header declares"
      status=1
    fi
  done <<<"$names"
done
exit $status
