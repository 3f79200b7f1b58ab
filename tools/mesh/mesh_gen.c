// SPDX-License-Identifier: MIT
/*
 * Built-in box meshes.  Nodes sit on a regular grid, node (i, j, k) at
 * index i + (nx+1) * (j + (ny+1) * k).  A hex's corner b (bit 0 = +x,
 * bit 1 = +y, bit 2 = +z) is split into
 *  - 6 tets (Kuhn/Freudenthal): one per path from corner 0 to corner 7
 *    along the axes; every face is cut along the diagonal through its
 *    lowest corner, the same in both neighbours, so the mesh conforms;
 *  - 5 tets: a central tet on the four corners of one parity and four
 *    corner tets; hexes with odd i+j+k use the mirror image, which puts
 *    the face diagonals of neighbours on the same corners.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

static const unsigned char kuhn[6][4] = {
	{ 0, 1, 3, 7 },
	{ 0, 1, 5, 7 },
	{ 0, 2, 3, 7 },
	{ 0, 2, 6, 7 },
	{ 0, 4, 5, 7 },
	{ 0, 4, 6, 7 },
};

/* For even hexes; odd hexes use corner ^ 1 (mirror in x). */
static const unsigned char five[5][4] = {
	{ 0, 3, 5, 6 }, /* central: the even corners */
	{ 1, 0, 3, 5 },
	{ 2, 3, 0, 6 },
	{ 4, 5, 6, 0 },
	{ 7, 6, 5, 3 },
};

/*
 * Sign of the unit-cube tet on corners c; scaling the axes by positive
 * spacings keeps it.
 */
static int corner_orientation(const unsigned char c[4])
{
	double p[4][3], u[3], v[3], w[3];
	int i, k;

	for (i = 0; i < 4; i++)
		for (k = 0; k < 3; k++)
			p[i][k] = (c[i] >> k) & 1;
	for (k = 0; k < 3; k++) {
		u[k] = p[1][k] - p[0][k];
		v[k] = p[2][k] - p[0][k];
		w[k] = p[3][k] - p[0][k];
	}
	return (u[1] * v[2] - u[2] * v[1]) * w[0] +
				       (u[2] * v[0] - u[0] * v[2]) * w[1] +
				       (u[0] * v[1] - u[1] * v[0]) * w[2] >
			       0 ?
		       1 :
		       -1;
}

/* Local tets for a hex of the given parity, each positively oriented. */
static void build_pattern(unsigned tets_per_hex, unsigned odd,
			  unsigned char pat[6][4])
{
	unsigned t, i;

	for (t = 0; t < tets_per_hex; t++) {
		for (i = 0; i < 4; i++)
			pat[t][i] = tets_per_hex == 6 ? kuhn[t][i] :
							(unsigned char)(five[t][i] ^ odd);
		if (corner_orientation(pat[t]) < 0) {
			unsigned char c = pat[t][2];

			pat[t][2] = pat[t][3];
			pat[t][3] = c;
		}
	}
}

static int check_args(double lx, double ly, double lz, unsigned nx,
		      unsigned ny, unsigned nz, unsigned tph, size_t *nodes,
		      size_t *tets, char *err, size_t errlen)
{
	unsigned long long nn, nt;

	if (!(isfinite(lx) && isfinite(ly) && isfinite(lz) &&
	      lx > 0 && ly > 0 && lz > 0)) {
		mesh_err(err, errlen, "box", "sizes must be positive (%g x %g x %g m)",
			 lx, ly, lz);
		return IRDM_EINVAL;
	}
	if (!nx || !ny || !nz || (tph != 5 && tph != 6)) {
		mesh_err(err, errlen, "box",
			 "need at least 1x1x1 hexes and 5 or 6 tets per hex (got %ux%ux%u, %u)",
			 nx, ny, nz, tph);
		return IRDM_EINVAL;
	}
	/* Each factor is checked before the next multiply, so nothing wraps. */
	nn = (unsigned long long)nx + 1;
	nn = nn > MESH_MAX_ITEMS ? nn : nn * ((unsigned long long)ny + 1);
	nn = nn > MESH_MAX_ITEMS ? nn : nn * ((unsigned long long)nz + 1);
	nt = (unsigned long long)nx * ny;
	nt = nt > MESH_MAX_ITEMS ? nt : nt * nz;
	nt = nt > MESH_MAX_ITEMS ? nt : nt * tph;
	if (nn > MESH_MAX_ITEMS || nt > MESH_MAX_ITEMS) {
		mesh_err(err, errlen, "box", "%ux%ux%u hexes is too many (limit %u)",
			 nx, ny, nz, MESH_MAX_ITEMS);
		return IRDM_EINVAL;
	}
	*nodes = (size_t)nn;
	*tets = (size_t)nt;
	return 0;
}

static void fill_nodes(double *x, double lx, double ly, double lz, unsigned nx,
		       unsigned ny, unsigned nz)
{
	unsigned i, j, k;

	for (k = 0; k <= nz; k++)
		for (j = 0; j <= ny; j++)
			for (i = 0; i <= nx; i++) {
				/* lx * i / nx is exact at both ends */
				*x++ = lx * i / nx;
				*x++ = ly * j / ny;
				*x++ = lz * k / nz;
			}
}

static void fill_tets(uint32_t *t, unsigned nx, unsigned ny, unsigned nz,
		      unsigned tph)
{
	unsigned char pat[2][6][4];
	uint32_t sx = 1, sy = nx + 1, sz = (nx + 1) * (ny + 1), base, c[8];
	unsigned i, j, k, b, e, q;

	build_pattern(tph, 0, pat[0]);
	build_pattern(tph, 1, pat[1]);
	for (k = 0; k < nz; k++)
		for (j = 0; j < ny; j++)
			for (i = 0; i < nx; i++) {
				base = i * sx + j * sy + k * sz;
				for (b = 0; b < 8; b++)
					c[b] = base + (b & 1 ? sx : 0) +
					       (b & 2 ? sy : 0) + (b & 4 ? sz : 0);
				/* the Kuhn split needs no alternation */
				q = tph == 5 ? (i + j + k) & 1 : 0;
				for (e = 0; e < tph; e++) {
					*t++ = c[pat[q][e][0]];
					*t++ = c[pat[q][e][1]];
					*t++ = c[pat[q][e][2]];
					*t++ = c[pat[q][e][3]];
				}
			}
}

int irdm_mesh_gen_box(double lx, double ly, double lz, unsigned nx, unsigned ny,
		      unsigned nz, unsigned tets_per_hex, struct irdm_mesh *m,
		      char *err, size_t errlen)
{
	size_t nodes, tets;
	int ret;

	memset(m, 0, sizeof(*m));
	ret = check_args(lx, ly, lz, nx, ny, nz, tets_per_hex, &nodes, &tets,
			 err, errlen);
	if (ret)
		return ret;
	m->pos_m = malloc(nodes * 3 * sizeof(*m->pos_m));
	m->tets = malloc(tets * 4 * sizeof(*m->tets));
	if (!m->pos_m || !m->tets) {
		mesh_err(err, errlen, "box", "out of memory");
		irdm_mesh_free(m);
		return IRDM_ENOMEM;
	}
	m->n_nodes = nodes;
	m->n_tets = tets;
	fill_nodes(m->pos_m, lx, ly, lz, nx, ny, nz);
	fill_tets(m->tets, nx, ny, nz, tets_per_hex);
	ret = irdm_mesh_finish(m, "box", err, errlen);
	if (ret)
		return ret;
	snprintf(m->name, sizeof(m->name), "box-%ux%ux%u-%u", nx, ny, nz,
		 tets_per_hex);
	return IRDM_OK;
}
