#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The precompute against materials nobody tuned it for: a small cuboid
# (resolution 4,4,8, fixed at its base, touched on top) over a grid of
# materials from a soft gel to steel-like stiffness, incompressible ones
# and a very light and a very heavy one, two ticks (1 and 2 ms), the three
# stored precisions and two ways of asking (the default, and a hybrid of
# 100 modes + a 128-sample head).  FIRs are left out: fir_tail = window
# finds its window by building the FIR again for each length it tries,
# over ten minutes a case on the soft materials here.
#
# Each case must end one of two ways: an image written that is certified
# (irdm image verify --require-stable accepts it) and whose measured error
# against the exact model (stored in the image, read back by irdm image
# info) is within max_error; or a refusal with a one-line message.  Any
# other end (an image off target or uncertified, a crash, no message) is a
# failure: the table marks it and the script exits 1.
#
#   tools/scripts/material-grid.sh IRDM [JOBS]      Markdown on stdout
#
# MATERIAL_GRID_QUICK=1 runs one tick and f32 only (a smoke run).
set -euo pipefail
irdm=${1:?usage: material-grid.sh IRDM [JOBS]}
jobs=${2:-1}
work=$(mktemp -d "${TMPDIR:-/tmp}/irdm-grid.XXXXXX")
trap 'rm -rf "$work"' EXIT

cat > "$work/base.scene" <<'EOF'
name = material-grid
mesh = cuboid
resolution = 4,4,8
fixed = z<=0
touch = z>=0.2
display = surface
EOF

# shellcheck source=tools/scripts/grid-materials.sh
. "$(dirname "$0")/grid-materials.sh"
materials=("${grid_materials[@]}")
dts=("${grid_dts[@]}")
precs=(f16 f32 f64)
reprs=("default" "modal:100+head:128")
if [ "${MATERIAL_GRID_QUICK:-0}" = 1 ]; then
	dts=(0.002)
	precs=(f32)
fi

# One case: its row's cells, tab-separated, into $work/NNN.row.
run_case() {
	local id=$1 E=$2 nu=$3 rho=$4 dt=$5 prec=$6 repr=$7
	local img=$work/$id.img log=$work/$id.log args=()
	case $repr in
	default) ;;
	modal:100+head:128) args=(--representation modal:100 --static_correction yes --exact_head 128) ;;
	esac
	local rc=0 t0 t1 verdict err radius msg head
	t0=$(date +%s.%N)
	"$irdm" precompute --scene "$work/base.scene" --young "$E" --poisson "$nu" \
		--density "$rho" --dt "$dt" --precision "$prec" "${args[@]}" \
		-o "$img" > "$log" 2>&1 || rc=$?
	t1=$(date +%s.%N)
	local secs
	secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
	if [ "$rc" = 0 ] && [ -f "$img" ]; then
		local info
		info=$("$irdm" image info "$img")
		err=$(sed -n 's/^force error *\([^ ]*\) against.*/\1/p' <<< "$info")
		radius=$(sed -n 's/^stability *max spectral radius \([^;]*\);.*/\1/p' <<< "$info")
		msg=$(sed -n 's/^responses *//p' <<< "$info")
		head=$(sed -n 's/^exact head .*samples 0\.\.\([0-9]*\) exact.*/\1/p' <<< "$info")
		[ -z "$head" ] || msg="$msg, exact head $((head + 1))"
		grep -q '^representation *auto:' "$log" && msg="auto: $msg"
		verdict=written
		if ! "$irdm" image verify --require-stable "$img" > /dev/null 2>&1; then
			verdict="FAIL: written, not certified"
		elif [ -z "$err" ]; then
			verdict="FAIL: written, error not measured"
		elif ! awk -v e="$err" 'BEGIN { exit !(e <= 1e-3) }'; then
			verdict="FAIL: written, off target"
		fi
	elif [ "$rc" = 1 ] && [ ! -e "$img" ]; then
		msg=$(grep -m 1 '^irdm precompute:' "$log" || true)
		if [ -n "$msg" ] && [ "$(grep -c '^irdm precompute:' "$log")" = 1 ]; then
			verdict=refused
		else
			verdict="FAIL: no one-line message"
		fi
		err=- radius=-
	else
		verdict="FAIL: exit $rc"
		msg=$(tail -n 1 "$log")
		err=- radius=-
	fi
	msg=${msg#irdm precompute: }
	msg=${msg//|/\\|}
	printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$E" "$nu" "$rho" "$dt" "$prec" \
		"$repr" "$verdict" "$err" "$radius" "$secs" "$msg" > "$work/$id.row"
	rm -f "$img"
}
export -f run_case
export irdm work

n=0
for m in "${materials[@]}"; do
	for dt in "${dts[@]}"; do
		for prec in "${precs[@]}"; do
			for repr in "${reprs[@]}"; do
				# shellcheck disable=SC2086
				printf '%03d %s %s %s %s %s %s\n' "$n" $m "$dt" "$prec" "$repr"
				n=$((n + 1))
			done
		done
	done
done > "$work/cases"
total=$n
echo "material grid: $total cases, $jobs at a time" >&2
xargs -P "$jobs" -L 1 bash -c 'run_case "$0" "$@"; echo "  case $0 done" >&2' < "$work/cases"

echo "Cuboid resolution 4,4,8 (225 nodes, 25 touchable), fixed base, every"
echo "case with max_error at its default (1e-3).  *written*: certified by"
echo "\`irdm image verify --require-stable\` and its stored measured error"
echo "(relative RMS force error of a step and a release against the exact"
echo "model) within 1e-3; *refused*: the precompute's one-line message."
echo
echo "| E (Pa) | nu | rho (kg/m^3) | dt (s) | precision | asked | result | error | radius | s | representation or message |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
cat "$work"/[0-9]*.row | while IFS=$'\t' read -r E nu rho dt prec repr verdict err radius secs msg; do
	echo "| $E | $nu | $rho | $dt | $prec | $repr | $verdict | $err | $radius | $secs | $msg |"
done
written=$(cat "$work"/[0-9]*.row | awk -F'\t' '$7 == "written"' | wc -l)
refused=$(cat "$work"/[0-9]*.row | awk -F'\t' '$7 == "refused"' | wc -l)
failed=$(cat "$work"/[0-9]*.row | awk -F'\t' '$7 ~ /^FAIL/' | wc -l)
echo
echo "$total cases: $written written (each certified and within 1e-3), $refused refused with a message, $failed failed."
[ "$failed" = 0 ] && [ $((written + refused)) = "$total" ]
