#!/usr/bin/env bash
# The default scene (the paper's cuboid, top face touchable, every key at
# its default: representation = auto, max_error = 1e-3) at finer meshes:
# how far the every-mode dense eigensolve, split by the mesh's symmetries
# (docs/precompute.md), carries the default target; then where every mode
# does not fit in memory, auto's hybrid of the lowest modes of a Lanczos
# solve and a head from Chebyshev series in the stiffness (measured
# against max_error as the default asks): at the paper's mesh under
# max_memory_mib = 512, and at 20,812 nodes, whose every mode does not fit
# in this machine's memory (its head needs max_head_mib = 256).  Prints a
# Markdown table; the logs and images stay in out/scale/.
#   tools/scripts/scale.sh [IRDM] [RES ...]   (RES: NX,NY,NZ; default the
#   paper's 11,11,22 and 17,17,34)
#   SCALE_LOWEST='RES:KEY=VALUE,... ...' (default
#   11,11,22:max_memory_mib=512 21,21,42:max_head_mib=256; empty: none):
#   the rows from the lowest modes
set -euo pipefail
irdm=${1:-build/irdm}
shift || true
res=("$@")
[ ${#res[@]} -gt 0 ] || res=(11,11,22 17,17,34)
mkdir -p out/scale
echo "| resolution | keys set | mesh | free DoFs | eigensolve | representation | measured error | two contacts | precompute | CPU | peak memory | image |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
# row RES NAME SET [PRECOMPUTE ARG...]: one table row, its log and image
# out/scale/NAME.* (SET: the keys set beside the scene's, as text)
row() {
	local r=$1 name=$2 set=$3
	shift 3
	local log=out/scale/$name.log img=out/scale/$name.img
	echo "scale: $r $set ..." >&2
	TIMEFORMAT='%U %S'
	{ time "$irdm" precompute --scene scenes/cuboid-top.scene --resolution "$r" "$@" -o "$img" \
		>"$log" 2>&1 || { tail -n 5 "$log" >&2; exit 1; }; } 2>out/scale/time-$name
	"$irdm" image verify --require-stable "$img" >>"$log"
	tr '\r' '\n' <"$log" | awk -v r="$r" -v set="$set" -v cpu="$(awk '{ print $1 + $2 }' out/scale/time-$name)" \
	    -v bytes="$(stat -c %s "$img")" '
		/^mesh  / { mesh = $2 " nodes, " $4 " tets"; dofs = $6 }
		/^symmetry:/ { split($0, a, "splits into "); blocks = a[2] + 0 }
		/^representation auto:/ { sub(/^representation auto: /, ""); sub(/, (the cheapest|from the lowest).*/, ""); repr = $0 }
		/^auto: .*solving the lowest / { solved = $NF }
		/^  Lanczos eigensolve/ { lanczos = 1 }
		/^time / { total = $2; for (i = 3; i <= NF; i++) if ($i == "eigen") eig = $(i + 1) }
		/^memory / { peak = $3 }
		/^force error / { err = $3 }
		/^two contacts / { pairs = $3 }
		END {
			sub(/,$/, "", eig)
			how = lanczos ? "Lanczos, the lowest " (solved != "" ? solved : 16) : blocks ? blocks " blocks (every mode)" : "whole"
			printf "| %s | %s | %s | %s | %s s, %s | %s | %s | %s | %s s | %.0f s | %s MiB | %.1f MB |\n",
			       r, set != "" ? set : "none", mesh, dofs, eig, how, repr, err,
			       pairs == "" ? "-" : pairs, total, cpu, peak, bytes / 1e6 }'
}

for r in "${res[@]}"; do
	row "$r" "cuboid-$r" ""
done
lowest=${SCALE_LOWEST-11,11,22:max_memory_mib=512 21,21,42:max_head_mib=256}
[ -n "$lowest" ] || exit 0
for spec in $lowest; do
	r=${spec%%:*}
	keys=${spec#*:}
	args=()
	IFS=, read -ra kv <<<"$keys"
	for k in "${kv[@]}"; do
		args+=("--${k%%=*}" "${k#*=}")
	done
	row "$r" "cuboid-$r-lowest" "${keys//,/, }" "${args[@]}"
done
echo
echo "The rows \"Lanczos, the lowest N\": every mode did not fit (max_memory_mib, or this machine's memory), so representation = auto kept the lowest modes whose envelope after a 128-sample head is over 200 max_error, from a Lanczos solve of the lowest N, and built the head from Chebyshev series in the stiffness (docs/precompute.md, \"The head without every mode\"); the error measured against the kept modes and Chebyshev series over the whole run at 6 nodes; two contacts not measured.  Their precompute's lines, row by row:"
echo
echo '```'
for spec in $lowest; do
	r=${spec%%:*}
	tr '\r' '\n' <"out/scale/cuboid-$r-lowest.log" | grep -E '^(auto|krylov head):' | sed "s/^/$r  /"
done
echo '```'
