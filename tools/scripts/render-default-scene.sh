#!/usr/bin/env bash
# make render: the default scene's deformed surface, frame by frame.
#  - the paper's Fig. 6a step and a release: the top node next to the centre
#    (mesh node 3246) pushed 1 cm down in 10 ms, held 1 s, let go, 2 s more;
#    irdm render -> out/render-step/ (frames.pvd for ParaView, .vtu frames,
#    frames.csv, forces.csv), a film of PNGs (out/render-step-png/), a strip
#    (press, hold, just after the release, ringing) and the force plot;
#  - if make run left its controller log (out/run.log), that run rendered
#    from the log on its board -> out/render-run/ and its force plot.
#   tools/scripts/render-default-scene.sh [IRDM]
set -euo pipefail
irdm=${1:-build/irdm}
py=/usr/bin/python3
tools/scripts/default-image.sh "$irdm"
awk 'BEGIN { print "t,ux,uy,uz"; for (i = 0; i < 3000; i++)
	if (i < 1000) printf "%.3f,0,0,%s\n", i * 0.001, (i < 10 ? -0.001 * (i + 1) : -0.01);
	else printf "%.3f,,,\n", i * 0.001 }' > out/render-step.csv
"$irdm" render --image out/default.img --contact 3246 --displacement out/render-step.csv \
	-o out/render-step --every 0.05 --nodes 3246
if [ -f out/run.log ]; then
	"$irdm" render --image out/default.img --log out/run.log --board boards/sim-phantom.board \
		-o out/render-run --every 0.1
fi
if ! $py -c 'import matplotlib' 2>/dev/null; then
	echo "render: python3-matplotlib not installed; skipped the PNGs"
	exit 0
fi
$py tools/scripts/plot-surface.py out/render-step/frames.pvd --each out/render-step-png --step=2 \
	"paper's cuboid: 1 cm step at the top, released at 1 s"
# 0.5 s: held; 1.05, 1.2, 1.35 s: ringing after the release
$py tools/scripts/plot-surface.py out/render-step/frame_000{09,20,23,26}.vtu out/render-step.png \
	"paper's cuboid: held, then ringing after the release at 1 s"
$py tools/scripts/plot-forces.py out/render-step/forces.csv out/render-step-forces.png \
	"paper's cuboid: top node pushed 1 cm in 10 ms, held 1 s, released (Fig. 6a)"
if [ -d out/render-run ]; then
	$py tools/scripts/plot-forces.py out/render-run/forces.csv out/render-run-forces.png \
		"irdm-fw run replayed from its log: press the top centre, hold, release"
fi
echo "render: out/render-step/frames.pvd (ParaView), out/render-step-png/, out/render-step.png, out/render-step-forces.png"
