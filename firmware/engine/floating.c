/* SPDX-License-Identifier: MIT */
/*
 * A floating object in the tick: the contact system in the world frame (the
 * deformation's W rotated, plus the rigid body's one-tick compliance and
 * free motion), the exact end-of-tick contact positions, the Newton
 * correction for imposed displacements, and the rigid step.
 */
#include <math.h>
#include <string.h>

#include "tick_priv.h"

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
void tick_to_world(struct irdm_engine *e, struct system *s)
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

/*
 * The body-frame material point of contact i at the end of the tick under
 * the body-frame forces fb: its free response u_body plus W_body fb (which
 * holds R[0], and the static correction of a truncated model).
 */
static void deformed_point(const struct irdm_engine *e, const struct system *s, int i,
			   const double *fb, double b[3])
{
	int n = 3 * s->m;
	double u[3];

	for (int r = 0; r < 3; r++) {
		u[r] = s->u_body[i][r];
		for (int k = 0; k < n; k++)
			u[r] += s->w_body[(3 * i + r) * n + k] * fb[k];
	}
	body_point(e, &e->c[s->idx[i]].site, u, b);
}

/*
 * Where a floating contact point really is after the step: its deformed
 * body point carried by the new pose (the solve used the linearised rigid
 * motion).
 */
void tick_floating_disp(const struct irdm_engine *e, const struct system *s, int i, double d[3])
{
	double b[3], x[3];

	deformed_point(e, s, i, s->f_body, b);
	irdm_rigid_body_to_world(&e->rb, b, x);
	irdm_v3_sub(d, x, e->c[s->idx[i]].site.rest_m);
}

/*
 * Floating, displacement imposed (k = 0): the solve used the rigid motion
 * linearised over the tick, which misses the gyroscopic coupling (error
 * O(|w| dt)).  Newton on the true end-of-tick positions, from a trial step
 * of a copy of the body, puts the points on their targets to rounding.
 */
#define NEWTON_STEPS 3

/*
 * The forces f (world; fb in the body frame) push rb, each at its contact
 * point's actual position: the deformed point, static-correction part
 * included, in the pose at the start of the tick (the lever arm; the free
 * response alone would leave out W_body fb and tilt the torque).
 */
static void push_body(const struct irdm_engine *e, const struct system *s, const double *f,
		      const double *fb, struct irdm_rigid_body *rb)
{
	for (int i = 0; i < s->m; i++) {
		double b[3], x[3];
		deformed_point(e, s, i, fb, b);
		irdm_rigid_body_to_world(&e->rb, b, x);
		irdm_rigid_accumulate(rb, &f[3 * i], x);
	}
}

static void trial_positions(const struct irdm_engine *e, const struct system *s, double *x)
{
	struct irdm_rigid_body trial = e->rb;
	double fb[MAX_SOLVE];

	for (int i = 0; i < s->m; i++)
		irdm_rigid_rotate_inverse(&e->rb, &s->f[3 * i], &fb[3 * i]);
	push_body(e, s, s->f, fb, &trial);
	irdm_rigid_step(&trial, e->dt_s);
	for (int i = 0; i < s->m; i++) {
		double b[3];
		deformed_point(e, s, i, fb, b);
		irdm_rigid_body_to_world(&trial, b, &x[3 * i]);
	}
}

void tick_newton_floating(struct irdm_engine *e, struct system *s,
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
int tick_move_rigid(struct irdm_engine *e, const struct system *s)
{
	push_body(e, s, s->f, s->f_body, &e->rb);
	return irdm_rigid_step(&e->rb, e->dt_s);
}
