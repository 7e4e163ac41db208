# Sourced by the checks that read every source file (file_length.sh, wire_types.sh).

# Prints the files to read, NUL-separated, relative to the current directory (the repository root). In a
# git checkout: the tracked ones and the untracked ones git does not ignore; elsewhere (an unpacked source
# tree) every file below it, without build trees, .git and node_modules.
list_files() {
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git ls-files -z --cached --others --exclude-standard
  else
    find . \( -name .git -o -name node_modules -o -name 'build*' \) -prune -o -type f -print0 | sed -z 's|^\./||'
  fi
}

# Whether $1 is on the check's `allowed` list (entries: a path, or a path, a tab and the reason).
is_allowed() {
  local entry
  for entry in "${allowed[@]}"; do
    [[ "$1" == "${entry%%$'\t'*}" ]] && return 0
  done
  return 1
}
