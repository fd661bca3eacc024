#!/usr/bin/env bash
# words.sh - the project speaks of itself only. Fails (exit 1) when a tracked file names how
# it was built (work sessions, numbered issues), a path outside the repository or a private
# tool, and prints each such line as file:line:text. This script itself is not scanned.
#
# A control runs first: the same check on a temporary file holding each forbidden word must
# flag every one of them, or the check could not fail and the script exits 1.
set -euo pipefail
cd "$(dirname "$0")/.."

# Case-insensitive, extended regular expressions.
patterns=(
  'sessions?'          # how the work was divided up
  'issue ?#?[0-9]'     # "issue 8", "issue #8"
  '\.\./shared'        # a directory beside the repository
  'meshq'              # a checker that is not part of the project
  '/work/'             # the machine's own paths
)
pattern=$(IFS='|'; echo "${patterns[*]}")

# Legitimate uses: a file and an extended regular expression its matching line must match.
allowed=(
  # the CLI tests' scratch directory inside the build tree
  'tests/cli/CMakeLists.txt|CMAKE_CURRENT_BINARY_DIR\}/work/'
)

# Reads grep's file:line:text lines and prints those the allow-list does not cover.
not_allowed() {
  local hit file entry
  while IFS= read -r hit; do
    file=${hit%%:*}
    for entry in "${allowed[@]}"; do
      if [ "$file" = "${entry%%|*}" ] && grep -qE -- "${entry#*|}" <<< "$hit"; then
        continue 2
      fi
    done
    printf '%s\n' "$hit"
  done
}

# The control: one line per forbidden word, each must be reported.
control_dir=$(mktemp -d)
trap 'rm -rf "$control_dir"' EXIT
printf '%s\n' 'measured in session 4' 'as issue 12 asks' 'see ../shared/data' \
  'checked with MeshQ' 'copied from /work/main' > "$control_dir/control.txt"
control=$(git -C "$control_dir" grep --no-index -nIiE "$pattern" -- control.txt | not_allowed || true)
if [ "$(printf '%s\n' "$control" | grep -c .)" != 5 ]; then
  echo "words.sh: the control is not flagged line by line:"
  printf '%s\n' "$control"
  exit 1
fi
echo "words.sh: the control's 5 forbidden words are flagged: ok"

hits=$(git grep -nIiE "$pattern" -- . ':(exclude).ci/words.sh' | not_allowed || true)
if [ -n "$hits" ]; then
  printf '%s\n' "$hits"
  echo "words.sh: $(printf '%s\n' "$hits" | grep -c .) lines name sessions, issues, paths outside the repository or private tools"
  exit 1
fi
echo "words.sh: no process words in tracked files"
