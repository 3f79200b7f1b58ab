// SPDX-License-Identifier: MIT
/*
 * Mesh basics: freeing, volume, provenance hash, and irdm_mesh_read(),
 * which picks a reader by file extension.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh/mesh_priv.h"
#include "util/fnv1a.h"

void irdm_mesh_free(struct irdm_mesh *m)
{
	if (!m)
		return;
	free(m->pos_m);
	free(m->tets);
	free(m->tris);
	memset(m, 0, sizeof(*m));
}

void irdm_surface_free(struct irdm_surface *s)
{
	if (!s)
		return;
	free(s->pos_m);
	free(s->tris);
	memset(s, 0, sizeof(*s));
}

double irdm_mesh_volume(const struct irdm_mesh *m)
{
	const double *x = m->pos_m;
	double sum = 0.0;
	size_t e;

	for (e = 0; e < m->n_tets; e++) {
		const uint32_t *t = m->tets + 4 * e;
		const double *a = x + 3 * t[0], *b = x + 3 * t[1];
		const double *c = x + 3 * t[2], *d = x + 3 * t[3];
		double u[3], v[3], w[3];
		int i;

		for (i = 0; i < 3; i++) {
			u[i] = b[i] - a[i];
			v[i] = c[i] - a[i];
			w[i] = d[i] - a[i];
		}
		sum += (u[1] * v[2] - u[2] * v[1]) * w[0] +
		       (u[2] * v[0] - u[0] * v[2]) * w[1] +
		       (u[0] * v[1] - u[1] * v[0]) * w[2];
	}
	return sum / 6.0;
}

uint64_t irdm_mesh_hash(const struct irdm_mesh *m)
{
	uint64_t h = IRDM_FNV1A_INIT;

	if (m->pos_m)
		h = irdm_fnv1a(h, m->pos_m, 3 * m->n_nodes * sizeof(*m->pos_m));
	if (m->tets)
		h = irdm_fnv1a(h, m->tets, 4 * m->n_tets * sizeof(*m->tets));
	return h;
}

/* Case-insensitive "does path end in ext" (".STL" is common). */
static int has_ext(const char *path, const char *ext)
{
	size_t n = strlen(path), k = strlen(ext), i;

	if (n <= k)
		return 0;
	path += n - k;
	for (i = 0; i < k; i++) {
		char c = path[i];

		if (c >= 'A' && c <= 'Z')
			c = (char)(c - 'A' + 'a');
		if (c != ext[i])
			return 0;
	}
	return 1;
}

static void scale_positions(double *x, size_t n, double scale)
{
	size_t i;

	if (scale == 1.0)
		return;
	for (i = 0; i < n; i++)
		x[i] *= scale;
}

/* foo.node or foo.ele: both files, named after the one they describe. */
static int read_tetgen(const char *path, double scale, struct irdm_mesh *m,
		       char *err, size_t errlen)
{
	struct mesh_labels lab = { NULL, NULL, NULL, NULL };
	char *node_path = NULL, *ele_path = NULL;
	char *node_txt = NULL, *ele_txt = NULL;
	size_t stem, node_len, ele_len;
	int ret = -1;

	stem = strlen(path) - (has_ext(path, ".node") ? 5 : 4);
	node_path = malloc(stem + 6);
	ele_path = malloc(stem + 5);
	if (!node_path || !ele_path) {
		mesh_err(err, errlen, path, "out of memory");
		goto out_free;
	}
	memcpy(node_path, path, stem);
	memcpy(node_path + stem, ".node", 6);
	memcpy(ele_path, path, stem);
	memcpy(ele_path + stem, ".ele", 5);
	if (mesh_read_file(node_path, &node_txt, &node_len, err, errlen) ||
	    mesh_read_file(ele_path, &ele_txt, &ele_len, err, errlen))
		goto out_free;
	lab.node_what = node_path;
	lab.tet_what = ele_path;
	if (mesh_parse_tetgen_labeled(node_txt, node_len, ele_txt, ele_len, m,
				      &lab, err, errlen))
		goto out_free;
	scale_positions(m->pos_m, 3 * m->n_nodes, scale);
	ret = mesh_finish_labeled(m, &lab, err, errlen);

out_free:
	mesh_labels_free(&lab);
	free(ele_txt);
	free(node_txt);
	free(ele_path);
	free(node_path);
	return ret;
}

static int read_gmsh(const char *path, double scale, struct irdm_mesh *m,
		     char *err, size_t errlen)
{
	struct mesh_labels lab = { path, path, NULL, NULL };
	char *txt;
	size_t len;
	int ret = -1;

	if (mesh_read_file(path, &txt, &len, err, errlen))
		return -1;
	if (mesh_parse_gmsh_labeled(txt, len, path, m, &lab, err, errlen))
		goto out_free;
	scale_positions(m->pos_m, 3 * m->n_nodes, scale);
	ret = mesh_finish_labeled(m, &lab, err, errlen);

out_free:
	mesh_labels_free(&lab);
	free(txt);
	return ret;
}

/*
 * Surfaces are tetrahedralised in their own units, so size switches such
 * as "a0.5" mean what the author of the file would expect; the scale is
 * applied afterwards and the mesh checked again.
 */
static int read_surface(const char *path, double scale, const char *switches,
			struct irdm_mesh *m, char *err, size_t errlen)
{
	struct irdm_surface s = { 0, NULL, 0, NULL };
	char *txt;
	size_t len;
	int ret = -1;

	if (mesh_read_file(path, &txt, &len, err, errlen))
		return -1;
	if (has_ext(path, ".obj"))
		ret = irdm_surface_parse_obj(txt, len, path, &s, err, errlen);
	else if (has_ext(path, ".off"))
		ret = irdm_surface_parse_off(txt, len, path, &s, err, errlen);
	else
		ret = irdm_surface_parse_stl(txt, len, path, &s, err, errlen);
	free(txt);
	if (ret)
		return -1;
	ret = irdm_surface_tetrahedralize(&s, switches, path, m, err, errlen);
	irdm_surface_free(&s);
	if (ret || scale == 1.0)
		return ret;
	scale_positions(m->pos_m, 3 * m->n_nodes, scale);
	return irdm_mesh_finish(m, path, err, errlen);
}

int irdm_mesh_read(const char *path, double scale, const char *tetgen_switches,
		   struct irdm_mesh *m, char *err, size_t errlen)
{
	int ret;

	memset(m, 0, sizeof(*m));
	if (!path || !*path) {
		mesh_err(err, errlen, "mesh", "no file name given");
		return -1;
	}
	if (!isfinite(scale) || scale <= 0.0) {
		mesh_err(err, errlen, path, "scale %g is not a positive number", scale);
		return -1;
	}
	if (has_ext(path, ".node") || has_ext(path, ".ele")) {
		ret = read_tetgen(path, scale, m, err, errlen);
	} else if (has_ext(path, ".msh")) {
		ret = read_gmsh(path, scale, m, err, errlen);
	} else if (has_ext(path, ".obj") || has_ext(path, ".off") ||
		   has_ext(path, ".stl")) {
		ret = read_surface(path, scale, tetgen_switches, m, err, errlen);
	} else {
		mesh_err(err, errlen, path,
			 "unknown mesh format (expected .node, .ele, .msh, .obj, .off or .stl)");
		return -1;
	}
	if (ret) {
		irdm_mesh_free(m);
		return -1;
	}
	mesh_set_name(m, path);
	return 0;
}
