/* SPDX-License-Identifier: MIT */
/*
 * What the image holds: columns are the free surface nodes in the touch
 * region; rows are the columns, the displayed surface nodes, and every
 * vertex of a touchable triangle (so a contact on it can be rendered); the
 * surface is every boundary triangle whose vertices are all rows.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "precompute/model.h"

static int node_dofs(const struct irdm_model *m, uint32_t node, int64_t *dofs)
{
	for (int a = 0; a < 3; a++)
		dofs[a] = m->fem.map.free_of[3 * (size_t)node + (size_t)a];
	return 0;
}

/* Does the display region hold a surface node (a region that holds none
 * would be silently ignored: the image would show the touch region only)? */
static bool selects_surface(const struct irdm_scene *sc, const struct irdm_model *m)
{
	for (size_t i = 0; i < m->mesh.n_nodes; i++)
		if (m->on_surface[i] &&
		    irdm_region_contains(&sc->display, (uint32_t)i, &m->mesh.pos_m[3 * i], true))
			return true;
	return false;
}

int irdm_model_select(const struct irdm_scene *sc, struct irdm_model *m, char *err, size_t errlen)
{
	size_t n = m->mesh.n_nodes;
	bool *touch = calloc(n, sizeof(bool)), *row = calloc(n, sizeof(bool));
	int64_t *image_of = malloc(n * sizeof(int64_t));
	int ret = IRDM_EINVAL;

	if (!touch || !row || !image_of)
		goto out_nomem;
	for (size_t i = 0; i < n; i++) {
		const double *p = &m->mesh.pos_m[3 * i];
		touch[i] = m->on_surface[i] && !m->fixed[i] &&
			   irdm_region_contains(&sc->touch, (uint32_t)i, p, true);
		row[i] = touch[i] || (m->on_surface[i] &&
				      irdm_region_contains(&sc->display, (uint32_t)i, p, true));
	}
	/* vertices of triangles that have a touchable vertex */
	for (size_t t = 0; t < m->mesh.n_tris; t++) {
		const uint32_t *v = &m->mesh.tris[3 * t];
		if (touch[v[0]] || touch[v[1]] || touch[v[2]])
			row[v[0]] = row[v[1]] = row[v[2]] = true;
	}
	for (size_t i = 0; i < n; i++) {
		image_of[i] = row[i] ? (int64_t)m->n_rows++ : -1;
		m->n_cols += touch[i];
	}
	if (m->n_cols == 0) {
		snprintf(err, errlen, "scene: 'touch = %s' selects no free surface node", sc->touch.text);
		goto out_free;
	}
	if (sc->display.kind != IRDM_REGION_NONE && !selects_surface(sc, m)) {
		snprintf(err, errlen, "scene: 'display = %s' selects no surface node", sc->display.text);
		goto out_free;
	}
	m->rows = malloc(m->n_rows * sizeof(uint32_t));
	m->cols = malloc(m->n_cols * sizeof(uint32_t));
	m->row_dofs = malloc(3 * m->n_rows * sizeof(int64_t));
	m->col_dofs = malloc(3 * m->n_cols * sizeof(int64_t));
	m->tris = malloc(3 * (m->mesh.n_tris ? m->mesh.n_tris : 1) * sizeof(uint32_t));
	if (!m->rows || !m->cols || !m->row_dofs || !m->col_dofs || !m->tris)
		goto out_nomem;
	for (size_t i = 0, c = 0; i < n; i++) {
		if (!row[i])
			continue;
		size_t r = (size_t)image_of[i];
		m->rows[r] = (uint32_t)i;
		node_dofs(m, (uint32_t)i, &m->row_dofs[3 * r]);
		if (touch[i]) {
			m->cols[c] = (uint32_t)r;
			node_dofs(m, (uint32_t)i, &m->col_dofs[3 * c]);
			c++;
		}
	}
	for (size_t t = 0; t < m->mesh.n_tris; t++) {
		const uint32_t *v = &m->mesh.tris[3 * t];
		if (!row[v[0]] || !row[v[1]] || !row[v[2]])
			continue;
		for (int k = 0; k < 3; k++)
			m->tris[3 * m->n_tris + (size_t)k] = (uint32_t)image_of[v[k]];
		m->n_tris++;
	}
	ret = IRDM_OK;
	goto out_free;
out_nomem:
	snprintf(err, errlen, "selection: out of memory");
	ret = IRDM_ENOMEM;
out_free:
	free(touch);
	free(row);
	free(image_of);
	return ret;
}
