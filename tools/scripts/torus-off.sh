#!/usr/bin/env bash
# A torus surface as OFF: ring radius 1, tube radius 0.4, NU x NV vertices,
# two outward triangles per quad (a closed surface: 65 x 33
# is 2,145 vertices, about 2,500 touchable nodes after tetgen).
#   tools/scripts/torus-off.sh NU NV > torus.off
set -euo pipefail
awk -v nu="${1:?NU}" -v nv="${2:?NV}" 'BEGIN {
	pi = atan2(0, -1)
	print "OFF"; print nu * nv, 2 * nu * nv, 0
	for (i = 0; i < nu; i++)
		for (j = 0; j < nv; j++) {
			a = 2 * pi * i / nu; b = 2 * pi * j / nv
			printf "%.17g %.17g %.17g\n", (1 + 0.4 * cos(b)) * cos(a),
			       (1 + 0.4 * cos(b)) * sin(a), 0.4 * sin(b)
		}
	for (i = 0; i < nu; i++)
		for (j = 0; j < nv; j++) {
			a = i * nv + j; b = ((i + 1) % nu) * nv + j
			c = ((i + 1) % nu) * nv + (j + 1) % nv; d = i * nv + (j + 1) % nv
			print 3, a, b, c; print 3, a, c, d
		}
}'
