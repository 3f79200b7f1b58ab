/* SPDX-License-Identifier: MIT */
/*
 * Solving the contact forces: with the virtual coupling
 * F_i = k (p_i - u_i) + b ((p_i - p_i') - (u_i - u_i')) / dt,
 *   (W + I / kappa) F = p - U~ - (b / (kappa dt)) (p' - u'),  kappa = k + b / dt;
 * k = 0 imposes u_i = p_i (eq. 8).  All contacts as one system (default) or
 * each vertex alone (the paper's eq. 10-11); push contacts that would pull
 * the tool are released and the rest solved again.
 */
#include <math.h>
#include <string.h>

#include "tick_priv.h"

static double coupling_kappa(const struct irdm_engine *e)
{
	if (e->cfg.coupling_k_n_per_m == 0)
		return INFINITY; /* rigid: the target is the displacement */
	return e->cfg.coupling_k_n_per_m + e->cfg.coupling_b_ns_per_m / e->dt_s;
}

/* Coupled solve of all active contacts (the default). */
static void solve_coupled(struct irdm_engine *e, struct system *s,
			  const struct irdm_contact_cmd *cmd)
{
	int n = 3 * s->m;
	double kappa = coupling_kappa(e), a[MAX_SOLVE * MAX_SOLVE];
	double bterm = isinf(kappa) ? 0 : e->cfg.coupling_b_ns_per_m / (kappa * e->dt_s);

	memcpy(a, s->w, (size_t)n * n * sizeof(double));
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_state *c = &e->c[s->idx[i]];
		const double *p = cmd[s->idx[i]].target_m;
		for (int r = 0; r < 3; r++) {
			if (!isinf(kappa))
				a[(3 * i + r) * n + 3 * i + r] += 1.0 / kappa;
			s->f[3 * i + r] = p[r] - s->u_free[i][r] - bterm * (c->target_prev_m[r] - c->disp_prev_m[r]);
		}
	}
	int rc = irdm_solve_spd(a, s->f, n);
	if (rc)
		e->stats.singular_solves++;
	if (rc < 0)
		s->contradictory = true;
}

/*
 * The paper's eq. 10-11: each vertex v of contact i alone takes
 * F_v = R0(v <- v)^-1 (p_i - U~_v), weighted by a_iv; no cross terms.
 */
static void solve_per_vertex(struct irdm_engine *e, struct system *s,
			     const struct irdm_contact_cmd *cmd)
{
	double kappa = coupling_kappa(e);

	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		const double *p = cmd[s->idx[i]].target_m;
		double *F = &s->f[3 * i];
		irdm_v3_zero(F);
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			double a[9], rhs[3], uv[3];
			if (st->weight[v] == 0 || st->col[v] == NO_COL)
				continue;
			memcpy(a, tick_r0_block(e, st->col[v], st->col[v]), sizeof(a));
			if (!isinf(kappa))
				for (int r = 0; r < 3; r++)
					a[4 * r] += 1.0 / kappa;
			tick_free_disp(e, s, st->col[v], uv);
			irdm_v3_sub(rhs, p, uv);
			int rc = irdm_solve_spd(a, rhs, 3);
			if (rc)
				e->stats.singular_solves++;
			if (rc < 0)
				s->contradictory = true;
			irdm_v3_axpy(F, st->weight[v], rhs);
		}
	}
}

void tick_solve(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd)
{
	if (e->cfg.solve == IRDM_SOLVE_PER_VERTEX)
		solve_per_vertex(e, s, cmd);
	else
		solve_coupled(e, s, cmd);
}

/* Push contacts whose force would pull the tool are released; re-solve. */
void tick_release_pulling(struct irdm_engine *e, struct system *s,
			  const struct irdm_contact_cmd *cmd)
{
	for (int pass = 0; pass < IRDM_MAX_CONTACTS && s->m > 0; pass++) {
		int keep = 0, dropped = 0;
		for (int i = 0; i < s->m; i++) {
			struct irdm_contact_state *c = &e->c[s->idx[i]];
			const double *F = &s->f[3 * i], *nrm = s->normal[i];
			/* F acts on the object; pushing means F . n_out < 0 */
			if (c->mode == IRDM_CONTACT_PUSH && irdm_v3_dot(F, nrm) > 0) {
				tick_port_end(e, c);
				memset(c, 0, sizeof(*c));
				e->stats.releases++;
				dropped = 1;
				continue;
			}
			s->idx[keep] = s->idx[i];
			memcpy(s->u_body[keep], s->u_body[i], sizeof(s->u_body[i]));
			keep++;
		}
		if (!dropped)
			return;
		s->m = keep;
		if (s->m) {
			tick_assemble(e, s);
			tick_solve(e, s, cmd);
		}
	}
}
