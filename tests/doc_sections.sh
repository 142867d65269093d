#!/usr/bin/env bash
# Every "FORMAT.md §N" and "CONTRACT.md §N" cited in the sources and the docs names a heading of
# that document ("## N." or "### N"), so that a citation cannot outlive the section it points to.
set -euo pipefail
cd "$(dirname "$0")/.."
status=0
for doc in FORMAT CONTRACT; do
  sections=$(grep -oE '^#{2,4} [0-9]+(\.[0-9]+)*' "docs/$doc.md" | awk '{print $2}' | sed 's/\.$//')
  while IFS=: read -r file cited; do
    number=${cited##*§}
    if ! grep -qxF "$number" <<<"$sections"; then
      echo "$file: cites $doc.md §$number, which docs/$doc.md has no heading for" >&2
      status=1
    fi
  done < <(git grep -oE "$doc\.md §[0-9]+(\.[0-9]+)*" -- ':!target' ':!web/node_modules' | sort -u)
done
exit $status
