/* SPDX-License-Identifier: MIT */
/* The torus as OFF (torus.h). */
#include <math.h>
#include <stdio.h>

#include "torus.h"

int torus_write_off(const char *path, unsigned nu, unsigned nv)
{
	FILE *f = fopen(path, "w");

	if (!f)
		return -1;
	fprintf(f, "OFF\n%u %u 0\n", nu * nv, 2 * nu * nv);
	for (unsigned i = 0; i < nu; i++)
		for (unsigned j = 0; j < nv; j++) {
			double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv;
			fprintf(f, "%.17g %.17g %.17g\n", (1 + 0.4 * cos(b)) * cos(a),
				(1 + 0.4 * cos(b)) * sin(a), 0.4 * sin(b));
		}
	for (unsigned i = 0; i < nu; i++)
		for (unsigned j = 0; j < nv; j++) {
			unsigned a = i * nv + j, b = ((i + 1) % nu) * nv + j;
			unsigned c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
			fprintf(f, "3 %u %u %u\n3 %u %u %u\n", a, b, c, a, c, d);
		}
	return fclose(f) ? -1 : 0;
}

#define SEAM_SHIFT 1e-9 /* a seam copy's offset, of the ring radius */

int torus_write_off_seams(const char *path, unsigned nu, unsigned nv)
{
	FILE *f = fopen(path, "w");
	unsigned w = nv + 1;

	if (!f)
		return -1;
	fprintf(f, "OFF\n%u %u 0\n", (nu + 1) * w, 2 * nu * nv);
	for (unsigned i = 0; i <= nu; i++)
		for (unsigned j = 0; j <= nv; j++) {
			double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv;
			double e = (i == nu || j == nv) ? SEAM_SHIFT : 0;
			fprintf(f, "%.17g %.17g %.17g\n", (1 + 0.4 * cos(b)) * cos(a) + e,
				(1 + 0.4 * cos(b)) * sin(a) - e, 0.4 * sin(b) + e);
		}
	for (unsigned i = 0; i < nu; i++)
		for (unsigned j = 0; j < nv; j++) {
			unsigned a = i * w + j, b = (i + 1) * w + j, c = (i + 1) * w + j + 1;
			unsigned d = i * w + j + 1;
			fprintf(f, "3 %u %u %u\n3 %u %u %u\n", a, b, c, a, c, d);
		}
	return fclose(f) ? -1 : 0;
}
