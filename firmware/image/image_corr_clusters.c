/* SPDX-License-Identifier: MIT */
/*
 * The static correction in block low-rank form, STATIC_CORR_CLUSTERS
 * (image_format.h): its checks (image_read.c reads it).  The checks make
 * every read safe and bounded: the member lists a permutation
 * with its inverse, each pair's matrix inside the values and the values
 * tiling them, ranks no higher than the tick can afford, self pairs dense
 * (stored as their upper triangle: symmetric, as R[0] must be), every
 * value finite.
 */
#include <stdbool.h>
#include <stdint.h>

#include "image_priv.h"

#define HDR sizeof(struct irdm_corr_clusters_header)

/* Bytes of the header and the three u32 tables, padded to 8. */
static uint64_t tables_bytes(uint64_t n_clusters, uint64_t n_cols)
{
	uint64_t b = HDR + 4 * (n_clusters + 1 + 2 * n_cols);

	return (b + 7) & ~(uint64_t)7;
}

static uint64_t n_pairs(uint64_t n_clusters)
{
	return n_clusters * (n_clusters + 1) / 2;
}

static int check_header(struct parse *p, const struct irdm_corr_clusters_header *h,
			uint64_t size)
{
	uint32_t nc = p->meta.n_cols;
	uint32_t max = nc < IRDM_CORR_CLUSTERS_MAX ? nc : IRDM_CORR_CLUSTERS_MAX;
	uint64_t fixed;

	if (h->n_clusters < 1 || h->n_clusters > max)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_CLUSTERS: %u clusters is not in 1..%u (n_cols, at most %u)",
				h->n_clusters, max, IRDM_CORR_CLUSTERS_MAX);
	if (h->max_rank > IRDM_CORR_LOWRANK_MAX)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_CLUSTERS: max_rank %u is above %u",
				h->max_rank, IRDM_CORR_LOWRANK_MAX);
	if (p->strict && !all_zero(h->reserved, sizeof(h->reserved)))
		return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS: reserved header words not 0");
	fixed = tables_bytes(h->n_clusters, nc) + sizeof(struct irdm_corr_pair) * n_pairs(h->n_clusters);
	if (h->n_values > (UINT64_MAX - fixed) / p->es || size != fixed + p->es * h->n_values)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_CLUSTERS has %llu bytes, expected %llu for %u clusters and %llu values",
				(unsigned long long)size,
				(unsigned long long)(fixed + p->es * h->n_values),
				h->n_clusters, (unsigned long long)h->n_values);
	return IRDM_OK;
}

/* start: 0, increasing, n_cols; members a permutation, col_pos its inverse. */
static int check_tables(struct parse *p, uint32_t n_clusters, const uint32_t *start,
			const uint32_t *members, const uint32_t *col_pos, const uint8_t *pad,
			size_t pad_len)
{
	uint32_t nc = p->meta.n_cols;

	if (start[0] != 0 || start[n_clusters] != nc)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_CLUSTERS: cluster starts run %u..%u, expected 0..%u (n_cols)",
				start[0], start[n_clusters], nc);
	for (uint32_t a = 0; a < n_clusters; a++)
		if (start[a + 1] <= start[a])
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_CLUSTERS: cluster %u is empty or reversed (start %u, next %u)",
					a, start[a], start[a + 1]);
	for (uint32_t i = 0; i < nc; i++) {
		if (members[i] >= nc)
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_CLUSTERS: member %u is column %u, not below n_cols %u",
					i, members[i], nc);
		if (col_pos[members[i]] != i)
			return img_fail(p, IRDM_EFORMAT,
					"STATIC_CORR_CLUSTERS: column %u is member %u, but col_pos says %u",
					members[i], i, col_pos[members[i]]);
	}
	if (!all_zero(pad, pad_len))
		return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS: padding not 0");
	return IRDM_OK;
}

/* Elements of pair (a, b)'s matrix (a self pair: its upper triangle). */
static uint64_t pair_values(uint32_t rank, uint64_t rows, uint64_t cols, bool self)
{
	if (self)
		return rows * (rows + 1) / 2;
	return rank == IRDM_CORR_PAIR_DENSE ? rows * cols : (uint64_t)rank * (rows + cols);
}

/* Pair (a, b)'s matrix within the left values; divides (or bounds the
 * factors first) so that no product of 3 n_cols-sized factors can wrap
 * (next never passes n_values). */
static bool pair_fits(uint32_t rank, uint64_t rows, uint64_t cols, uint64_t left, bool self)
{
	if (self)
		return rows < (1ull << 31) && rows * (rows + 1) / 2 <= left;
	return rank == IRDM_CORR_PAIR_DENSE ? rows <= left / cols : rank <= left / (rows + cols);
}

static int check_pairs(struct parse *p, const struct irdm_corr_clusters_header *h,
		       const uint32_t *start, const struct irdm_corr_pair *pairs)
{
	uint64_t next = 0, k = 0;

	for (uint32_t a = 0; a < h->n_clusters; a++)
		for (uint32_t b = a; b < h->n_clusters; b++, k++) {
			const struct irdm_corr_pair *q = &pairs[k];
			uint64_t ra = 3 * (uint64_t)(start[a + 1] - start[a]);
			uint64_t rb = 3 * (uint64_t)(start[b + 1] - start[b]);
			uint64_t lim = ra < rb ? ra : rb;
			if (a == b && q->rank != IRDM_CORR_PAIR_DENSE)
				return img_fail(p, IRDM_EFORMAT,
						"STATIC_CORR_CLUSTERS: self pair %u has rank %u, must be dense",
						a, q->rank);
			if (q->rank != IRDM_CORR_PAIR_DENSE && (q->rank > lim || q->rank > h->max_rank))
				return img_fail(p, IRDM_EFORMAT,
						"STATIC_CORR_CLUSTERS: pair (%u, %u) has rank %u, above min(%llu, %llu, max_rank %u)",
						a, b, q->rank, (unsigned long long)ra,
						(unsigned long long)rb, h->max_rank);
			if (p->strict && q->reserved)
				return img_fail(p, IRDM_EFORMAT,
						"STATIC_CORR_CLUSTERS: pair (%u, %u) reserved word not 0",
						a, b);
			if (q->offset != next)
				return img_fail(p, IRDM_EFORMAT,
						"STATIC_CORR_CLUSTERS: pair (%u, %u) starts at value %llu, expected %llu (pairs follow each other)",
						a, b, (unsigned long long)q->offset,
						(unsigned long long)next);
			if (!pair_fits(q->rank, ra, rb, h->n_values - next, a == b))
				return img_fail(p, IRDM_EFORMAT,
						"STATIC_CORR_CLUSTERS: pair (%u, %u) runs past the header's %llu values (from value %llu)",
						a, b, (unsigned long long)h->n_values,
						(unsigned long long)next);
			next += pair_values(q->rank, ra, rb, a == b);
		}
	if (next != h->n_values)
		return img_fail(p, IRDM_EFORMAT,
				"STATIC_CORR_CLUSTERS: the pairs hold %llu values, the header says %llu",
				(unsigned long long)next, (unsigned long long)h->n_values);
	return IRDM_OK;
}

/* Every value finite. */
static int check_values(struct parse *p, const struct irdm_corr_clusters_header *h,
			const uint8_t *values)
{
	uint32_t prec = p->meta.precision;

	for (uint64_t i = 0; i < h->n_values; i++)
		if (!f64_finite(irdm_elem_get(values, prec, (size_t)i)))
			return img_fail(p, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS: value %llu is not finite",
					(unsigned long long)i);
	return IRDM_OK;
}

int img_check_corr_clusters(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_STATIC_CORR_CLUSTERS];
	const uint8_t *pl = img_payload(p, IRDM_SEC_STATIC_CORR_CLUSTERS);
	struct irdm_corr_clusters_header h;
	const uint32_t *start, *members, *col_pos;
	const struct irdm_corr_pair *pairs;
	uint64_t tb;
	int ret;

	if (!s)
		return IRDM_OK;
	if (s->elem != IRDM_ELEM_BYTES)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_CLUSTERS has element type %s, expected BYTES",
				img_elem_name(s->elem));
	if (s->size < HDR)
		return img_fail(p, IRDM_EFORMAT,
				"section STATIC_CORR_CLUSTERS has %llu bytes, fewer than its 32-byte header",
				(unsigned long long)s->size);
	memcpy(&h, pl, HDR);
	ret = check_header(p, &h, s->size);
	if (ret)
		return ret;
	start = (const uint32_t *)(pl + HDR);
	members = start + h.n_clusters + 1;
	col_pos = members + p->meta.n_cols;
	tb = tables_bytes(h.n_clusters, p->meta.n_cols);
	pairs = (const struct irdm_corr_pair *)(pl + tb);
	ret = check_tables(p, h.n_clusters, start, members, col_pos,
			   (const uint8_t *)(col_pos + p->meta.n_cols),
			   (size_t)(pl + tb - (const uint8_t *)(col_pos + p->meta.n_cols)));
	if (!ret)
		ret = check_pairs(p, &h, start, pairs);
	if (!ret)
		ret = check_values(p, &h, pl + tb + sizeof(struct irdm_corr_pair) * n_pairs(h.n_clusters));
	if (ret)
		return ret;
	p->img.corr_clusters = (const struct irdm_corr_clusters_header *)pl;
	p->img.corr_cl_start = start;
	p->img.corr_cl_members = members;
	p->img.corr_cl_pos = col_pos;
	p->img.corr_cl_pairs = pairs;
	p->img.corr_cl_values = pl + tb + sizeof(struct irdm_corr_pair) * n_pairs(h.n_clusters);
	return IRDM_OK;
}
