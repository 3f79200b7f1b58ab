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

#include "repr.h"
#include "tick_priv.h"

/* Spread contact forces over their nodes, merging shared columns. */
static void gather_forces(struct irdm_engine *e, const struct system *s, struct irdm_force_tick *t)
{
	t->n = 0;
	for (int i = 0; i < s->m; i++) {
		const struct irdm_contact_site *st = &e->c[s->idx[i]].site;
		for (uint32_t v = 0; v < st->n_nodes; v++) {
			uint32_t col = st->col[v], n0 = t->n, k;
			if (col == NO_COL || st->weight[v] == 0)
				continue; /* a fixed node takes its share to ground */
			k = tick_col_slot(t->col, &t->n, col);
			if (t->n != n0)
				memset(t->f_n[k], 0, sizeof(t->f_n[k]));
			irdm_v3_axpy(t->f_n[k], st->weight[v], &s->f_body[3 * i]);
		}
	}
}

/* Finite and within IRDM_MAX_TARGET_M on every axis (NaN fails both). */
static bool target_usable(const double p[3])
{
	for (int a = 0; a < 3; a++)
		if (!(fabs(p[a]) <= IRDM_MAX_TARGET_M))
			return false;
	return true;
}

/* Zero force and the engine stopped until a reset; why: a constant string
 * (irdm_engine_fault_reason()). */
static int fault(struct irdm_engine *e, const char *why)
{
	e->faulted = true;
	e->fault_why = why;
	for (unsigned i = 0; i < IRDM_MAX_CONTACTS; i++)
		memset(e->c[i].force_n, 0, sizeof(e->c[i].force_n));
	return IRDM_EFAULT;
}

/* Forces in the object frame (for the deformation history). */
static void body_forces(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		if (FLOATING(e))
			irdm_rigid_rotate_inverse(&e->rb, &s->f[3 * i], &s->f_body[3 * i]);
		else
			memcpy(&s->f_body[3 * i], &s->f[3 * i], 3 * sizeof(double));
	}
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
		memcpy(c->port_disp_prev_m, s->u_free[i], sizeof(c->port_disp_prev_m));
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
		tick_contact_disp(s, i, c->disp_m);
		if (FLOATING(e))
			tick_floating_disp(e, s, i, c->disp_m);
		memcpy(c->force_n, &s->f[3 * i], sizeof(c->force_n));
		memcpy(c->disp_prev_m, c->disp_m, sizeof(c->disp_m));
		memcpy(c->target_prev_m, cmd[s->idx[i]].target_m, sizeof(c->target_prev_m));
	}
}

/* A snapshot for the deformation worker (irdm/deform.h). */
static void publish(struct irdm_engine *e)
{
#if IRDM_CONFIG_DEFORM
	struct irdm_pose pose;
	const struct irdm_pose *pp = tick_pose(e, &pose) ? &pose : NULL;

	if (repr_is_modal(e))
		irdm_deform_publish_modal(e->deform, e->tick, e->x, &e->last, pp);
	else
		irdm_deform_publish_fir(e->deform, e->tick, &e->ring, pp);
#else
	(void)e;
#endif
}

int irdm_engine_tick(struct irdm_engine *e, const struct irdm_contact_cmd *cmd_in)
{
	struct irdm_contact_cmd eff[IRDM_MAX_CONTACTS];
	const struct irdm_contact_cmd *cmd = cmd_in;
	struct system s;

	if (e->faulted)
		return IRDM_EFAULT;
	s.m = 0;
	s.contradictory = false;
	for (unsigned i = 0; i < e->cfg.max_contacts; i++) {
		if (cmd[i].mode == IRDM_CONTACT_OFF && e->c[i].mode != IRDM_CONTACT_OFF)
			irdm_engine_contact_end(e, i);
		if (e->c[i].mode == IRDM_CONTACT_OFF)
			continue;
		if (!target_usable(cmd[i].target_m))
			return fault(e, "a contact target is not finite or beyond IRDM_MAX_TARGET_M");
		s.idx[s.m++] = i;
	}
	if (s.m) {
		tick_history_terms(e, &s);
		tick_assemble(e, &s);
		start_fresh(e, &s);
		cmd = tick_engage(e, &s, cmd_in, eff);
		tick_solve(e, &s, cmd);
		if (s.contradictory)
			return fault(e, "the contact targets contradict each other (rigid contacts on one node, or on fixed nodes, asked for displacements no force can give)");
		tick_release_pulling(e, &s, cmd);
		tick_newton_floating(e, &s, cmd);
		tick_passivity(e, &s);
	}
	tick_port_leak(e, s.m);
	for (int i = 0; i < 3 * s.m; i++)
		if (!isfinite(s.f[i]) ||
		    (e->cfg.max_force_n > 0 && fabs(s.f[i]) > e->cfg.max_force_n))
			return fault(e, isfinite(s.f[i]) ? "a contact force is over max_force_n" :
							   "a contact force is not finite");
	body_forces(e, &s);
	if (FLOATING(e) && tick_move_rigid(e, &s))
		return fault(e, "the floating object's rigid step failed");
	record(e, &s, cmd);
	gather_forces(e, &s, &e->last);
	repr_apply(e, &e->last);
	e->tick++;
	e->stats.ticks++;
	if (e->deform && e->cfg.publish_every && e->tick % e->cfg.publish_every == 0)
		publish(e);
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
	/* a modal image's y = A x is kept current between ticks: the next
	 * tick's free displacement, the one its contacts will be given */
	repr_free_disp(e, col, u);
}
