#!/usr/bin/env bash
# make run's press, held against the exact model: the controller's run on
# the default image (out/run.log, out/default.img, written by make run) is
# replayed by the force engine on that image (which irdm replay reproduces
# bit for bit) and on an all-modes double-precision image of the same scene
# (every elastic mode, no static correction: the exact linear model),
# along the same recorded contact sites and targets.  The figure is the
# relative RMS difference of the force on the object over the ticks in
# contact, and over the first 10 of them alone.
#   tools/scripts/run-vs-exact.sh [IRDM]   (after make run)   Markdown on stdout
set -euo pipefail
irdm=${1:-build/irdm}
board=boards/sim-phantom.board
for f in out/default.img out/run.log; do
	[ -f "$f" ] || { echo "run-vs-exact: needs $f: make run first" >&2; exit 1; }
done
key="$(sha256sum scenes/cuboid-top.scene | cut -c1-16) $("$irdm" --version) $(sha256sum "$irdm" | cut -c1-16) exact"
if [ -f out/exact.img ] && [ "$(cat out/exact.img.key 2>/dev/null)" = "$key" ]; then
	echo "out/exact.img is up to date: precompute skipped" >&2
else
	rm -f out/exact.img.key
	"$irdm" precompute -q --scene scenes/cuboid-top.scene --representation modal:all \
		--static_correction no --precision f64 --max_error none -o out/exact.img >&2
	echo "$key" > out/exact.img.key
fi
"$irdm" replay --image out/default.img --log out/run.log --board "$board" -o out/run-default.csv >&2
"$irdm" replay --image out/exact.img --log out/run.log --board "$board" -o out/run-exact.csv >&2

# Columns 2..4: contact 0's force on the object.  A row is in contact when
# either run has a non-zero force there.
paste -d, out/run-default.csv out/run-exact.csv | awk -F, -v n="$(head -n 1 out/run-default.csv | awk -F, '{ print NF }')" '
NR == 1 { next }
{
	a2 = 0; d2 = 0; contact = 0
	for (i = 2; i <= 4; i++) {
		x = $i; y = $(i + n)
		if (x != 0 || y != 0) contact = 1
		d2 += (x - y) ^ 2; a2 += y ^ 2
	}
	if (!contact) next
	k++; D += d2; A += a2
	if (k <= 10) { D10 += d2; A10 += a2 }
	if (a2 > peak) peak = a2
}
END {
	if (k == 0 || A == 0) { print "run-vs-exact: no tick in contact" > "/dev/stderr"; exit 1 }
	printf "make run (scenes/cuboid-top.scene, boards/sim-phantom.board, scenes/users/press-hold-release.user) replayed on\n"
	printf "its own image and on the all-modes f64 image of the same scene, along the run'\''s contact sites and targets:\n\n"
	printf "| ticks in contact | force peak (exact) | relative RMS force difference | over the first 10 contact ticks |\n"
	printf "|---|---|---|---|\n"
	printf "| %d | %.4f N | %.3g | %.3g |\n", k, sqrt(peak), sqrt(D / A), (A10 > 0 ? sqrt(D10 / A10) : 0)
}'
echo
echo "The default image, as \`irdm image info out/default.img\` gives it:"
echo
echo '```'
"$irdm" image info out/default.img | grep -E '^(responses|exact head|force error|image )'
echo '```'
