// SPDX-License-Identifier: MIT
/*
 * irdm_mesh_read(): the dispatcher, which picks a reader by file extension.
 * It sits above the readers; what they share (text scanning, the file
 * loader, labels, freeing) lives below them in mesh_text.c, mesh_finish.c
 * and mesh_base.c, so no reader calls back into this file.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

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

/* A parsed volume mesh in file units to metres, then checked. */
static int scale_and_finish(struct irdm_mesh *m, const struct mesh_labels *lab, double scale,
			    char *err, size_t errlen)
{
	scale_positions(m->pos_m, 3 * m->n_nodes, scale);
	return mesh_finish_labeled(m, lab, err, errlen);
}

/* foo.node or foo.ele: both files, named after the one they describe. */
static int read_tetgen(const char *path, double scale, struct irdm_mesh *m,
		       char *err, size_t errlen)
{
	struct mesh_labels lab = { NULL, NULL, NULL, NULL };
	char *node_path = NULL, *ele_path = NULL;
	char *node_txt = NULL, *ele_txt = NULL;
	size_t stem, node_len, ele_len;
	int ret;

	stem = strlen(path) - (has_ext(path, ".node") ? 5 : 4);
	node_path = malloc(stem + 6);
	ele_path = malloc(stem + 5);
	if (!node_path || !ele_path) {
		mesh_err(err, errlen, path, "out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	memcpy(node_path, path, stem);
	memcpy(node_path + stem, ".node", 6);
	memcpy(ele_path, path, stem);
	memcpy(ele_path + stem, ".ele", 5);
	ret = mesh_read_file(node_path, &node_txt, &node_len, err, errlen);
	if (!ret)
		ret = mesh_read_file(ele_path, &ele_txt, &ele_len, err, errlen);
	if (ret)
		goto out_free;
	lab.node_what = node_path;
	lab.tet_what = ele_path;
	ret = mesh_parse_tetgen_labeled(node_txt, node_len, ele_txt, ele_len, m,
					&lab, err, errlen);
	if (!ret)
		ret = scale_and_finish(m, &lab, scale, err, errlen);

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
	int ret;

	ret = mesh_read_file(path, &txt, &len, err, errlen);
	if (ret)
		return ret;
	ret = mesh_parse_gmsh_labeled(txt, len, path, m, &lab, err, errlen);
	if (!ret)
		ret = scale_and_finish(m, &lab, scale, err, errlen);
	mesh_labels_free(&lab);
	free(txt);
	return ret;
}

/* The weld goes into the sizing's note, after what the sizing did. */
static void say_welded(struct irdm_mesh_sizing *sz, size_t welded, double tol)
{
	size_t n = strlen(sz->note);

	snprintf(sz->note + n, sizeof(sz->note) - n,
		 "%swelded %zu vertices (within %.3g, 1e-9 of the bounding box, of another)",
		 n ? "; " : "mesh: ", welded, tol);
}

/*
 * Surfaces are tetrahedralised in their own units, so size switches such
 * as "a0.5" mean what the author of the file would expect; the scale is
 * applied afterwards and the mesh checked again.
 */
static int read_surface(const char *path, double scale, struct irdm_mesh_sizing *sz,
			struct irdm_mesh *m, char *err, size_t errlen)
{
	struct irdm_surface s = { 0, NULL, 0, NULL };
	char *txt;
	size_t len, welded = 0;
	double tol = 0;
	int ret;

	ret = mesh_read_file(path, &txt, &len, err, errlen);
	if (ret)
		return ret;
	if (has_ext(path, ".obj"))
		ret = irdm_surface_parse_obj(txt, len, path, &s, err, errlen);
	else if (has_ext(path, ".off"))
		ret = irdm_surface_parse_off(txt, len, path, &s, err, errlen);
	else
		ret = irdm_surface_parse_stl(txt, len, path, &s, err, errlen);
	free(txt);
	if (!ret)
		ret = surface_weld(&s, &welded, &tol);
	if (ret) {
		if (ret == IRDM_ENOMEM)
			mesh_err(err, errlen, path, "out of memory");
		irdm_surface_free(&s);
		return ret;
	}
	ret = irdm_surface_tetrahedralize_sized(&s, sz, path, m, err, errlen);
	irdm_surface_free(&s);
	if (!ret && welded)
		say_welded(sz, welded, tol);
	if (ret || scale == 1.0)
		return ret;
	scale_positions(m->pos_m, 3 * m->n_nodes, scale);
	return irdm_mesh_finish(m, path, err, errlen);
}

int irdm_mesh_read(const char *path, double scale, const char *tetgen_switches,
		   struct irdm_mesh *m, char *err, size_t errlen)
{
	struct irdm_mesh_sizing sz = { tetgen_switches, 0, 0, "" };

	return irdm_mesh_read_sized(path, scale, &sz, m, err, errlen);
}

int irdm_mesh_read_sized(const char *path, double scale, struct irdm_mesh_sizing *sz,
			 struct irdm_mesh *m, char *err, size_t errlen)
{
	int ret;

	memset(m, 0, sizeof(*m));
	if (!path || !*path) {
		mesh_err(err, errlen, "mesh", "no file name given");
		return IRDM_EINVAL;
	}
	if (!isfinite(scale) || scale <= 0.0) {
		mesh_err(err, errlen, path, "scale %g is not a positive number", scale);
		return IRDM_EINVAL;
	}
	if (has_ext(path, ".node") || has_ext(path, ".ele")) {
		ret = read_tetgen(path, scale, m, err, errlen);
	} else if (has_ext(path, ".msh")) {
		ret = read_gmsh(path, scale, m, err, errlen);
	} else if (has_ext(path, ".obj") || has_ext(path, ".off") ||
		   has_ext(path, ".stl")) {
		struct irdm_mesh_sizing file_sz = *sz;
		file_sz.max_tet_volume = sz->max_tet_volume / (scale * scale * scale);
		ret = read_surface(path, scale, &file_sz, m, err, errlen);
		memcpy(sz->note, file_sz.note, sizeof(sz->note));
	} else {
		mesh_err(err, errlen, path,
			 "unknown mesh format (expected .node, .ele, .msh, .obj, .off or .stl)");
		return IRDM_EFORMAT;
	}
	if (ret) {
		irdm_mesh_free(m);
		return ret;
	}
	mesh_set_name(m, path);
	return IRDM_OK;
}
