/* SPDX-License-Identifier: MIT */
/*
 * The R[0] blocks between the nodes of the active contact sites: kept while
 * the sites stay, refreshed for new nodes only (a site change every tick
 * costs 9 K multiply-adds per new block for a modal image, a read for FIR).
 */
#include <string.h>

#include "repr.h"
#include "tick_priv.h"

static int r0_index(const struct r0_table *t, uint32_t col)
{
	for (uint32_t k = 0; k < t->n; k++)
		if (t->col[k] == col)
			return (int)k;
	return -1;
}

/*
 * Bring the R[0] table to the nodes of the active sites: blocks between
 * nodes already there are kept, the others computed (9 (K + r)
 * multiply-adds each for a modal image with a far field of rank r, a read
 * for FIR).  Nothing happens while the sites stay the same.
 */
void tick_r0_refresh(struct irdm_engine *e, const unsigned *idx, int m)
{
	struct r0_table *old = &e->r0, *nt = &e->r0_next;
	bool same = true;

	nt->n = 0;
	for (int i = 0; i < m; i++) {
		const struct irdm_contact_site *st = &e->c[idx[i]].site;
		for (uint32_t v = 0; v < st->n_nodes; v++)
			if (st->col[v] != NO_COL && r0_index(nt, st->col[v]) < 0)
				nt->col[nt->n++] = st->col[v];
	}
	same = nt->n == old->n && !memcmp(nt->col, old->col, nt->n * sizeof(uint32_t));
	if (same)
		return;
	for (uint32_t a = 0; a < nt->n; a++)
		for (uint32_t b = 0; b < nt->n; b++) {
			int oa = r0_index(old, nt->col[a]), ob = r0_index(old, nt->col[b]);
			double *blk = nt->blk[a][b];
			if (oa >= 0 && ob >= 0)
				memcpy(blk, old->blk[oa][ob], 9 * sizeof(double));
			else
				repr_r0(e, nt->col[b], nt->col[a], blk);
		}
	old->n = nt->n;
	memcpy(old->col, nt->col, nt->n * sizeof(uint32_t));
	for (uint32_t a = 0; a < nt->n; a++)
		memcpy(old->blk[a], nt->blk[a], nt->n * 9 * sizeof(double));
}

/* R[0] block: displacement at col_disp per force at col_force (fixed: 0). */
const double *tick_r0_block(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp)
{
	static const double zero[9];
	int a = col_disp == NO_COL ? -1 : r0_index(&e->r0, col_disp);
	int b = col_force == NO_COL ? -1 : r0_index(&e->r0, col_force);

	return (a < 0 || b < 0) ? zero : e->r0.blk[a][b];
}
