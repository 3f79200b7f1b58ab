#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A generated block inside a hand-written document: prints DOC with the
# lines between "<!-- begin WHAT -->" and "<!-- end WHAT -->" replaced by
# standard input (make docs).  Fails when DOC lacks either marker.
#   tools/scripts/splice-doc.sh DOC WHAT < BLOCK
set -euo pipefail
doc=$1 what=$2
begin="<!-- begin $what -->" end="<!-- end $what -->"
grep -qxF "$begin" "$doc" && grep -qxF "$end" "$doc" || {
	echo "splice-doc: $doc has no '$begin' ... '$end' block" >&2
	exit 1
}
block=$(mktemp)
trap 'rm -f "$block"' EXIT
cat > "$block"
awk -v b="$begin" -v e="$end" -v f="$block" '
	$0 == b { print; while ((getline l < f) > 0) print l; skip = 1; next }
	$0 == e { skip = 0 }
	!skip' "$doc"
