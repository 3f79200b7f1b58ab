/* SPDX-License-Identifier: MIT */
/*
 * The optional CONTACT_BVH: the contact module walks it in the force tick
 * without bounds checks, so it is proven here to be a tree over exactly the
 * contactable triangles, with nested finite boxes, a symmetric adjacency and
 * col_of_row the inverse of COLUMNS.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

#include "image_priv.h"

/* Scratch of the BVH check (init time: allocating is fine here). */
struct bvh_scratch {
	uint8_t *tri_seen;  /* per surface triangle: listed in index[] */
	uint8_t *slot_seen; /* per index[] entry: covered by a leaf */
	uint8_t *parents;   /* per node: references from a parent */
	uint8_t *level;     /* per node: depth, root = 1 */
};

static bool bvh_contactable(const uint32_t *col_of_row, const uint32_t *v)
{
	return col_of_row[v[0]] != IRDM_BVH_NONE &&
	       col_of_row[v[1]] != IRDM_BVH_NONE &&
	       col_of_row[v[2]] != IRDM_BVH_NONE;
}

static bool box_inside(const float *lo, const float *hi, const float *ilo,
		       const float *ihi)
{
	for (unsigned a = 0; a < 3; a++)
		if (ilo[a] < lo[a] || ihi[a] > hi[a])
			return false;
	return true;
}

/* Header: counts agree with meta, the canonical contiguous layout. */
static int bvh_check_header(struct parse *p, const struct irdm_image_section *s,
			    const struct irdm_bvh_header *h)
{
	const struct irdm_meta *m = &p->meta;
	uint64_t nodes_off = sizeof(*h);
	uint64_t index_off = nodes_off + (uint64_t)h->n_bvh_nodes * sizeof(struct irdm_bvh_node);
	uint64_t adj_off = index_off + (uint64_t)h->n_contact_tris * 4;
	uint64_t cor_off = adj_off + (uint64_t)m->n_tris * 12;
	uint64_t end = cor_off + (uint64_t)m->n_nodes * 4;

	if (h->n_surface_tris != m->n_tris || h->n_rows != m->n_nodes)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH is for %u triangles and %u rows, meta has %u and %u",
				h->n_surface_tris, h->n_rows, m->n_tris, m->n_nodes);
	if (p->strict && !all_zero(h->reserved, sizeof(h->reserved)))
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH reserved fields are not zero");
	if (h->n_contact_tris > m->n_tris || (h->n_bvh_nodes == 0) != (h->n_contact_tris == 0) ||
	    h->n_bvh_nodes > 2 * (uint64_t)h->n_contact_tris)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH has %u nodes for %u of %u triangles",
				h->n_bvh_nodes, h->n_contact_tris, m->n_tris);
	if (h->depth > IRDM_BVH_MAX_DEPTH || (h->depth == 0) != (h->n_bvh_nodes == 0) ||
	    h->leaf_max > IRDM_BVH_LEAF_MAX || (h->leaf_max == 0) != (h->n_bvh_nodes == 0))
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH depth %u, leaf_max %u: need 1..%u and 1..%u",
				h->depth, h->leaf_max, IRDM_BVH_MAX_DEPTH, IRDM_BVH_LEAF_MAX);
	if (h->nodes_offset != nodes_off || h->index_offset != index_off ||
	    h->adj_offset != adj_off || h->col_of_row_offset != cor_off || s->size != end)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH layout: offsets %u, %u, %u, %u and size %llu, expected %llu, %llu, %llu, %llu and %llu",
				h->nodes_offset, h->index_offset, h->adj_offset,
				h->col_of_row_offset, (unsigned long long)s->size,
				(unsigned long long)nodes_off, (unsigned long long)index_off,
				(unsigned long long)adj_off, (unsigned long long)cor_off,
				(unsigned long long)end);
	return IRDM_OK;
}

/* col_of_row is exactly the inverse of COLUMNS. */
static int bvh_check_cols(struct parse *p, const uint32_t *cor)
{
	uint32_t n = 0;

	for (uint32_t r = 0; r < p->meta.n_nodes; r++) {
		if (cor[r] == IRDM_BVH_NONE)
			continue;
		if (cor[r] >= p->meta.n_cols || p->img.columns[cor[r]] != r)
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH col_of_row[%u] is %u, which is not the column of row %u",
					r, cor[r], r);
		n++;
	}
	if (n != p->meta.n_cols)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH col_of_row names %u columns, the image has %u",
				n, p->meta.n_cols);
	return IRDM_OK;
}

/* index[] lists every contactable triangle exactly once, nothing else. */
static int bvh_check_index(struct parse *p, const struct irdm_bvh_header *h,
			   const uint32_t *index, const uint32_t *cor,
			   struct bvh_scratch *sc)
{
	uint32_t n = 0;

	for (uint32_t i = 0; i < h->n_contact_tris; i++) {
		uint32_t t = index[i];

		if (t >= p->meta.n_tris)
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH index[%u] is triangle %u, but there are only %u",
					i, t, p->meta.n_tris);
		if (sc->tri_seen[t])
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH index[%u] repeats triangle %u", i, t);
		if (!bvh_contactable(cor, &p->img.tris[3 * (uint64_t)t]))
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH index[%u]: triangle %u has a vertex that is not a column",
					i, t);
		sc->tri_seen[t] = 1;
	}
	for (uint32_t t = 0; t < p->meta.n_tris; t++)
		n += bvh_contactable(cor, &p->img.tris[3 * (uint64_t)t]);
	if (n != h->n_contact_tris)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH lists %u triangles, the surface has %u contactable ones",
				h->n_contact_tris, n);
	return IRDM_OK;
}

static int bvh_check_leaf(struct parse *p, const struct irdm_bvh_header *h,
			  const struct irdm_bvh_node *nd, uint32_t i,
			  const uint32_t *index, struct bvh_scratch *sc)
{
	uint64_t first = nd->left_or_first, count = nd->count_or_right;

	if (count < 1 || count > h->leaf_max || first + count > h->n_contact_tris)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH leaf %u has triangles [%llu, %llu) of %u (at most %u per leaf)",
				i, (unsigned long long)first, (unsigned long long)(first + count),
				h->n_contact_tris, h->leaf_max);
	for (uint64_t k = first; k < first + count; k++) {
		const uint32_t *v = &p->img.tris[3 * (uint64_t)index[k]];

		if (sc->slot_seen[k])
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH leaf %u: index entry %llu is in another leaf too",
					i, (unsigned long long)k);
		sc->slot_seen[k] = 1;
		for (unsigned j = 0; j < 3; j++) {
			const float *q = p->img.nodes[v[j]].pos_m;

			if (!box_inside(nd->lo, nd->hi, q, q))
				return img_fail(p, IRDM_EFORMAT,
						"CONTACT_BVH leaf %u does not contain triangle %u",
						i, index[k]);
		}
	}
	return IRDM_OK;
}

static int bvh_check_child(struct parse *p, const struct irdm_bvh_header *h,
			   const struct irdm_bvh_node *nodes, uint32_t i,
			   uint32_t c, struct bvh_scratch *sc)
{
	if (c <= i || c >= h->n_bvh_nodes)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH node %u has child %u: must be in (%u, %u)",
				i, c, i, h->n_bvh_nodes);
	if (sc->parents[c]++)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH node %u has more than one parent", c);
	if (!box_inside(nodes[i].lo, nodes[i].hi, nodes[c].lo, nodes[c].hi))
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH node %u does not contain its child %u", i, c);
	sc->level[c] = sc->level[i] + 1;
	return IRDM_OK;
}

/*
 * A tree: children have larger indices than their parent (no cycle), every
 * node but the root has exactly one parent, so every node hangs off node 0.
 * Leaves partition index[]; boxes are finite, ordered and nested.
 */
static int bvh_check_nodes(struct parse *p, const struct irdm_bvh_header *h,
			   const struct irdm_bvh_node *nodes, const uint32_t *index,
			   struct bvh_scratch *sc)
{
	uint32_t depth = 0;
	int ret;

	if (h->n_bvh_nodes)
		sc->level[0] = 1;
	for (uint32_t i = 0; i < h->n_bvh_nodes; i++) {
		const struct irdm_bvh_node *nd = &nodes[i];

		for (unsigned a = 0; a < 3; a++)
			if (!f32_finite(nd->lo[a]) || !f32_finite(nd->hi[a]) ||
			    !(nd->lo[a] <= nd->hi[a]))
				return img_fail(p, IRDM_EFORMAT,
						"CONTACT_BVH node %u: box axis %u is [%g, %g], need finite lo <= hi",
						i, a, (double)nd->lo[a], (double)nd->hi[a]);
		if (i && sc->parents[i] != 1)
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH node %u is not reachable from the root", i);
		if (sc->level[i] > h->depth)
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH node %u is at level %u, the header says depth %u",
					i, sc->level[i], h->depth);
		depth = sc->level[i] > depth ? sc->level[i] : depth;
		if (nd->count_or_right & IRDM_BVH_INTERNAL) {
			ret = bvh_check_child(p, h, nodes, i, nd->left_or_first, sc);
			if (!ret)
				ret = bvh_check_child(p, h, nodes, i,
						      nd->count_or_right & ~IRDM_BVH_INTERNAL, sc);
		} else {
			ret = bvh_check_leaf(p, h, nd, i, index, sc);
		}
		if (ret)
			return ret;
	}
	if (depth != h->depth)
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH is %u levels deep, the header says %u", depth, h->depth);
	for (uint32_t k = 0; k < h->n_contact_tris; k++)
		if (!sc->slot_seen[k])
			return img_fail(p, IRDM_EFORMAT,
					"CONTACT_BVH index entry %u is in no leaf", k);
	return IRDM_OK;
}

/* Neighbours are contactable, share the edge, and name us back across it. */
static int bvh_check_adj(struct parse *p, const uint32_t *adj, const uint32_t *cor)
{
	const uint32_t *tris = p->img.tris;

	for (uint32_t t = 0; t < p->meta.n_tris; t++) {
		const uint32_t *v = &tris[3 * (uint64_t)t];
		bool contactable = bvh_contactable(cor, v);

		for (unsigned e = 0; e < 3; e++) {
			uint32_t u = adj[3 * (uint64_t)t + e], a = v[e], b = v[(e + 1) % 3];
			const uint32_t *w;
			unsigned f;

			if (u == IRDM_BVH_NONE)
				continue;
			if (!contactable || u >= p->meta.n_tris || u == t ||
			    !bvh_contactable(cor, &tris[3 * (uint64_t)u]))
				return img_fail(p, IRDM_EFORMAT,
						"CONTACT_BVH triangle %u edge %u: neighbour %u is out of range or not contactable",
						t, e, u);
			w = &tris[3 * (uint64_t)u];
			for (f = 0; f < 3; f++)
				if ((w[f] == a && w[(f + 1) % 3] == b) ||
				    (w[f] == b && w[(f + 1) % 3] == a))
					break;
			if (f == 3 || adj[3 * (uint64_t)u + f] != t)
				return img_fail(p, IRDM_EFORMAT,
						"CONTACT_BVH triangle %u edge %u: neighbour %u does not share it back",
						t, e, u);
		}
	}
	return IRDM_OK;
}

/*
 * Optional.  Version 1.0 reserved kind 12 without defining it, so a kind-12
 * section of another element type than BYTES is that reserved form: skipped
 * like an unknown kind, no view.  A BYTES one must be a valid BVH.
 */
int img_check_contact_bvh(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_CONTACT_BVH];
	const struct irdm_bvh_header *h;
	struct bvh_scratch sc = { 0 };
	const uint8_t *base;
	int ret;

	if (!s || s->elem != IRDM_ELEM_BYTES)
		return IRDM_OK;
	if (s->size < sizeof(*h))
		return img_fail(p, IRDM_EFORMAT,
				"CONTACT_BVH has %llu bytes, less than its %zu-byte header",
				(unsigned long long)s->size, sizeof(*h));
	base = p->base + s->offset;
	h = (const struct irdm_bvh_header *)base;
	ret = bvh_check_header(p, s, h);
	if (ret)
		return ret;
	ret = bvh_check_cols(p, (const uint32_t *)(base + h->col_of_row_offset));
	if (ret)
		return ret;
	sc.tri_seen = calloc((size_t)p->meta.n_tris + 1, 1);
	sc.slot_seen = calloc((size_t)h->n_contact_tris + 1, 1);
	sc.parents = calloc((size_t)h->n_bvh_nodes + 1, 1);
	sc.level = calloc((size_t)h->n_bvh_nodes + 1, 1);
	if (!sc.tri_seen || !sc.slot_seen || !sc.parents || !sc.level) {
		ret = img_fail(p, IRDM_ENOMEM, "out of memory checking CONTACT_BVH");
		goto out;
	}
	ret = bvh_check_index(p, h, (const uint32_t *)(base + h->index_offset),
			      (const uint32_t *)(base + h->col_of_row_offset), &sc);
	if (!ret)
		ret = bvh_check_nodes(p, h, (const struct irdm_bvh_node *)(base + h->nodes_offset),
				      (const uint32_t *)(base + h->index_offset), &sc);
	if (!ret)
		ret = bvh_check_adj(p, (const uint32_t *)(base + h->adj_offset),
				    (const uint32_t *)(base + h->col_of_row_offset));
	if (!ret) {
		p->img.contact_bvh = h;
		p->img.contact_bvh_size = (size_t)s->size;
	}
out:
	free(sc.tri_seen);
	free(sc.slot_seen);
	free(sc.parents);
	free(sc.level);
	return ret;
}
