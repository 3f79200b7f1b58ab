#!/usr/bin/env bash
# Precompute benchmark: paper-scale scenes end to end (precompute + verify),
# wall time, peak memory and image size beside the paper's Table 1 (the
# torus has no paper figures).  Prints a Markdown table and
# keeps the logs in out/bench/.
#   tools/scripts/bench-precompute.sh [IRDM]
set -euo pipefail
irdm=${1:-build/irdm}
mkdir -p out/bench build/data
[ -s build/data/torus.off ] || tools/scripts/torus-off.sh 65 33 > build/data/torus.off
row() {  # scene paper_hours paper_gb ("-": none)
	local scene=$1 log=out/bench/$1.log img=out/bench/$1.img t0 t1
	t0=$(date +%s.%N)
	"$irdm" precompute --scene "scenes/$scene.scene" --max_error none -o "$img" >"$log" 2>&1 || { cat "$log"; exit 1; }
	t1=$(date +%s.%N)
	"$irdm" image verify "$img" >>"$log"
	local secs bytes mesh cols peak
	secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }')
	bytes=$(stat -c %s "$img")
	mesh=$(sed -n 's/^mesh *\([0-9]*\) nodes, \([0-9]*\) tets.*/\1 nodes, \2 tets/p' "$log")
	cols=$(sed -n 's/^image nodes.* \([0-9]*\) touchable columns.*/\1/p' "$log")
	peak=$(sed -n 's/^memory *peak \([0-9.]*\) MiB.*/\1/p' "$log")
	awk -v s="$scene" -v m="$mesh" -v c="$cols" -v t="$secs" -v b="$bytes" -v p="$peak" \
	    -v ph="$2" -v pg="$3" 'BEGIN {
		vs = ph == "-" ? "-" : sprintf("%.0fx faster, %.2f %% of the size", ph * 3600 / t, 100 * b / (pg * 1e9))
		printf "| %s | %s | %s | %.0f s | %.0f MiB | %.1f MB | %s h | %s GB | %s |\n",
		       s, m, c, t, p, b / 1e6, ph, pg, vs }'
}
echo "| scene | mesh | touchable | precompute | peak memory | image | paper time | paper size | vs paper |"
echo "|---|---|---|---|---|---|---|---|---|"
row cuboid-paper 508.7 38.2
row bunny 126.2 22.8
row torus - -
