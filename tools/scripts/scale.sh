#!/usr/bin/env bash
# The default scene (the paper's cuboid, top face touchable, every key at
# its default: representation = auto, max_error = 1e-3) at finer meshes:
# how far the every-mode dense eigensolve, split by the mesh's symmetries
# (docs/precompute.md), carries the default target.  Prints a Markdown
# table; the logs and images stay in out/scale/.
#   tools/scripts/scale.sh [IRDM] [RES ...]   (RES: NX,NY,NZ; default the
#   paper's 11,11,22 and 17,17,34)
set -euo pipefail
irdm=${1:-build/irdm}
shift || true
res=("$@")
[ ${#res[@]} -gt 0 ] || res=(11,11,22 17,17,34)
mkdir -p out/scale
echo "| resolution | mesh | free DoFs | eigensolve | representation | measured error | two contacts | precompute | CPU | peak memory | image |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for r in "${res[@]}"; do
	log=out/scale/cuboid-$r.log img=out/scale/cuboid-$r.img
	echo "scale: $r ..." >&2
	TIMEFORMAT='%U %S'
	{ time "$irdm" precompute --scene scenes/cuboid-top.scene --resolution "$r" -o "$img" \
		>"$log" 2>&1 || { tail -n 5 "$log" >&2; exit 1; }; } 2>out/scale/time-$r
	"$irdm" image verify --require-stable "$img" >>"$log"
	tr '\r' '\n' <"$log" | awk -v r="$r" -v cpu="$(awk '{ print $1 + $2 }' out/scale/time-$r)" \
	    -v bytes="$(stat -c %s "$img")" '
		/^mesh  / { mesh = $2 " nodes, " $4 " tets"; dofs = $6 }
		/^symmetry:/ { split($0, a, "splits into "); blocks = a[2] + 0 }
		/^representation auto:/ { sub(/^representation auto: /, ""); sub(/, the cheapest.*/, ""); repr = $0 }
		/^time / { total = $2; for (i = 3; i <= NF; i++) if ($i == "eigen") eig = $(i + 1) }
		/^memory / { peak = $3 }
		/^force error / { err = $3 }
		/^two contacts / { pairs = $3 }
		END {
			sub(/,$/, "", eig)
			printf "| %s | %s | %s | %s s, %s | %s | %s | %s | %s s | %.0f s | %s MiB | %.1f MB |\n",
			       r, mesh, dofs, eig, blocks ? blocks " blocks" : "whole", repr, err,
			       pairs == "" ? "-" : pairs, total, cpu, peak, bytes / 1e6 }'
done
