/* SPDX-License-Identifier: MIT */
/*
 * One tick of the force engine.
 *
 * For the active contacts i (points with barycentric weights a_iv on their
 * site nodes v), with U~ the history term and R0 the first response block:
 *   u_i = sum_j W_ij F_j + U~_i,  W_ij = sum_vw a_iv a_jw R0(v <- w),
 *   U~_i = sum_v a_iv U~_v                        (eq. 5-8, 10-11)
 * and the virtual coupling F_i = k (p_i - u_i) + b ((p_i - p_i') - (u_i - u_i')) / dt
 * gives (W + I / kappa) F = p - U~ - (b / (kappa dt)) (p' - u'), kappa = k + b / dt;
 * k = 0 imposes u_i = p_i (eq. 8).
 *
 * A floating object is solved in the world frame: the deformation's W is
 * rotated, the rigid body adds its one-tick compliance at the contact
 * points and its free motion to the history term, and the solved forces
 * drive both the deformation (in the body frame) and the rigid motion.
 */
#include <math.h>
#include <string.h>

#include "engine_priv.h"

static int r0_index(const struct r0_table *t, uint32_t col)
{
	for (uint32_t k = 0; k < t->n; k++)
		if (t->col[k] == col)
			return (int)k;
	return -1;
}

/*
 * Bring the R[0] table to the nodes of the active sites: blocks between
 * nodes already there are kept, the others computed (9 K multiply-adds
 * each for a modal image, a read for FIR).  Nothing happens while the
 * sites stay the same.
 */
static void r0_refresh(struct irdm_engine *e, const unsigned *idx, int m)
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
			else if (e->repr == IRDM_REPR_MODAL)
				irdm_modal_r0(e, nt->col[b], nt->col[a], blk);
			else
				irdm_fir_r0(e, nt->col[b], nt->col[a], blk);
		}
	old->n = nt->n;
	memcpy(old->col, nt->col, nt->n * sizeof(uint32_t));
	for (uint32_t a = 0; a < nt->n; a++)
		memcpy(old->blk[a], nt->blk[a], nt->n * 9 * sizeof(double));
}

/* R[0] block: displacement at col_disp per force at col_force (fixed: 0). */
static const double *r0_block(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp)
{
	static const double zero[9];
	int a = col_disp == NO_COL ? -1 : r0_index(&e->r0, col_disp);
	int b = col_force == NO_COL ? -1 : r0_index(&e->r0, col_force);

	return (a < 0 || b < 0) ? zero : e->r0.blk[a][b];
}

static void free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
	if (col == NO_COL) {
		irdm_v3_zero(u);
		return;
	}
	if (e->repr == IRDM_REPR_MODAL)
		irdm_modal_free_disp(e, col, u);
	else
		irdm_fir_free_disp(e, col, u);
}

struct system {
	int m;                              /* active contacts */
	unsigned idx[IRDM_MAX_CONTACTS];    /* their slots */
	double u_body[IRDM_MAX_CONTACTS][3];    /* history term, object (body) frame */
	double w_body[MAX_SOLVE * MAX_SOLVE];   /* W in the object frame */
	/* in the solve frame: the object frame, or the world for a floating object */
	double u_free[IRDM_MAX_CONTACTS][3];
	double normal[IRDM_MAX_CONTACTS][3];
	double w[MAX_SOLVE * MAX_SOLVE];    /* row-major 3m x 3m */
	double f[MAX_SOLVE];
	double f_body[MAX_SOLVE];
	double x_now[IRDM_MAX_CONTACTS][3];     /* floating: world position of each point */
};

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
					const double *blk = r0_block(e, sj->col[w], si->col[v]);
					for (int k = 0; k < 9; k++)
						acc[k] += a * blk[k];
				}
			for (int r = 0; r < 3; r++)
				for (int c = 0; c < 3; c++)
					s->w_body[(3 * i + r) * n + 3 * j + c] = acc[3 * r + c];
		}
}

/* The body-frame material point of a contact: rest point about the COM plus u. */
static void body_point(const struct irdm_engine *e, const struct irdm_contact_site *st,
		       const double u[3], double b[3])
{
	irdm_v3_sub(b, st->rest_m, e->com_rest_m);
	irdm_v3_add(b, b, u);
}

static void rotation(const struct irdm_engine *e, double R[9])
{
	for (int k = 0; k < 3; k++) {
		double ek[3] = { 0, 0, 0 }, col[3];
		ek[k] = 1;
		irdm_rigid_rotate(&e->rb, ek, col);
		for (int r = 0; r < 3; r++)
			R[3 * r + k] = col[r];
	}
}

/*
 * World-frame system of a floating object: W_ij = R W_body,ij R^T + the
 * rigid body's compliance between the points; the free term is where the
 * free motion takes each point, as a displacement from its rest position.
 */
static void to_world(struct irdm_engine *e, struct system *s)
{
	int n = 3 * s->m;
	double R[9], arm[IRDM_MAX_CONTACTS][3], com[3], zero[3] = { 0, 0, 0 };

	rotation(e, R);
	irdm_rigid_body_to_world(&e->rb, zero, com);
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		double b[3], p[3];
		body_point(e, st, s->u_body[i], b);
		irdm_rigid_body_to_world(&e->rb, b, s->x_now[i]);
		irdm_rigid_predict_point(&e->rb, b, e->dt_s, p);
		irdm_rigid_rotate(&e->rb, st->normal, s->normal[i]);
		irdm_v3_sub(s->u_free[i], p, st->rest_m);
		irdm_v3_sub(arm[i], s->x_now[i], com);
	}
	for (int i = 0; i < s->m; i++)
		for (int j = 0; j < s->m; j++) {
			double c[9];
			irdm_rigid_point_compliance(&e->rb, arm[j], arm[i], e->dt_s, c);
			for (int r = 0; r < 3; r++)
				for (int q = 0; q < 3; q++) {
					double v = c[3 * r + q];
					for (int k = 0; k < 3; k++)
						for (int l = 0; l < 3; l++)
							v += R[3 * r + k] * s->w_body[(3 * i + k) * n + 3 * j + l] * R[3 * q + l];
					s->w[(3 * i + r) * n + 3 * j + q] = v;
				}
		}
}

/* W, the free term and the normals in the solve frame. */
static void assemble(struct irdm_engine *e, struct system *s)
{
	int n = 3 * s->m;

	r0_refresh(e, s->idx, s->m);
	build_w(e, s);
	if (e->floating) {
		to_world(e, s);
		return;
	}
	memcpy(s->w, s->w_body, (size_t)n * n * sizeof(double));
	for (int i = 0; i < s->m; i++) {
		memcpy(s->u_free[i], s->u_body[i], sizeof(s->u_free[i]));
		memcpy(s->normal[i], e->c[s->idx[i]].site.normal, sizeof(s->normal[i]));
	}
}

static void history_terms(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		double *u = s->u_body[i];
		irdm_v3_zero(u);
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			double uv[3];
			if (st->weight[v] == 0)
				continue;
			free_disp(e, st->col[v], uv);
			irdm_v3_axpy(u, st->weight[v], uv);
		}
	}
}

static double coupling_kappa(const struct irdm_engine *e)
{
	if (e->cfg.coupling_k_n_per_m == 0)
		return INFINITY;            /* rigid: the target is the displacement */
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
			s->f[3 * i + r] = p[r] - s->u_free[i][r]
					  - bterm * (c->target_prev_m[r] - c->disp_prev_m[r]);
		}
	}
	if (irdm_solve_spd(a, s->f, n))
		e->stats.singular_solves++;
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
			memcpy(a, r0_block(e, st->col[v], st->col[v]), sizeof(a));
			if (!isinf(kappa))
				for (int r = 0; r < 3; r++)
					a[4 * r] += 1.0 / kappa;
			free_disp(e, st->col[v], uv);
			irdm_v3_sub(rhs, p, uv);
			if (irdm_solve_spd(a, rhs, 3))
				e->stats.singular_solves++;
			irdm_v3_axpy(F, st->weight[v], rhs);
		}
	}
}

static void solve(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd)
{
	if (e->cfg.solve == IRDM_SOLVE_PER_VERTEX)
		solve_per_vertex(e, s, cmd);
	else
		solve_coupled(e, s, cmd);
}

/* Push contacts whose force would pull the tool are released; re-solve. */
static void release_pulling(struct irdm_engine *e, struct system *s,
			    const struct irdm_contact_cmd *cmd)
{
	for (int pass = 0; pass < IRDM_MAX_CONTACTS && s->m > 0; pass++) {
		int keep = 0, dropped = 0;
		for (int i = 0; i < s->m; i++) {
			struct irdm_contact_state *c = &e->c[s->idx[i]];
			const double *F = &s->f[3 * i], *nrm = s->normal[i];
			/* F acts on the object; pushing means F . n_out < 0 */
			if (c->mode == IRDM_CONTACT_PUSH && irdm_v3_dot(F, nrm) > 0) {
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
			assemble(e, s);
			solve(e, s, cmd);
		}
	}
}

/* u_i = sum_j W_ij F_j + U~_i */
static void contact_disp(const struct system *s, int i, double u[3])
{
	int n = 3 * s->m;

	for (int r = 0; r < 3; r++) {
		double acc = s->u_free[i][r];
		for (int k = 0; k < n; k++)
			acc += s->w[(3 * i + r) * n + k] * s->f[k];
		u[r] = acc;
	}
}

/*
 * Hannaford-Ryu at each contact port: E = sum F . du is the work done on
 * the object.  When the model has given out more than it received (E < 0)
 * the controller adds the damping alpha = -E / (dt |v|^2) along the
 * contact velocity, which returns E to zero.
 */
static void passivity(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		double u[3], du[3], v2 = 0, work = 0;
		contact_disp(s, i, u);
		for (int r = 0; r < 3; r++) {
			du[r] = u[r] - c->disp_prev_m[r];
			v2 += du[r] * du[r];
			work += s->f[3 * i + r] * du[r];
		}
		double energy = c->port_energy_j + work;
		c->pc_damping_ns_per_m = 0;
		if (e->cfg.passivity_control && energy < 0 && v2 > 0) {
			double alpha = -energy * e->dt_s / v2;   /* N s/m, with v = du / dt */
			for (int r = 0; r < 3; r++)
				s->f[3 * i + r] += alpha * du[r] / e->dt_s;
			energy = 0;
			c->pc_damping_ns_per_m = alpha;
			e->stats.pc_activations++;
		}
		c->port_energy_j = energy;
	}
}

/* Spread contact forces over their nodes, merging shared columns. */
static void gather_forces(struct irdm_engine *e, const struct system *s, struct irdm_force_tick *t)
{
	t->n = 0;
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			uint32_t col = st->col[v], k;
			if (col == NO_COL || st->weight[v] == 0)
				continue;           /* a fixed node takes its share to ground */
			for (k = 0; k < t->n && t->col[k] != col; k++)
				;
			if (k == t->n) {
				t->col[t->n] = col;
				memset(t->f_n[t->n], 0, sizeof(t->f_n[t->n]));
				t->n++;
			}
			irdm_v3_axpy(t->f_n[k], st->weight[v], &s->f_body[3 * i]);
		}
	}
}

static int fault(struct irdm_engine *e)
{
	e->faulted = true;
	for (unsigned i = 0; i < IRDM_MAX_CONTACTS; i++)
		memset(e->c[i].force_n, 0, sizeof(e->c[i].force_n));
	return IRDM_EFAULT;
}

/*
 * Where a floating contact point really is after the step: its body-frame
 * deformation u_body + W_body F_body, carried by the new pose (the solve
 * used the linearised rigid motion).
 */
static void floating_disp(const struct irdm_engine *e, const struct system *s, int i, double d[3])
{
	const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
	int n = 3 * s->m;
	double u[3], b[3], x[3];

	for (int r = 0; r < 3; r++) {
		u[r] = s->u_body[i][r];
		for (int k = 0; k < n; k++)
			u[r] += s->w_body[(3 * i + r) * n + k] * s->f_body[k];
	}
	body_point(e, st, u, b);
	irdm_rigid_body_to_world(&e->rb, b, x);
	irdm_v3_sub(d, x, st->rest_m);
}

/* Forces in the object frame (for the deformation history). */
static void body_forces(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		if (e->floating)
			irdm_rigid_rotate_inverse(&e->rb, &s->f[3 * i], &s->f_body[3 * i]);
		else
			memcpy(&s->f_body[3 * i], &s->f[3 * i], 3 * sizeof(double));
	}
}

/*
 * Floating, displacement imposed (k = 0): the solve used the rigid motion
 * linearised over the tick, which misses the gyroscopic coupling (error
 * O(|w| dt)).  Newton on the true end-of-tick positions, from a trial step
 * of a copy of the body, puts the points on their targets to rounding.
 */
#define NEWTON_STEPS 3

static void trial_positions(const struct irdm_engine *e, const struct system *s, double *x)
{
	struct irdm_rigid_body trial = e->rb;
	int n = 3 * s->m;
	double fb[MAX_SOLVE];

	for (int i = 0; i < s->m; i++) {
		irdm_rigid_accumulate(&trial, &s->f[3 * i], s->x_now[i]);
		irdm_rigid_rotate_inverse(&e->rb, &s->f[3 * i], &fb[3 * i]);
	}
	irdm_rigid_step(&trial, e->dt_s);
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		double u[3], b[3];
		for (int r = 0; r < 3; r++) {
			u[r] = s->u_body[i][r];
			for (int k = 0; k < n; k++)
				u[r] += s->w_body[(3 * i + r) * n + k] * fb[k];
		}
		body_point(e, st, u, b);
		irdm_rigid_body_to_world(&trial, b, &x[3 * i]);
	}
}

static void newton_floating(struct irdm_engine *e, struct system *s,
			    const struct irdm_contact_cmd *cmd)
{
	int n = 3 * s->m;

	if (!e->floating || e->cfg.coupling_k_n_per_m != 0 || e->cfg.solve != IRDM_SOLVE_COUPLED)
		return;
	for (int it = 0; it < NEWTON_STEPS; it++) {
		double x[MAX_SOLVE], r[MAX_SOLVE], a[MAX_SOLVE * MAX_SOLVE], big = 0;
		trial_positions(e, s, x);
		for (int i = 0; i < s->m; i++)
			for (int k = 0; k < 3; k++) {
				const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
				r[3 * i + k] = st->rest_m[k] + cmd[s->idx[i]].target_m[k] - x[3 * i + k];
				big = fmax(big, fabs(r[3 * i + k]));
			}
		if (big < 1e-15)
			return;
		memcpy(a, s->w, (size_t)n * n * sizeof(double));
		irdm_solve_spd(a, r, n);
		for (int k = 0; k < n; k++)
			s->f[k] += r[k];
	}
}

/* The contact forces push the rigid body for one tick. */
static int move_rigid(struct irdm_engine *e, const struct system *s)
{
	for (int i = 0; i < s->m; i++)
		irdm_rigid_accumulate(&e->rb, &s->f[3 * i], s->x_now[i]);
	return irdm_rigid_step(&e->rb, e->dt_s);
}

/* A contact that just began: its past target and displacement are where
 * the point is now, so neither the coupling damper nor the passivity
 * observer sees a jump. */
static void start_fresh(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		if (!c->fresh)
			continue;
		memcpy(c->disp_prev_m, s->u_free[i], sizeof(c->disp_prev_m));
		memcpy(c->target_prev_m, s->u_free[i], sizeof(c->target_prev_m));
		c->fresh = 0;
	}
}

static void record(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd)
{
	for (unsigned i = 0; i < IRDM_MAX_CONTACTS; i++)
		if (e->c[i].mode == IRDM_CONTACT_OFF)
			memset(e->c[i].force_n, 0, sizeof(e->c[i].force_n));
	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		contact_disp(s, i, c->disp_m);
		if (e->floating)
			floating_disp(e, s, i, c->disp_m);
		memcpy(c->force_n, &s->f[3 * i], sizeof(c->force_n));
		memcpy(c->disp_prev_m, c->disp_m, sizeof(c->disp_m));
		memcpy(c->target_prev_m, cmd[s->idx[i]].target_m, sizeof(c->target_prev_m));
	}
}

int irdm_engine_tick(struct irdm_engine *e, const struct irdm_contact_cmd *cmd)
{
	struct system s;

	if (e->faulted)
		return IRDM_EFAULT;
	s.m = 0;
	for (unsigned i = 0; i < e->cfg.max_contacts; i++) {
		if (cmd[i].mode == IRDM_CONTACT_OFF && e->c[i].mode != IRDM_CONTACT_OFF)
			irdm_engine_contact_end(e, i);
		if (e->c[i].mode == IRDM_CONTACT_OFF)
			continue;
		if (!irdm_v3_finite(cmd[i].target_m))
			return fault(e);
		s.idx[s.m++] = i;
	}
	if (e->repr == IRDM_REPR_MODAL)
		irdm_modal_begin_tick(e);
	if (s.m) {
		history_terms(e, &s);
		assemble(e, &s);
		start_fresh(e, &s);
		solve(e, &s, cmd);
		release_pulling(e, &s, cmd);
		newton_floating(e, &s, cmd);
		passivity(e, &s);
	}
	for (int i = 0; i < 3 * s.m; i++)
		if (!isfinite(s.f[i]) ||
		    (e->cfg.max_force_n > 0 && fabs(s.f[i]) > e->cfg.max_force_n))
			return fault(e);
	body_forces(e, &s);
	if (e->floating && move_rigid(e, &s))
		return fault(e);
	record(e, &s, cmd);
	gather_forces(e, &s, &e->last);
	if (e->repr == IRDM_REPR_MODAL)
		irdm_modal_apply(e, &e->last);
	else
		irdm_fir_apply(e, &e->last);
	e->tick++;
	e->stats.ticks++;
	if (e->deform && e->cfg.publish_every && e->tick % e->cfg.publish_every == 0) {
		struct irdm_pose pose, *pp = NULL;
		if (e->floating) {
			irdm_rigid_pose(&e->rb, &pose);
			pp = &pose;
		}
		if (e->repr == IRDM_REPR_MODAL)
			irdm_deform_publish_modal(e->deform, e->tick, e->x, &e->last, pp);
		else
			irdm_deform_publish_fir(e->deform, e->tick, &e->ring, pp);
	}
	return IRDM_OK;
}

void irdm_engine_node_disp(const struct irdm_engine *e, uint32_t row, double u[3])
{
	/*
	 * The free response: where the node will be at the next sample if no
	 * new force acts.  That is the surface a new contact meets.
	 */
	uint32_t col = row < e->n_nodes ? e->col_of_row[row] : NO_COL;

	irdm_v3_zero(u);
	if (col == NO_COL)
		return;
	if (e->repr == IRDM_REPR_FIR) {
		irdm_fir_free_disp(e, col, u);
		return;
	}
	const struct irdm_mode *m = e->img->modes;
	const double *phi = &e->phi[(size_t)col * 3 * e->K];
	for (uint32_t k = 0; k < e->K; k++) {
		double yq = m[k].a[0] * e->x[2 * k] + m[k].a[1] * e->x[2 * k + 1];
		for (int i = 0; i < 3; i++)
			u[i] += phi[(size_t)i * e->K + k] * yq;
	}
}
