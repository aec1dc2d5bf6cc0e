#!/usr/bin/env bash
# Formats every C++ file of the tree with clang-format (.clang-format at the
# root), or with --check lists the files that are not formatted and fails.
# CI runs the check (scripts/test.sh); clang-format 14 is Debian 12's.
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-fix}"
# Tracked files and new ones not yet added (not those .gitignore keeps out),
# so a file formats before its first commit, as CI's clone will check it.
mapfile -t files < <(git ls-files --cached --others --exclude-standard \
  '*.cc' '*.h' | sort -u)
if [ ${#files[@]} -eq 0 ]; then
  echo "format: no C++ files found" >&2
  exit 1
fi
case "$mode" in
  fix)
    clang-format -i "${files[@]}"
    echo "format: ${#files[@]} files formatted"
    ;;
  --check)
    bad=()
    for f in "${files[@]}"; do
      if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
        bad+=("$f")
      fi
    done
    if [ ${#bad[@]} -ne 0 ]; then
      echo "format: ${#bad[@]} of ${#files[@]} files are not clang-format clean:" >&2
      printf '  %s\n' "${bad[@]}" >&2
      echo "format: run scripts/format.sh to fix them" >&2
      exit 1
    fi
    echo "format: all ${#files[@]} files clang-format clean"
    ;;
  *)
    echo "usage: scripts/format.sh [--check]" >&2
    exit 2
    ;;
esac
