#!/usr/bin/env bash
# Run each test binary given on the command line, show its cmocka output,
# and close with one plain summary line that counts test cases:
#   "tests: N passed, M failed"
# Exit non-zero if any binary failed or a binary ran no test.
set -u
passed=0; failed=0; bad_bins=()
for t in "$@"; do
	name=$(basename "$t")
	out=$("$t" 2>&1); rc=$?
	printf '%s\n' "$out"
	p=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9][0-9]*\) test.*/\1/p' | awk '{s+=$1} END {print s+0}')
	f=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9][0-9]*\) test.*/\1/p' | awk '{s+=$1} END {print s+0}')
	if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi   # crashed before reporting
	if [ "$p" -eq 0 ] && [ "$f" -eq 0 ]; then f=1; echo "$name: ran no test"; fi
	passed=$((passed + p)); failed=$((failed + f))
	[ "$rc" -eq 0 ] || bad_bins+=("$name")
done
[ ${#bad_bins[@]} -eq 0 ] || echo "failing binaries: ${bad_bins[*]}"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
