/* SPDX-License-Identifier: MIT */
/* The CAD-like part (cad_part.h): each face of a box gridded densely in the
 * fillet bands, then every point pushed onto the rounded box. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cad_part.h"

#define FIL_N 3  /* segments across a fillet */
#define FLAT_N 3 /* and across a flat */
#define AXIS_N (2 * FIL_N + FLAT_N)

const double cad_part_half_mm[3] = { 30, 20, 8 };
static const double fillet_mm = 0.5;

/* Grid lines along an axis of half size h: dense in the fillet bands. */
static void grid(double h, double c[AXIS_N + 1])
{
	int k = 0;

	for (int i = 0; i < FIL_N; i++)
		c[k++] = -h + fillet_mm * i / FIL_N;
	for (int i = 0; i < FLAT_N; i++)
		c[k++] = -h + fillet_mm + (2 * h - 2 * fillet_mm) * i / FLAT_N;
	for (int i = 0; i < FIL_N; i++)
		c[k++] = h - fillet_mm + fillet_mm * i / FIL_N;
	c[k] = h;
}

/* A point q of the box's surface onto the rounded box: the inner box plus
 * the fillet radius along q's offset from it. */
static void round_point(const double q[3], float out[3])
{
	double in[3], d[3], len = 0;

	for (int a = 0; a < 3; a++) {
		double lim = cad_part_half_mm[a] - fillet_mm;
		in[a] = q[a] < -lim ? -lim : q[a] > lim ? lim :
							  q[a];
		d[a] = q[a] - in[a];
		len += d[a] * d[a];
	}
	len = sqrt(len);
	for (int a = 0; a < 3; a++)
		out[a] = (float)(in[a] + fillet_mm * d[a] / len);
}

static void put_tri(FILE *f, float v[4][3], int i, int j, int k)
{
	float rec[12] = { 0, 0, 0 };
	uint16_t attr = 0;

	memcpy(&rec[3], v[i], sizeof(v[i]));
	memcpy(&rec[6], v[j], sizeof(v[j]));
	memcpy(&rec[9], v[k], sizeof(v[k]));
	fwrite(rec, sizeof(rec), 1, f); /* little-endian host, as STL */
	fwrite(&attr, sizeof(attr), 1, f);
}

/* Each face of the box gridded and rounded, outward; binary STL. */
int cad_part_write_stl(const char *path, const char *header_text)
{
	double c[3][AXIS_N + 1];
	char header[80] = { 0 };
	uint32_t n = 6 * 2 * AXIS_N * AXIS_N;
	FILE *f = fopen(path, "wb");

	if (!f)
		return -1;
	memcpy(header, header_text, strnlen(header_text, sizeof(header)));
	for (int a = 0; a < 3; a++)
		grid(cad_part_half_mm[a], c[a]);
	fwrite(header, sizeof(header), 1, f);
	fwrite(&n, sizeof(n), 1, f);
	for (int ax = 0; ax < 3; ax++)
		for (int sg = -1; sg <= 1; sg += 2) {
			int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
			for (int i = 0; i < AXIS_N; i++)
				for (int j = 0; j < AXIS_N; j++) {
					float v[4][3];
					int di[4] = { 0, 1, 1, 0 }, dj[4] = { 0, 0, 1, 1 };
					for (int k = 0; k < 4; k++) {
						double q[3];
						q[ax] = sg * cad_part_half_mm[ax];
						q[a1] = c[a1][i + di[k]];
						q[a2] = c[a2][j + dj[k]];
						round_point(q, v[k]);
					}
					if (sg > 0) {
						put_tri(f, v, 0, 1, 2);
						put_tri(f, v, 0, 2, 3);
					} else {
						put_tri(f, v, 2, 1, 0);
						put_tri(f, v, 3, 2, 0);
					}
				}
		}
	return fclose(f);
}
