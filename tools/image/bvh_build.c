/* SPDX-License-Identifier: MIT */
/*
 * CONTACT_BVH builder.  Offline, so it may allocate and sort freely; what it
 * writes is what firmware/image/image_bvh.c checks, and the firmware walks
 * it with a fixed stack (firmware/proxy/contact.c).
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/bvh_build.h"

struct sort_key {
	double key;
	uint32_t tri;
};

struct edge {
	uint32_t a, b; /* vertex rows, a < b */
	uint32_t tri;
	uint32_t e; /* edge (v[e], v[(e + 1) % 3]) */
};

struct bld {
	const struct irdm_node *nodes;
	const uint32_t *tris;
	uint32_t *index;       /* contactable triangles, permuted in place */
	double *cent;          /* 3 per surface triangle */
	struct sort_key *keys; /* scratch, one per contactable triangle */
	struct irdm_bvh_node *out;
	uint32_t n_out;
	uint32_t depth;
	uint32_t leaf_max;
};

static int cmp_key(const void *x, const void *y)
{
	const struct sort_key *a = x, *b = y;

	if (a->key != b->key)
		return a->key < b->key ? -1 : 1;
	return a->tri < b->tri ? -1 : a->tri > b->tri;
}

static int cmp_edge(const void *x, const void *y)
{
	const struct edge *a = x, *b = y;

	if (a->a != b->a)
		return a->a < b->a ? -1 : 1;
	if (a->b != b->b)
		return a->b < b->b ? -1 : 1;
	return a->tri < b->tri ? -1 : a->tri > b->tri;
}

static void box_of(const struct bld *b, uint32_t begin, uint32_t end,
		   struct irdm_bvh_node *nd)
{
	for (unsigned a = 0; a < 3; a++) {
		nd->lo[a] = b->nodes[b->tris[3 * (size_t)b->index[begin]]].pos_m[a];
		nd->hi[a] = nd->lo[a];
	}
	for (uint32_t i = begin; i < end; i++)
		for (unsigned k = 0; k < 3; k++) {
			const float *q = b->nodes[b->tris[3 * (size_t)b->index[i] + k]].pos_m;

			for (unsigned a = 0; a < 3; a++) {
				if (q[a] < nd->lo[a])
					nd->lo[a] = q[a];
				if (q[a] > nd->hi[a])
					nd->hi[a] = q[a];
			}
		}
}

/* Longest axis of the centroids of index[begin, end). */
static unsigned split_axis(const struct bld *b, uint32_t begin, uint32_t end)
{
	double lo[3], hi[3];
	unsigned axis = 0;

	for (unsigned a = 0; a < 3; a++)
		lo[a] = hi[a] = b->cent[3 * (size_t)b->index[begin] + a];
	for (uint32_t i = begin; i < end; i++)
		for (unsigned a = 0; a < 3; a++) {
			double c = b->cent[3 * (size_t)b->index[i] + a];

			lo[a] = c < lo[a] ? c : lo[a];
			hi[a] = c > hi[a] ? c : hi[a];
		}
	for (unsigned a = 1; a < 3; a++)
		if (hi[a] - lo[a] > hi[axis] - lo[axis])
			axis = a;
	return axis;
}

/* Node for index[begin, end) at `level` (root 1), preorder numbering:
 * children always get larger indices than their parent. */
static int build_node(struct bld *b, uint32_t begin, uint32_t end, uint32_t level)
{
	uint32_t me = b->n_out++, n = end - begin, mid, right;
	struct irdm_bvh_node *nd = &b->out[me];
	unsigned axis;

	if (level > IRDM_BVH_MAX_DEPTH)
		return -1;
	if (level > b->depth)
		b->depth = level;
	box_of(b, begin, end, nd);
	if (n <= IRDM_BVH_LEAF_MAX) {
		nd->left_or_first = begin;
		nd->count_or_right = n;
		if (n > b->leaf_max)
			b->leaf_max = n;
		return 0;
	}
	axis = split_axis(b, begin, end);
	for (uint32_t i = 0; i < n; i++) {
		uint32_t t = b->index[begin + i];

		b->keys[i] = (struct sort_key){ b->cent[3 * (size_t)t + axis], t };
	}
	qsort(b->keys, n, sizeof(*b->keys), cmp_key);
	for (uint32_t i = 0; i < n; i++)
		b->index[begin + i] = b->keys[i].tri;
	mid = begin + n / 2;
	if (build_node(b, begin, mid, level + 1))
		return -1;
	right = b->n_out;
	if (build_node(b, mid, end, level + 1))
		return -1;
	/* b->out did not move: it was sized for the largest possible tree */
	b->out[me].left_or_first = me + 1;
	b->out[me].count_or_right = IRDM_BVH_INTERNAL | right;
	return 0;
}

static bool contactable(const uint32_t *col_of_row, const uint32_t *v)
{
	return col_of_row[v[0]] != IRDM_BVH_NONE && col_of_row[v[1]] != IRDM_BVH_NONE &&
	       col_of_row[v[2]] != IRDM_BVH_NONE;
}

/*
 * Neighbours across each edge among the contactable triangles: an edge that
 * exactly two of them share links them; an edge of one (the region's
 * boundary) or of three or more (non-manifold) links nothing.  A triangle
 * with a repeated vertex links nothing either.
 */
static int build_adjacency(const uint32_t *tris, uint32_t n_tris, const uint32_t *col_of_row,
			   uint32_t n_contact, uint32_t *adj)
{
	struct edge *ed = malloc(3 * (size_t)(n_contact ? n_contact : 1) * sizeof(*ed));
	size_t n = 0;

	if (!ed)
		return -1;
	for (size_t i = 0; i < 3 * (size_t)n_tris; i++)
		adj[i] = IRDM_BVH_NONE;
	for (uint32_t t = 0; t < n_tris; t++) {
		const uint32_t *v = &tris[3 * (size_t)t];

		if (!contactable(col_of_row, v) || v[0] == v[1] || v[1] == v[2] || v[2] == v[0])
			continue;
		for (uint32_t e = 0; e < 3; e++) {
			uint32_t a = v[e], c = v[(e + 1) % 3];

			ed[n++] = (struct edge){ a < c ? a : c, a < c ? c : a, t, e };
		}
	}
	qsort(ed, n, sizeof(*ed), cmp_edge);
	for (size_t i = 0; i < n;) {
		size_t j = i + 1;

		while (j < n && ed[j].a == ed[i].a && ed[j].b == ed[i].b)
			j++;
		if (j - i == 2) {
			adj[3 * (size_t)ed[i].tri + ed[i].e] = ed[i + 1].tri;
			adj[3 * (size_t)ed[i + 1].tri + ed[i + 1].e] = ed[i].tri;
		}
		i = j;
	}
	free(ed);
	return 0;
}

int irdm_bvh_build(const struct irdm_node *nodes, uint32_t n_nodes,
		   const uint32_t *columns, uint32_t n_cols,
		   const uint32_t *tris, uint32_t n_tris,
		   void **payload, size_t *size, char *err, size_t errlen)
{
	struct bld b = { .nodes = nodes, .tris = tris };
	struct irdm_bvh_header h = { 0 };
	uint32_t *col_of_row = NULL, *adj = NULL;
	uint32_t n_contact = 0;
	uint8_t *out = NULL;
	size_t bytes;
	int ret = IRDM_EINVAL;

	*payload = NULL;
	*size = 0;
	for (uint32_t c = 0; c < n_cols; c++)
		if (columns[c] >= n_nodes) {
			snprintf(err, errlen, "bvh: column %u names row %u of %u", c, columns[c], n_nodes);
			return IRDM_EINVAL;
		}
	for (size_t i = 0; i < 3 * (size_t)n_tris; i++)
		if (tris[i] >= n_nodes) {
			snprintf(err, errlen, "bvh: triangle %zu names row %u of %u", i / 3, tris[i],
				 n_nodes);
			return IRDM_EINVAL;
		}
	col_of_row = malloc(((size_t)n_nodes + 1) * sizeof(uint32_t));
	adj = malloc((3 * (size_t)n_tris + 1) * sizeof(uint32_t));
	b.index = malloc(((size_t)n_tris + 1) * sizeof(uint32_t));
	b.cent = malloc((3 * (size_t)n_tris + 1) * sizeof(double));
	b.keys = malloc(((size_t)n_tris + 1) * sizeof(*b.keys));
	b.out = calloc(2 * (size_t)n_tris + 1, sizeof(*b.out));
	if (!col_of_row || !adj || !b.index || !b.cent || !b.keys || !b.out)
		goto out_nomem;
	for (uint32_t r = 0; r < n_nodes; r++)
		col_of_row[r] = IRDM_BVH_NONE;
	for (uint32_t c = 0; c < n_cols; c++)
		col_of_row[columns[c]] = c;
	for (uint32_t t = 0; t < n_tris; t++) {
		const uint32_t *v = &tris[3 * (size_t)t];

		for (unsigned a = 0; a < 3; a++)
			b.cent[3 * (size_t)t + a] = ((double)nodes[v[0]].pos_m[a] +
						     nodes[v[1]].pos_m[a] + nodes[v[2]].pos_m[a]) /
						    3;
		if (contactable(col_of_row, v))
			b.index[n_contact++] = t;
	}
	if (n_contact && build_node(&b, 0, n_contact, 1)) {
		snprintf(err, errlen, "bvh: tree deeper than %u levels over %u triangles",
			 IRDM_BVH_MAX_DEPTH, n_contact);
		goto out_free;
	}
	if (build_adjacency(tris, n_tris, col_of_row, n_contact, adj))
		goto out_nomem;

	h.n_surface_tris = n_tris;
	h.n_rows = n_nodes;
	h.n_contact_tris = n_contact;
	h.n_bvh_nodes = b.n_out;
	h.depth = b.depth;
	h.leaf_max = b.leaf_max;
	h.nodes_offset = sizeof(h);
	h.index_offset = h.nodes_offset + b.n_out * (uint32_t)sizeof(*b.out);
	h.adj_offset = h.index_offset + n_contact * 4u;
	h.col_of_row_offset = h.adj_offset + n_tris * 12u;
	bytes = (size_t)h.col_of_row_offset + (size_t)n_nodes * 4;
	if ((uint64_t)sizeof(h) + (uint64_t)b.n_out * sizeof(*b.out) + n_contact * 4ull +
		    n_tris * 12ull + n_nodes * 4ull !=
	    bytes) {
		snprintf(err, errlen, "bvh: %u triangles and %u rows do not fit a 4 GiB section",
			 n_tris, n_nodes);
		goto out_free;
	}
	out = malloc(bytes);
	if (!out)
		goto out_nomem;
	memcpy(out, &h, sizeof(h));
	memcpy(out + h.nodes_offset, b.out, (size_t)b.n_out * sizeof(*b.out));
	memcpy(out + h.index_offset, b.index, (size_t)n_contact * 4);
	memcpy(out + h.adj_offset, adj, (size_t)n_tris * 12);
	memcpy(out + h.col_of_row_offset, col_of_row, (size_t)n_nodes * 4);
	*payload = out;
	*size = bytes;
	ret = IRDM_OK;
	goto out_free;
out_nomem:
	snprintf(err, errlen, "bvh: out of memory for %u triangles", n_tris);
	ret = IRDM_ENOMEM;
out_free:
	free(col_of_row);
	free(adj);
	free(b.index);
	free(b.cent);
	free(b.keys);
	free(b.out);
	return ret;
}
