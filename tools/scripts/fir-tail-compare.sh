#!/bin/sh
# The FIR tail window against the engine's r^s damping, on the paper's
# setting at 4x4x8 cells (FIR T = 500 from all modes, 2 ms): the top-centre
# node pushed 1 cm and held 12 s, each image replayed, against the
# all-modes modal image.  Writes out/fir-tail/{exact,rs,window}.csv and
# out/fir-tail/forces.png.  The same figures are asserted by test_fir_tail.
# usage: tools/scripts/fir-tail-compare.sh [IRDM]
set -eu
irdm=${1:-build/irdm}
out=out/fir-tail
mkdir -p "$out"
# the bare FIR is uncertified and all three are compared here, not refused
common="--resolution 4,4,8 --dt 0.002 --precision f64 --display touch --uncertified yes --max_error none"
top="box:0.035,0.035,0.199,0.065,0.065,0.201"       # the top-centre node
# shellcheck disable=SC2086
$irdm precompute $common --representation modal:all --touch "$top" -o "$out/exact.img"
# shellcheck disable=SC2086
$irdm precompute $common --representation fir:500 --modes all --touch "$top" -o "$out/rs.img"
# shellcheck disable=SC2086
$irdm precompute $common --representation fir:500 --modes all --fir_tail window:1000 \
	--touch "$top" -o "$out/window.img"
awk 'BEGIN { print "t,ux,uy,uz"; for (i = 0; i < 6000; i++) printf "%.3f,0,0,-0.01\n", i * 0.002 }' \
	> "$out/hold.csv"
for k in exact rs window; do
	# the image's one column: the mesh node the box selected
	node=$($irdm image info "$out/$k.img" | sed -n 's/^columns (mesh nodes): //p')
	$irdm replay --image "$out/$k.img" --contact "$node" --displacement "$out/hold.csv" \
		-o "$out/$k.csv"
done
/usr/bin/python3 tools/scripts/plot-fir-tail.py "$out" "$out/forces.png"
