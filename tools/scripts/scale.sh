#!/usr/bin/env bash
# The default scene (the paper's cuboid, top face touchable, every key at
# its default: representation = auto, max_error = 1e-3) at finer meshes:
# how far the every-mode dense eigensolve, split by the mesh's symmetries
# (docs/precompute.md), carries the default target; then a hybrid whose
# head comes from Chebyshev series in the stiffness (eigensolver =
# lanczos, its kept modes and head named, measured against max_error as
# the default asks), at the paper's mesh and at 20,812 nodes, whose every
# mode would not fit in this machine's memory.  Prints a Markdown table; the logs and images stay in out/scale/.
#   tools/scripts/scale.sh [IRDM] [RES ...]   (RES: NX,NY,NZ; default the
#   paper's 11,11,22 and 17,17,34)
#   SCALE_KRYLOV='RES:K:H ...' (default 11,11,22:275:128 21,21,42:400:128;
#   empty: none): the rows without every mode
set -euo pipefail
irdm=${1:-build/irdm}
shift || true
res=("$@")
[ ${#res[@]} -gt 0 ] || res=(11,11,22 17,17,34)
mkdir -p out/scale
echo "| resolution | mesh | free DoFs | eigensolve | representation | measured error | two contacts | precompute | CPU | peak memory | image |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
# row RES NAME LABEL [PRECOMPUTE ARG...]: one table row, its log and
# image out/scale/NAME.* (LABEL: the representation; empty: auto's, from
# its log)
row() {
	local r=$1 name=$2 label=$3
	shift 3
	local log=out/scale/$name.log img=out/scale/$name.img
	echo "scale: $r ..." >&2
	TIMEFORMAT='%U %S'
	{ time "$irdm" precompute --scene scenes/cuboid-top.scene --resolution "$r" "$@" -o "$img" \
		>"$log" 2>&1 || { tail -n 5 "$log" >&2; exit 1; }; } 2>out/scale/time-$name
	"$irdm" image verify --require-stable "$img" >>"$log"
	tr '\r' '\n' <"$log" | awk -v r="$r" -v label="$label" -v cpu="$(awk '{ print $1 + $2 }' out/scale/time-$name)" \
	    -v bytes="$(stat -c %s "$img")" '
		/^mesh  / { mesh = $2 " nodes, " $4 " tets"; dofs = $6 }
		/^symmetry:/ { split($0, a, "splits into "); blocks = a[2] + 0 }
		/^representation auto:/ { sub(/^representation auto: /, ""); sub(/, the cheapest.*/, ""); repr = $0 }
		/^modes  / { kept = $2 }
		/^  Lanczos eigensolve/ { lanczos = 1 }
		/^time / { total = $2; for (i = 3; i <= NF; i++) if ($i == "eigen") eig = $(i + 1) }
		/^memory / { peak = $3 }
		/^force error / { err = $3 }
		/^two contacts / { pairs = $3 }
		END {
			sub(/,$/, "", eig)
			how = lanczos ? "Lanczos, " kept " modes" : blocks ? blocks " blocks" : "whole"
			printf "| %s | %s | %s | %s s, %s | %s | %s | %s | %s s | %.0f s | %s MiB | %.1f MB |\n",
			       r, mesh, dofs, eig, how, label != "" ? label : repr, err,
			       pairs == "" ? "-" : pairs, total, cpu, peak, bytes / 1e6 }'
}

for r in "${res[@]}"; do
	row "$r" "cuboid-$r" ""
done
krylov=${SCALE_KRYLOV-11,11,22:275:128 21,21,42:400:128}
[ -n "$krylov" ] || exit 0
for spec in $krylov; do
	IFS=: read -r r k h <<<"$spec"
	row "$r" "cuboid-$r-krylov" "modal:$k + static correction + exact_head $h, the head from Chebyshev series" \
		--eigensolver lanczos --representation "modal:$k" --exact_head "$h"
done
echo
echo "The rows \"the head from Chebyshev series\": \`--eigensolver lanczos --representation modal:K --exact_head H\` (docs/precompute.md, \"The head without every mode\"): no dense eigensolve; the error measured against the kept modes and Chebyshev series over the whole run at 6 nodes, two contacts not measured.  The precompute's line on its runs, row by row:"
echo
echo '```'
for spec in $krylov; do
	r=${spec%%:*}
	printf '%s  ' "$r"
	tr '\r' '\n' <"out/scale/cuboid-$r-krylov.log" | grep '^krylov head:'
done
echo '```'
