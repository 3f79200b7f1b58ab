#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The index of the tests for docs/testing.md (make docs): one row per
# tests/**/test_*.c, its name and the first paragraph of the comment that
# opens the file.  The comment is the test's own statement of what it
# checks, so the index cannot drift from it.
#   tools/scripts/test-index.sh [DIR]
set -euo pipefail
dir=${1:-tests}
echo "| test | what it checks |"
echo "|---|---|"
find "$dir" -name 'test_*.c' -not -path '*/support/*' | LC_ALL=C sort | while read -r f; do
	awk -v name="$(basename "$f" .c)" '
		/^\/\* SPDX/ { next }
		!started && /^\/\*/ { started = 1; sub(/^\/\* ?/, "") }
		!started { next }
		/^ \*\// || /^ \*$/ || /^$/ { if (text != "") exit; next }
		{
			end = sub(/ *\*\/.*$/, "")
			sub(/^ \* ?/, "")
			gsub(/\|/, "\\|")
			text = text (text == "" ? "" : " ") $0
			if (end) exit
		}
		END {
			if (text == "") text = "(no opening comment)"
			printf "| `%s` | %s |\n", name, text
		}' "$f"
done
