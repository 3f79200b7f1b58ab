/* SPDX-License-Identifier: MIT */
/*
 * The contact system of a tick (grounded object, or the body-frame part of
 * a floating one): the history term U~ of each contact point, and
 *   W_ij = sum_vw a_iv a_jw R0(v <- w)
 * between contacts i (displacement) and j (force), eq. 5-8 and 10-11.
 */
#include <string.h>

#include "repr.h"
#include "tick_priv.h"

/* The free displacement at a site node: from this tick's memo (filled by
 * tick_history_terms), summed afresh only for a node it lacks. */
void tick_free_disp(const struct irdm_engine *e, const struct system *s, uint32_t col,
		    double u[3])
{
	if (col == NO_COL) {
		irdm_v3_zero(u);
		return;
	}
	for (uint32_t k = 0; k < s->n_free; k++)
		if (s->free_col[k] == col) {
			memcpy(u, s->free_u[k], sizeof(s->free_u[k]));
			return;
		}
	repr_free_disp(e, col, u);
}

/* The distinct weighted site nodes of the active contacts, summed in one
 * call (one pass over the FIR ring for all of them). */
static void free_disp_memo(const struct irdm_engine *e, struct system *s)
{
	s->n_free = 0;
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			if (st->col[v] != NO_COL && st->weight[v] != 0)
				tick_col_slot(s->free_col, &s->n_free, st->col[v]);
		}
	}
	repr_free_disps(e, s->n_free, s->free_col, s->free_u);
}

/* W_ij = sum_vw a_iv a_jw R0(v <- w) for contacts i (displacement), j (force). */
static void build_w(struct irdm_engine *e, struct system *s)
{
	int n = 3 * s->m;

	for (int i = 0; i < s->m; i++)
		for (int j = 0; j < s->m; j++) {
			const struct irdm_contact_site *si = &e->c[s->idx[i]].site;
			const struct irdm_contact_site *sj = &e->c[s->idx[j]].site;
			double acc[9] = { 0 };
			for (uint32_t v = 0; v < si->n_nodes; v++)
				for (uint32_t w = 0; w < sj->n_nodes; w++) {
					double a = si->weight[v] * sj->weight[w];
					if (a == 0)
						continue;
					const double *blk = tick_r0_block(e, sj->col[w], si->col[v]);
					for (int k = 0; k < 9; k++)
						acc[k] += a * blk[k];
				}
			for (int r = 0; r < 3; r++)
				for (int c = 0; c < 3; c++)
					s->w_body[(3 * i + r) * n + 3 * j + c] = acc[3 * r + c];
		}
}

void tick_history_terms(struct irdm_engine *e, struct system *s)
{
	free_disp_memo(e, s);
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		double *u = s->u_body[i];
		irdm_v3_zero(u);
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			double uv[3];
			if (st->weight[v] == 0)
				continue;
			tick_free_disp(e, s, st->col[v], uv);
			irdm_v3_axpy(u, st->weight[v], uv);
		}
	}
}

/* W, the free term and the normals in the solve frame. */
void tick_assemble(struct irdm_engine *e, struct system *s)
{
	int n = 3 * s->m;

	tick_r0_refresh(e, s->idx, s->m);
	build_w(e, s);
	if (FLOATING(e)) {
		tick_to_world(e, s);
		return;
	}
	memcpy(s->w, s->w_body, (size_t)n * n * sizeof(double));
	for (int i = 0; i < s->m; i++) {
		memcpy(s->u_free[i], s->u_body[i], sizeof(s->u_free[i]));
		memcpy(s->normal[i], e->c[s->idx[i]].site.normal, sizeof(s->normal[i]));
	}
}

/* u_i = sum_j W_ij F_j + U~_i */
void tick_contact_disp(const struct system *s, int i, double u[3])
{
	int n = 3 * s->m;

	for (int r = 0; r < 3; r++) {
		double acc = s->u_free[i][r];
		for (int k = 0; k < n; k++)
			acc += s->w[(3 * i + r) * n + k] * s->f[k];
		u[r] = acc;
	}
}
