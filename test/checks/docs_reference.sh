#!/usr/bin/env bash
# Reference pages say what is true now; history lives in docs/decisions/.
#
# Usage: docs_reference.sh REPO_ROOT
#
# Fails (exit 1), printing `file:line: what` for each finding, when
#   - a reference page (README.md, docs/**/*.md outside docs/decisions/) holds a date: YYYY-MM-DD or
#     "Month YYYY";
#   - a doc or source file names an issue by its number (the word issue or issues followed by a number,
#     with or without '#', also across a line break, or a '#' and a number in parentheses) or a section of
#     a design file that is not in the repository (DESIGN followed by a section sign or a number). Say the
#     rule itself, or link the decision in docs/decisions/ that explains it.
#
# Not flagged: `#include`, markdown headings, CSS colours (#fff), HTML entities (&#38;), counters in
# program output ("restart #1", "Test #12:", "item #3"): a bare '#' and number counts only in parentheses.
set -euo pipefail

root=${1:?usage: docs_reference.sh REPO_ROOT}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cd "$root"

# The files to read, NUL-separated, relative to the root.
list_files() {
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git ls-files -z
  else
    find . -path ./build -prune -o -path '*/node_modules' -prune -o -path '*/.git' -prune -o \
      -type f -print0 | sed -z 's|^\./||'
  fi
}

# Documentation and source: by extension, plus the extension-less scripts of deploy/, tools/, test/, .ci/.
is_checked() {
  case $1 in
    */node_modules/* | node_modules/*) return 1 ;;
    *.md | *.cpp | *.hpp | *.h | *.c | *.cc | *.js | *.mjs | *.cmake | */CMakeLists.txt | CMakeLists.txt | \
      *.sh | *.py | *.idl | *.html | *.css | *.yaml | *.yml) return 0 ;;
    deploy/* | tools/* | test/* | .ci/*) [[ ${1##*/} != *.* ]] ;;
    *) return 1 ;;
  esac
}

is_reference_page() {
  case $1 in
    README.md) return 0 ;;
    docs/decisions/*) return 1 ;;
    docs/performance.md) return 1 ;;  # the benches' output (test/bench/run): each figure says when it was measured
    docs/*.md) return 0 ;;
    *) return 1 ;;
  esac
}

checked=()
pages=()
while IFS= read -r -d '' f; do
  [[ -f $f ]] || continue
  is_checked "$f" || continue
  checked+=("$f")
  if is_reference_page "$f"; then pages+=("$f"); fi
done < <(list_files)

months='January|February|March|April|May|June|July|August|September|October|November|December'
date_re="\\b[0-9]{4}-[01][0-9]-[0-3][0-9]\\b|\\b($months)( [0-3]?[0-9],?)? [0-9]{4}\\b"
issue_re='\b[Ii]ssues?[ -]#?[0-9]+|\(#[0-9]+\)'
design_re='DESIGN[[:space:]]*(§|[0-9])'

findings=$(mktemp)
trap 'rm -f "$findings"' EXIT

# grep -I skips binary files; each hit is `file:line:text`, reported as `file:line: what`.
report() {
  local what=$1 re=$2
  shift 2
  (($# > 0)) || return 0
  printf '%s\0' "$@" | xargs -0 grep -InHE -- "$re" 2>/dev/null |
    awk -v what="$what" '{ match($0, /^[^:]*:[0-9]+:/); loc = substr($0, 1, RLENGTH);
                           text = substr($0, RLENGTH + 1); sub(/^[ \t]+/, "", text);
                           print loc " " what ": " text }' >>"$findings" || true
}

# "issue" at the end of one line and its number at the start of the next (wrapped prose or comments).
report_wrapped_issues() {
  (($# > 0)) || return 0
  printf '%s\0' "$@" | xargs -0 grep -IlE -- '[Ii]ssues?[[:space:]]*$' 2>/dev/null |
    while IFS= read -r f; do
      awk -v f="$f" 'prev ~ /[Ii]ssues?[ \t]*$/ && $0 ~ /^[ \t]*((\/\/\/?|#|\*|--)[ \t]*)?#?[0-9]/ {
                       print f ":" NR - 1 ": issue number (say the rule, or link its decision): " prev }
                     { prev = $0 }' "$f"
    done >>"$findings" || true
}

report 'date in a reference page (history belongs in docs/decisions/)' "$date_re" ${pages[@]+"${pages[@]}"}
report 'issue number (say the rule, or link its decision)' "$issue_re" ${checked[@]+"${checked[@]}"}
report_wrapped_issues ${checked[@]+"${checked[@]}"}
report 'reference to a DESIGN section that is not in the repository' "$design_re" \
  ${checked[@]+"${checked[@]}"}

# Known string literals (program output, strings tests compare against): a repository check does not
# change what the code prints. docs_reference.allow lists them, one `path<TAB>fixed text` a line.
allow=$here/docs_reference.allow
if [[ -f $allow ]]; then
  kept=$(mktemp)
  trap 'rm -f "$findings" "$kept"' EXIT
  while IFS= read -r finding; do
    path=${finding%%:*}
    listed=0
    while IFS=$'\t' read -r allowed_path allowed_text; do
      [[ -z $allowed_path || $allowed_path == \#* ]] && continue
      if [[ $path == "$allowed_path" && $finding == *"$allowed_text"* ]]; then listed=1; fi
    done <"$allow"
    ((listed)) || printf '%s\n' "$finding"
  done <"$findings" >"$kept"
  mv "$kept" "$findings"
fi

if [[ -s $findings ]]; then
  sort -t: -k1,1 -k2,2n "$findings"
  echo "docs_reference: $(wc -l <"$findings") finding(s) in ${#checked[@]} files" >&2
  exit 1
fi
echo "docs_reference: ${#checked[@]} files, ${#pages[@]} reference pages: no dates, issue numbers or DESIGN sections"
