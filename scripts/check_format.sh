#!/usr/bin/env bash
# Checks that every C++ file git tracks or would add is formatted as .clang-format says
# (clang-format 14, Debian 12's). Prints the files that differ and how to fix them; exit 1 if any
# does. --fix formats them.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.cpp' '*.hpp' '*.h')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
unformatted=()
for file in "${files[@]}"; do
  clang-format --dry-run -Werror "$file" >/dev/null 2>&1 || unformatted+=("$file")
done
if [ ${#unformatted[@]} -gt 0 ]; then
  printf 'not formatted: %s\n' "${unformatted[@]}" >&2
  echo "format them with: scripts/check_format.sh --fix" >&2
  exit 1
fi
echo "formatted: ${#files[@]} files"
