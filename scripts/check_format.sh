#!/usr/bin/env bash
# Checks that every tracked C++ file of solver/ api/ server/ tests/ bench/ fuzz/
# is formatted as .clang-format says. Exit 0 when none differs; 1 with the
# list of files that differ (fix them with --fix, or `clang-format -i FILE`);
# 2 when clang-format is missing.
#   bash scripts/check_format.sh          # check
#   bash scripts/check_format.sh --fix    # rewrite the files that differ
# CLANG_FORMAT names the binary (default: clang-format).
set -euo pipefail
cd "$(dirname "$0")/.."
fix=0
case "${1:-}" in
  --fix) fix=1 ;;
  "") ;;
  *) echo "usage: $0 [--fix]" >&2; exit 2 ;;
esac
clang_format=${CLANG_FORMAT:-clang-format}
if ! command -v "$clang_format" >/dev/null; then
  echo "check_format: $clang_format not found (Debian: apt-get install clang-format)" >&2
  exit 2
fi
# Tracked files; outside a git checkout (a source tarball), every file.
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  list_sources() { git ls-files -- solver api server tests bench fuzz; }
else
  list_sources() { find solver api server tests bench fuzz -type f | sort; }
fi
mapfile -t files < <(list_sources | grep -E '\.(cpp|hpp|h|cc)$')
differ=()
for f in "${files[@]}"; do
  if ! "$clang_format" --dry-run -Werror "$f" >/dev/null 2>&1; then
    differ+=("$f")
  fi
done
if [ ${#differ[@]} -eq 0 ]; then
  echo "check_format: ${#files[@]} files, all formatted ($("$clang_format" --version | head -1))"
  exit 0
fi
if [ $fix -eq 1 ]; then
  "$clang_format" -i "${differ[@]}"
  printf 'check_format: reformatted %s\n' "${differ[@]}"
  exit 0
fi
printf '%s\n' "${differ[@]}"
echo "check_format: ${#differ[@]} of ${#files[@]} files differ from .clang-format" \
     "(bash scripts/check_format.sh --fix)" >&2
exit 1
