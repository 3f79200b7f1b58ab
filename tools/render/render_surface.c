/* SPDX-License-Identifier: MIT */
/*
 * What the image can show: its SURFACE is every boundary triangle whose
 * vertices are all rows (tools/precompute/select.c), so a scene that
 * displays only part of the object gives an open surface.  Counting the
 * edges that only one triangle has says so without the source mesh.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render.h"

static int cmp_edge(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;

	return (x > y) - (x < y);
}

/* Edges (smaller row, larger row) that occur exactly once. */
static uint32_t open_edges(const struct irdm_image *img)
{
	size_t n = 3 * (size_t)img->meta->n_tris, k = 0;
	uint64_t *e = malloc((n ? n : 1) * sizeof(uint64_t));
	uint32_t open = 0;

	if (!e)
		return UINT32_MAX; /* unknown: said as "not closed" */
	for (size_t t = 0; t < img->meta->n_tris; t++)
		for (int j = 0; j < 3; j++) {
			uint64_t a = img->tris[3 * t + j], b = img->tris[3 * t + (j + 1) % 3];
			e[k++] = a < b ? a << 32 | b : b << 32 | a;
		}
	qsort(e, n, sizeof(uint64_t), cmp_edge);
	for (size_t i = 0; i < n;) {
		size_t j = i;
		while (j < n && e[j] == e[i])
			j++;
		open += j - i == 1;
		i = j;
	}
	free(e);
	return open;
}

/* The value of "display=" in the provenance, if it is there. */
static void display_key(const struct irdm_image *img, char *out, size_t len)
{
	const char *p = img->provenance, *end = p + img->provenance_len;

	out[0] = '\0';
	while (p < end) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		size_t n = (size_t)((nl ? nl : end) - p);
		if (n > 8 && !memcmp(p, "display=", 8)) {
			snprintf(out, len, "%.*s", (int)(n - 8), p + 8);
			return;
		}
		p += n + 1;
	}
}

void irdm_render_surface(const struct irdm_image *img, struct irdm_render_surface *s)
{
	s->nodes = img->meta->n_nodes;
	s->tris = img->meta->n_tris;
	s->open_edges = open_edges(img);
	display_key(img, s->display, sizeof(s->display));
}
