/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer target: irdm_image_parse() on arbitrary bytes.  The input is
 * copied into an exactly sized heap buffer (8-aligned, as the loader
 * requires) so that AddressSanitizer catches any read outside the image.
 * When an input is accepted, every view is read end to end by the meta
 * counts: a view that the parser validated must lie inside the buffer.
 *
 * Checksums stop almost every mutation at the header; fuzz_image_semantic.c
 * builds the same target with the checksum comparisons compiled out.
 *
 * Seeds (tests/fuzz/seeds/, the same in both targets' folders): valid
 * images of each kind.  clusters_f16.img (format 2.2, 2536 bytes) is the
 * test fixture's img_fixture_modal(f16, 6 nodes, 5 columns, 2 modes,
 * STATIC_CORR) with img_fixture_lowrank(rank 1) and
 * img_fixture_clusters(3 clusters, cross pairs of rank 2), written by
 * img_fixture_write (tests/support/image_fixture.h).
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static volatile uint64_t fuzz_sink;

static void read_bytes(const void *p, uint64_t len)
{
	const uint8_t *b = p;
	uint64_t acc = 0;

	for (uint64_t i = 0; i < len; i++)
		acc += b[i];
	fuzz_sink += acc;
}

static void read_values(const void *p, uint32_t elem, uint64_t count)
{
	double acc = 0;

	for (uint64_t i = 0; i < count; i++)
		acc += irdm_elem_get(p, elem, i);
	fuzz_sink += (uint64_t)(acc != acc);
}

/* STATIC_CORR_CLUSTERS: the tables and values, every column's cluster
 * lookup against the members list, and whole blocks (the tick's reader)
 * for the first, last and a middle column in both orders. */
static void walk_clusters(const struct irdm_image *img)
{
	const struct irdm_corr_clusters_header *h = img->corr_clusters;
	uint32_t cols = img->meta->n_cols, ends[3] = { 0, cols / 2, cols - 1 };
	double blk[9];

	read_bytes(img->corr_cl_start, 4 * ((uint64_t)h->n_clusters + 1));
	read_bytes(img->corr_cl_members, 4 * (uint64_t)cols);
	read_bytes(img->corr_cl_pos, 4 * (uint64_t)cols);
	read_bytes(img->corr_cl_pairs,
		   sizeof(*img->corr_cl_pairs) * ((uint64_t)h->n_clusters * (h->n_clusters + 1) / 2));
	read_values(img->corr_cl_values, img->meta->precision, h->n_values);
	for (uint32_t c = 0; c < cols; c++) {
		uint32_t local, a = irdm_image_corr_cluster(img, c, &local);
		if (a >= h->n_clusters ||
		    local >= img->corr_cl_start[a + 1] - img->corr_cl_start[a] ||
		    img->corr_cl_members[img->corr_cl_start[a] + local] != c)
			abort();
	}
	for (unsigned i = 0; i < 3; i++)
		for (unsigned j = 0; j < 3; j++) {
			irdm_image_corr_value(img, ends[i], ends[j], blk);
			read_bytes(blk, sizeof(blk));
		}
}

static void walk_views(const struct irdm_image *img)
{
	const struct irdm_meta *m = img->meta;
	uint64_t nodes = m->n_nodes, cols = m->n_cols;

	read_bytes(img->provenance, img->provenance_len);
	read_bytes(img->nodes, nodes * sizeof(*img->nodes));
	read_bytes(img->columns, cols * 4);
	read_bytes(img->tris, (uint64_t)m->n_tris * 12);
	read_bytes(img->stability, cols * sizeof(*img->stability));
	if (img->fir)
		read_values(img->fir, m->precision,
			    cols * nodes * m->fir_length * 9);
	if (img->modes)
		read_bytes(img->modes, (uint64_t)m->n_modes * sizeof(*img->modes));
	if (img->mode_shapes)
		read_values(img->mode_shapes, m->precision,
			    nodes * 3 * m->n_modes);
	if (img->corr_start) {
		uint64_t n_blocks = img->corr_start[cols];
		read_bytes(img->corr_rows, n_blocks * 4);
		read_values(img->corr_blocks, m->precision, n_blocks * 9);
		/* the tick's lookup: every kept block, and the ends */
		for (uint32_t c = 0; c < cols; c++) {
			for (uint32_t k = img->corr_start[c]; k < img->corr_start[c + 1]; k++)
				if (irdm_image_corr_block(img, c, img->corr_rows[k]) != (long)k)
					abort();
			(void)irdm_image_corr_block(img, c, 0);
			(void)irdm_image_corr_block(img, c, (uint32_t)cols - 1);
		}
		/* the hybrid's head: head_samples x 9 per run, and each kept
		 * block's run through the index (HEAD_PAIRS) */
		if (img->exact_head) {
			uint64_t per = (uint64_t)m->head_samples * 9;
			read_values(img->exact_head, m->precision,
				    irdm_image_find(img, IRDM_SEC_EXACT_HEAD)->size /
					    irdm_elem_size(m->precision));
			for (uint64_t k = 0; k < n_blocks; k++) {
				bool tr;
				size_t run = irdm_image_head_run(img, (size_t)k, &tr);
				double v[2] = {
					irdm_elem_get(img->exact_head, m->precision,
						      run * per + irdm_head_elem(tr, 1)),
					irdm_elem_get(img->exact_head, m->precision, run * per + per - 1),
				};
				read_bytes(v, sizeof(v));
			}
		}
	}
	if (img->corr_rank) {
		/* the far field: every value, and a whole block at the ends
		 * (the reader the engine and image_response use) */
		double blk[9];
		read_values(img->corr_lambda, m->precision, img->corr_rank);
		read_values(img->corr_u, m->precision, 3 * cols * img->corr_rank);
		irdm_image_corr_value(img, 0, (uint32_t)cols - 1, blk);
		read_bytes(blk, sizeof(blk));
		irdm_image_corr_value(img, (uint32_t)cols - 1, 0, blk);
		read_bytes(blk, sizeof(blk));
	}
	if (img->corr_clusters)
		walk_clusters(img);
	if (img->rigid)
		read_bytes(img->rigid, sizeof(*img->rigid));
	if (img->col_scale)
		read_bytes(img->col_scale, img->meta->n_cols * sizeof(*img->col_scale));
	for (uint32_t k = 0; k <= IRDM_SEC_COLUMN_SCALE + 1; k++) {
		const struct irdm_image_section *s = irdm_image_find(img, k);

		if (s)
			read_bytes(img->base + s->offset, s->size);
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct irdm_image img;
	char err[256];
	void *buf = malloc(size ? size : 1); /* malloc: 16-aligned */

	if (!buf)
		return 0;
	memcpy(buf, data, size);
	if (irdm_image_parse(buf, size, &img, err, sizeof(err)) == IRDM_OK)
		walk_views(&img);
	else if (!err[0] || img.base)
		abort(); /* every rejection has a reason and no views */
	free(buf);
	return 0;
}
