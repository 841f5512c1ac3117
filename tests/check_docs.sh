#!/usr/bin/env bash
# The repository stands on its own: nothing tracked points at design notes outside it, every
# relative link of the README and docs/ reaches a file of the repository, and the README stays a
# short guide. Prints each problem and exits 1 when there is any.
#   bash tests/check_docs.sh [SOURCE_DIR]
set -uo pipefail

ROOT=$(cd "${1:-$(dirname "${BASH_SOURCE[0]}")/..}" && pwd)
cd "$ROOT" || exit 2
SELF=tests/check_docs.sh
MAX_README_LINES=450
problems=0
problem() {
  echo "check_docs: $*"
  problems=$((problems + 1))
}

# The files of the repository: git's list in a checkout, every file otherwise.
if git -C "$ROOT" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t FILES < <(git -C "$ROOT" ls-files --cached --others --exclude-standard)
else
  mapfile -t FILES < <(find . -type f ! -path './build*' ! -path './.git/*' | sed 's|^\./||')
fi
declare -A KNOWN=()
declare -A KNOWN_DIRS=()
for f in "${FILES[@]}"; do
  [ -e "$f" ] || continue  # deleted in the work tree
  KNOWN[$f]=1
  d=$(dirname "$f")
  while [ "$d" != . ] && [ -z "${KNOWN_DIRS[$d]:-}" ]; do
    KNOWN_DIRS[$d]=1
    d=$(dirname "$d")
  done
done

# (a) No file outside docs/ names the design notes that live outside the repository, or a design
# document by its bare name (docs/NAME.md is the one to name).
outside='\.\./shared/'"design"
bare='(^|[^/[:alnum:]_.-])(CODEC|LAVAPIPE|RENDERING|STYLE|ARCHITECTURE)\.md'
for f in "${FILES[@]}"; do
  case "$f" in docs/*|"$SELF") continue ;; esac
  [ -f "$f" ] || continue
  grep -Iq . "$f" 2>/dev/null || continue  # binary or empty
  while IFS= read -r hit; do
    problem "$f:$hit: names a design document outside docs/ (write docs/NAME.md)"
  done < <(grep -nE -e "$outside" -e "$bare" "$f" | cut -c1-160)
done
# Pages a reader opens must not send them beside the repository at all.
for f in README.md THIRD_PARTY_NOTICES.md docs/*.md; do
  [ -f "$f" ] || continue
  while IFS= read -r hit; do
    problem "$f:$hit: points outside the repository (../shared)"
  done < <(grep -nF '../shared' "$f" | cut -c1-160)
done

# (b) Every relative link in README.md and docs/*.md resolves to a file (or folder) of the
# repository. Fenced code blocks and inline code are not links.
links_of() {
  awk '/^[[:space:]]*```/ { fence = !fence; next } !fence { gsub(/`[^`]*`/, ""); print NR ":" $0 }' "$1" |
    grep -oE '^[0-9]+:|\]\([^)[:space:]]+' |
    awk '/^[0-9]+:$/ { line = substr($0, 1, length($0) - 1); next } { print line " " substr($0, 3) }'
}
for f in README.md docs/*.md; do
  [ -f "$f" ] || continue
  dir=$(dirname "$f")
  while read -r line target; do
    case "$target" in
      http://*|https://*|mailto:*|\#*) continue ;;
    esac
    path=${target%%#*}
    [ -n "$path" ] || continue
    resolved=$(realpath -m --relative-to="$ROOT" "$dir/$path")
    resolved=${resolved%/}
    if [ -z "${KNOWN[$resolved]:-}" ] && [ -z "${KNOWN_DIRS[$resolved]:-}" ]; then
      problem "$f:$line: link to $target does not reach a file of the repository"
    fi
  done < <(links_of "$f")
done

# (c) The README is a guide, not a notebook.
if [ -f README.md ]; then
  n=$(wc -l <README.md)
  if [ "$n" -gt "$MAX_README_LINES" ]; then
    problem "README.md has $n lines, more than $MAX_README_LINES: move detail into docs/"
  fi
else
  problem "README.md is missing"
fi

if [ "$problems" -gt 0 ]; then
  echo "check_docs: $problems problem(s)"
  exit 1
fi
echo "check_docs: README.md and docs/ are self-contained"
