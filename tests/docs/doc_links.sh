#!/usr/bin/env bash
# No document cites a file that is not in the repository: every relative Markdown link in
# README.md and docs/ (resolved from the page's folder), every backticked path that starts with
# one of the repository's top-level folders (resolved from the root), and every *.md file named
# anywhere must exist. Paths with placeholders (<name>, *, {a,b}, ...) are skipped.
# Usage: doc_links.sh SRC
set -u
SRC=$(readlink -f "$1")
cd "$SRC" || exit 2
fails=0
pages=(README.md $(find docs -name '*.md' | sort))
for page in "${pages[@]}"; do
  dir=$(dirname "$page")
  # Markdown links and images: ](target) without a scheme; the #anchor is dropped.
  while IFS= read -r target; do
    target=${target%%#*}
    [ -z "$target" ] && continue
    case $target in http:* | https:* | mailto:*) continue ;; esac
    if [ ! -e "$dir/$target" ]; then
      echo "$page: link to a missing file: $target"
      fails=$((fails + 1))
    fi
  done < <(grep -oE '\]\([^) ]+\)' "$page" | sed -E 's/^\]\(//; s/\)$//')
  # Backticked repository paths.
  while IFS= read -r p; do
    case $p in *'<'* | *'*'* | *'{'* | *'...'* | *'$'* | *'|'*) continue ;; esac
    p=${p%%:*}  # file:line
    if [ ! -e "$p" ]; then
      echo "$page: names a missing file: $p"
      fails=$((fails + 1))
    fi
  done < <(grep -oE '`(assets|behaviors|worlds|lua|engine|tests|docs|cmake|\.ci)/[^` ]*`' "$page" | tr -d '`' | sort -u)
  # Any Markdown file named by its bare name (such as a design or module list).
  while IFS= read -r m; do
    if [ -z "$(git ls-files -- "$m" "*/$m" 2>/dev/null)" ] && [ ! -e "$dir/$m" ] && [ ! -e "$m" ]; then
      echo "$page: names a Markdown file that is not in the repository: $m"
      fails=$((fails + 1))
    fi
  done < <(grep -oE '(^|[^A-Za-z0-9_/.-])[A-Za-z0-9_-]+\.md\b' "$page" | sed -E 's/^[^A-Za-z0-9_-]//' | sort -u)
  # Anything outside the repository.
  if grep -nE '\.\./shared|\.\./\.\./' "$page" | grep -vE '\]\(\.\./' >/dev/null; then
    grep -nE '\.\./shared' "$page" | sed "s|^|$page: cites a path outside the repository: |"
    grep -qE '\.\./shared' "$page" && fails=$((fails + 1))
  fi
done
# Source comments and module types must not cite documents that are gone.
while IFS= read -r hit; do
  echo "cites a missing document: $hit"
  fails=$((fails + 1))
done < <(grep -rnE '\bMODULES\.md\b' --include='*.lua' --include='*.cpp' --include='*.h' --include='*.cmake' \
           --include='*.sh' assets behaviors worlds lua engine tests 2>/dev/null)
if [ "$fails" -gt 0 ]; then
  echo "$fails missing"
  exit 1
fi
echo "every file the documents cite exists (${#pages[@]} pages)"
