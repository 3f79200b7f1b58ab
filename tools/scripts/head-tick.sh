#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The hybrid tick (bench_tick's hybrid-300+128 cases: a contact at one node
# and on one triangle) timed and counted, for one bench_tick binary or for
# two side by side (BEFORE, AFTER), as Markdown for measure.sh -m:
#  - time: median and p99 of each binary, the two run in turn ROUNDS times
#    (HEAD_TICK_ROUNDS, default 3), so a load change hits both;
#  - instructions per tick under callgrind (IRDM_BENCH_TICKS=1000 timed
#    ticks a case, --toggle-collect=irdm_engine_tick; bench_util.h makes
#    each case a dump of its own), and where they went: the functions with
#    the most instructions of their own, code inlined into a function
#    counted as the function's.
#
#   tools/scripts/head-tick.sh AFTER [BEFORE]
#
# Each binary runs from the root of its own tree (two levels above it:
# ROOT/build/bench/bench_tick), so that a BEFORE built from another
# checkout ticks the image its own precompute made (out/bench/ there,
# made when missing) even when the image format changed between them.
set -euo pipefail
[ $# -ge 1 ] && [ $# -le 2 ] || {
	echo "usage: head-tick.sh AFTER_BENCH_TICK [BEFORE_BENCH_TICK]" >&2
	exit 2
}
after=$1 before=${2:-}
rounds=${HEAD_TICK_ROUNDS:-3}
ticks=1000
cases=("hybrid-300+128 1 node" "hybrid-300+128 1 tri")
export IRDM_BENCH_ONLY="${cases[0]},${cases[1]}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

if [ -n "$before" ]; then
	names=(before after)
	bins=("$before" "$after")
else
	names=(this)
	bins=("$after")
fi
roots=()
for i in "${!bins[@]}"; do
	b=${bins[$i]}
	[ -x "$b" ] || { echo "head-tick: $b: not an executable" >&2; exit 2; }
	bins[$i]=$(realpath "$b")
	roots[$i]=$(cd "$(dirname "${bins[$i]}")/../.." && pwd)
done
# binary i, run from its tree's root
run() {
	local i=$1
	shift
	(cd "${roots[$i]}" && "$@")
}

# "median X us  p99 Y us" of a case in one bench_tick output (which pads
# the case's words with spaces)
figures() {
	local pat=${2// / *}
	sed -n "s/.*$pat *median *\([0-9.]*\) us *p99 *\([0-9.]*\) us.*/\1 \2/p" "$1"
}

echo "The hybrid tick: time and instructions per tick."
echo
for i in "${!names[@]}"; do
	echo "- ${names[$i]}: \`${bins[$i]}\` (built $(date -u -r "${bins[$i]}" '+%Y-%m-%d %H:%M UTC'), run from \`${roots[$i]}\`)"
done
echo "- cases: \`IRDM_BENCH_ONLY=\"$IRDM_BENCH_ONLY\"\` (tests/bench/bench_tick.c)"
echo
echo "## Time (median / p99 us, each round the binaries in turn)"
echo
for r in $(seq 1 "$rounds"); do
	for i in "${!names[@]}"; do
		run "$i" "${bins[$i]}" > "$tmp/time.$r.$i" 2>&1 ||
			{ cat "$tmp/time.$r.$i" >&2; exit 1; }
	done
done
printf '| case | round |'
for n in "${names[@]}"; do printf ' %s |' "$n"; done
printf '\n|---|---|'
for n in "${names[@]}"; do printf -- '---|'; done
printf '\n'
for c in "${cases[@]}"; do
	for r in $(seq 1 "$rounds"); do
		printf '| %s | %s |' "$c" "$r"
		for i in "${!names[@]}"; do
			read -r med p99 < <(figures "$tmp/time.$r.$i" "$c") || true
			printf ' %s / %s |' "${med:-?}" "${p99:-?}"
		done
		printf '\n'
	done
done
echo
grep -m1 '^tick  real-time' "$tmp/time.1.0" | sed 's/^tick  /Conditions: /' || true
echo
echo "## Instructions per tick (callgrind, $ticks timed ticks a case)"
echo
for i in "${!names[@]}"; do
	run "$i" env IRDM_BENCH_TICKS=$ticks valgrind --tool=callgrind --collect-atstart=no \
		--toggle-collect=irdm_engine_tick --callgrind-out-file="$tmp/cg.$i.%p" \
		"${bins[$i]}" > "$tmp/cg.$i.log" 2>&1 || { cat "$tmp/cg.$i.log" >&2; exit 1; }
done
# the dump of case c (its trigger names it) of binary i
dump() {
	grep -l "^desc: Trigger: Client Request: $2" "$tmp"/cg."$1".*.* | head -n 1
}
total() {
	sed -n 's/^summary: //p' "$1"
}
printf '| case |'
for n in "${names[@]}"; do printf ' %s |' "$n"; done
printf '\n|---|'
for n in "${names[@]}"; do printf -- '---:|'; done
printf '\n'
for c in "${cases[@]}"; do
	printf '| %s |' "$c"
	for i in "${!names[@]}"; do
		printf ' %s |' "$(($(total "$(dump "$i" "$c")") / ticks))"
	done
	printf '\n'
done
echo
echo "## Where the instructions went (per tick, the functions with the most of their own)"
for c in "${cases[@]}"; do
	for i in "${!names[@]}"; do
		echo
		echo "${names[$i]}, $c:"
		echo
		echo '```'
		callgrind_annotate --inclusive=no --threshold=100 "$(dump "$i" "$c")" |
			sed -n 's/^ *\([0-9,]*\) ([ 0-9.]*%) *[^ ]*:\([A-Za-z_][A-Za-z0-9_]*\)\( \[.*\]\)\{0,1\}$/\1 \2/p' |
			tr -d , |
			awk -v t="$ticks" '$2 != "main" && $2 !~ /^__libc/ { s[$2] += $1 }
				END { for (f in s) printf "%8d  %s\n", s[f] / t, f }' |
			sort -rn | head -n 8
		echo '```'
	done
done
