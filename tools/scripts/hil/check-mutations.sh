#!/usr/bin/env bash
# The checks must be able to fail: each mutation below breaks one thing a
# check guards, in a copy of a passing run's results, and hil-check.py
# must then fail on exactly that check.  Run by make hil after the checks.
#   tools/scripts/hil/check-mutations.sh RESULTS_DIR CHECK_ARGS...
# (the kill's EMCYs moved later keep their order in the file: the check
# reads times, not positions)
set -euo pipefail
results=$1
shift
here=$(dirname "$0")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0

# the line number of the Nth line matching a pattern
nth() { grep -n "$2" "$1" | sed -n "${3}p" | cut -d: -f1; }

skip_sync() { sed -i "$(nth "$work/r/base.candump" ' 080#' 200)d" "$work/r/base.candump"; }
two_rpdos() { local n; n=$(nth "$work/r/base.candump" ' 202#' 200); sed -i "${n}p" "$work/r/base.candump"; }
late_off() {        # the first three torque-off windows after the EMCY keep the torque
	local n; n=$(nth "$work/r/emcy.candump" ' 083#' 1)
	sed -i "$n,\$ { s/ 20\([123]\)#00000000$/ 20\1#0F000100/ }" "$work/r/emcy.candump"
	sed -i "$(nth "$work/r/emcy.candump" ' 080#' "$(( $(grep -c ' 080#' <(head -n "$n" "$work/r/emcy.candump")) + 3 ))"),\$ { s/ 20\([123]\)#0F000100$/ 20\1#00000000/ }" "$work/r/emcy.candump"
}
weak_force() { awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i ~ /^d0_f[xyz]_n$/) c[i] = 1; print; next }
	{ for (i in c) $i = $i * 1.5; print }' "$results/base.csv" > "$work/r/base.csv"; }
no_rt() { sed -i 's/PREEMPT_RT/PREEMPT_DYNAMIC/' "$work/r/kernel.txt"; }
no_overflow() { sed -i '/ 60[123]#2F191000/d' "$work/r/base.candump"; }
late_stop() {       # the drives' EMCYs after the kill one second later
	awk '$3 ~ /^08[123]#/ { t = substr($1, 2, length($1) - 2) + 1.0; $1 = sprintf("(%.6f)", t) } { print }' \
		"$results/kill.candump" > "$work/r/kill.candump"
}
no_reason() { sed -i '1s/drive 2 (node 2)/a drive/' "$work/r/sdo.fw.txt"; }

args=("$@")
# mutate NAME EXPECTED_FAILURE FUNCTION: FUNCTION edits the copy in $work/r
mutate() {
	local name=$1 expect=$2 fn=$3
	rm -rf "$work/r" && cp -r "$results" "$work/r"
	"$fn"
	python3 "$here/hil-check.py" "$work/r" "${args[@]}" > "$work/out" 2>&1 || true
	if grep -q "hil: FAILED: .*$expect" "$work/out"; then
		echo "hil: mutation '$name' caught ($expect)"
	else
		echo "hil: mutation '$name' NOT caught: expected a failure of '$expect'" >&2
		failed=1
	fi
}
mutate "a SYNC skipped" "counter +1 each time" skip_sync
mutate "two RPDO1 for one axis" "exactly one RPDO1 per axis" two_rpdos
mutate "the torque-off delayed 3 periods" "emcy: every axis RPDO1 00 00 00 00" late_off
mutate "forces 1.5 times the reference's" "forces: hold means" weak_force
mutate "a kernel without PREEMPT_RT" "PREEMPT_RT" no_rt
mutate "the start-up failure unnamed" "sdo: start-up refused" no_reason
mutate "0x1019 never written" "base: node 1: 0x1019" no_overflow
mutate "the drives stop 1 s later after the kill" "kill: node 1 at zero torque within" late_stop
exit $failed
