#!/usr/bin/env bash
# One job per file: fails when a source file (C and C++, JavaScript, CMake, Python, shell) is longer than
# 600 lines, naming each such file. A file that grew past it is split by job, not added to the list below.
#
# Usage: file_length.sh REPOSITORY_ROOT
# In a git checkout the files are the tracked ones and the untracked ones git does not ignore; elsewhere
# (an unpacked source tree) every file below the root, without build trees, .git and node_modules.
set -euo pipefail

readonly kLimit=600

# Generated files only, each with the reason it may be longer (none today).
readonly allowed=(
)

root=${1:?usage: file_length.sh REPOSITORY_ROOT}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=source_files.sh
source "$here/source_files.sh"
cd "$root"

is_source() {
  case "$1" in
    */node_modules/* | node_modules/*) return 1 ;;
    *.cpp | *.hpp | *.h | *.c | *.js | *.mjs | *.cmake | *.py | *.sh) return 0 ;;
    *) return 1 ;;
  esac
}

failed=0
checked=0
while IFS= read -r -d '' path; do
  is_source "$path" || continue
  [[ -f "$path" ]] || continue  # deleted in the work tree, not yet in the index
  checked=$((checked + 1))
  lines=$(awk 'END { print NR }' "$path")
  if ((lines > kLimit)) && ! is_allowed "$path"; then
    echo "$path: $lines lines (limit $kLimit)"
    failed=1
  fi
done < <(list_files)

if ((failed)); then
  echo "file_length: split these files by job (one job per file); the limit is $kLimit lines" >&2
  exit 1
fi
echo "file_length: $checked source files, none over $kLimit lines"
