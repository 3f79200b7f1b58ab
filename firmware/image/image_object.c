/* SPDX-License-Identifier: MIT */
/*
 * The object the responses belong to: NODES (positions), COLUMNS (the rows
 * that can be touched), SURFACE (triangles over the nodes) and, for a
 * floating object, RIGID (its mass properties).
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

#include "image_priv.h"

int img_check_nodes(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const struct irdm_node *nodes;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_NODES, true, "always");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_NODES,
				      (uint64_t[]){ m->n_nodes, sizeof(*nodes) }, 2,
				      "n_nodes x 16");
	if (ret)
		return ret;
	nodes = img_payload(p, IRDM_SEC_NODES);
	for (uint32_t i = 0; i < m->n_nodes; i++) {
		const struct irdm_node *nd = &nodes[i];

		if (!f32_finite(nd->pos_m[0]) || !f32_finite(nd->pos_m[1]) ||
		    !f32_finite(nd->pos_m[2]))
			return img_fail(p, IRDM_EFORMAT,
					"node %u has a non-finite position", i);
		/* mesh_nodes 0: responses not from a mesh (e.g. measured). */
		if (m->mesh_nodes && nd->mesh_node >= m->mesh_nodes)
			return img_fail(p, IRDM_EFORMAT,
					"node %u: mesh_node %u >= mesh_nodes %u",
					i, nd->mesh_node, m->mesh_nodes);
	}
	p->img.nodes = nodes;
	return IRDM_OK;
}

/* Column indices must name distinct rows; a bitmap finds repeats in O(n).
 * Allocating is fine here: this is initialisation, not the loop. */
int img_check_columns(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint32_t *cols;
	uint8_t *seen;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_COLUMNS, true, "always");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_COLUMNS, (uint64_t[]){ m->n_cols },
				      1, "n_cols");
	if (ret)
		return ret;
	cols = img_payload(p, IRDM_SEC_COLUMNS);
	seen = calloc((size_t)m->n_nodes / 8 + 1, 1);
	if (!seen)
		return img_fail(p, IRDM_ENOMEM,
				"out of memory checking %u columns", m->n_cols);
	for (uint32_t i = 0; i < m->n_cols; i++) {
		uint32_t c = cols[i];

		if (c >= m->n_nodes) {
			ret = img_fail(p, IRDM_EFORMAT,
				       "column %u names node %u, but there are only %u nodes",
				       i, c, m->n_nodes);
			goto free_seen;
		}
		if (seen[c / 8] & (1u << (c % 8))) {
			ret = img_fail(p, IRDM_EFORMAT,
				       "column %u repeats node %u", i, c);
			goto free_seen;
		}
		seen[c / 8] |= (uint8_t)(1u << (c % 8));
	}
	p->img.columns = cols;
free_seen:
	free(seen);
	return ret;
}

int img_check_surface(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint32_t *tris;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_SURFACE, true, "always");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_SURFACE, (uint64_t[]){ m->n_tris, 3 },
				      2, "n_tris x 3");
	if (ret)
		return ret;
	tris = img_payload(p, IRDM_SEC_SURFACE);
	for (uint64_t i = 0; i < (uint64_t)m->n_tris * 3; i++)
		if (tris[i] >= m->n_nodes)
			return img_fail(p, IRDM_EFORMAT,
					"triangle %llu names node %u, but there are only %u nodes",
					(unsigned long long)(i / 3), tris[i], m->n_nodes);
	p->img.tris = tris;
	return IRDM_OK;
}

int img_check_rigid(struct parse *p)
{
	bool floating = p->meta.flags & IRDM_META_FLOATING;
	const struct irdm_rigid *rg;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_RIGID, floating,
				 floating ? "meta flags say floating" :
					    "meta flags say grounded");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_RIGID,
				      (uint64_t[]){ sizeof(*rg) }, 1, "128");
	if (ret || !floating)
		return ret;
	rg = img_payload(p, IRDM_SEC_RIGID);
	if (!f64_finite(rg->mass_kg) || !(rg->mass_kg > 0))
		return img_fail(p, IRDM_EFORMAT,
				"rigid mass_kg is %g, must be finite and > 0", rg->mass_kg);
	for (unsigned i = 0; i < 3; i++)
		if (!f64_finite(rg->com_m[i]))
			return img_fail(p, IRDM_EFORMAT,
					"rigid com_m[%u] is not finite", i);
	for (unsigned i = 0; i < 9; i++)
		if (!f64_finite(rg->inertia_kg_m2[i]))
			return img_fail(p, IRDM_EFORMAT,
					"rigid inertia_kg_m2[%u] is not finite", i);
	if (p->strict && !all_zero(rg->reserved, sizeof(rg->reserved)))
		return img_fail(p, IRDM_EFORMAT,
				"rigid reserved fields are not zero");
	p->img.rigid = rg;
	return IRDM_OK;
}
