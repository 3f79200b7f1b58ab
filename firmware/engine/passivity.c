/* SPDX-License-Identifier: MIT */
/*
 * The Hannaford-Ryu passivity observer and controller at the contact ports.
 */

#include <math.h>
#include <string.h>

#include "tick_priv.h"

/*
 * Hannaford-Ryu: E = sum F . du is the work done on the object.  Each port
 * keeps its own observer, but the object is one multi-port and passive iff
 * the total over its ports never goes below zero: a port may hand on what
 * another port put in (two contacts on one node, or on neighbours, pulling
 * different ways).  Run per port, the controller took such a port for an
 * active one and, as its velocity settled, its alpha = -E dt / |du|^2 grew
 * without bound (3e91 N, tests/test_stability_cases.c).  So when the total
 * goes below zero the controller adds the one damping alpha =
 * -E_total dt / sum |du_i|^2 along every port's velocity, which returns
 * the total to zero.
 *
 * du is measured between the displacements the solve gave, before the
 * controller's own force: that force moves the point too (by R[0] times
 * it), and a du taken from the moved point one tick and the solved one the
 * next mixes two ports, so the zero the controller sets would not be the
 * port's energy (a grab on a ringing surface then kept handing energy to
 * the tool, test_passivity).
 *
 * A port that ends (released, or its command turned off) leaves its
 * energy in the total (port_energy_left_j): dropping it left the remaining
 * port's share, negative where energy flowed from one hand to the other
 * through the object, looking like an active object, and the controller's
 * damping kicked the remaining hand.  The observation starts afresh when
 * no port is left (a contact made again on a ringing object sees the
 * ringing as energy it never gave: the controller damps it, test_passivity).
 */
void tick_port_leak(struct irdm_engine *e, int m)
{
	if (!m)
		e->port_energy_left_j = 0;
}

void tick_port_end(struct irdm_engine *e, struct irdm_contact_state *c)
{
	if (c->mode != IRDM_CONTACT_OFF)
		e->port_energy_left_j += c->port_energy_j;
}

/*
 * The damping port i may take: alpha, less where the damper's force would
 * turn a push into a pull (F . n > 0, the force on the object pointing
 * out): the push release ran before the controller, so its force must not
 * undo what that check kept.  A port held back leaves the rest of the
 * deficit to the next ticks.
 */
static double port_alpha(const struct irdm_engine *e, const struct system *s, int i,
			 const double *du, double alpha)
{
	const struct irdm_contact_state *c = &e->c[s->idx[i]];
	double fn = irdm_v3_dot(&s->f[3 * i], s->normal[i]);
	double dn = irdm_v3_dot(du, s->normal[i]) / e->dt_s;

	if (c->mode != IRDM_CONTACT_PUSH || !(dn > 0) || fn + alpha * dn <= 0)
		return alpha;
	return fn < 0 ? -fn / dn : 0;
}

void tick_passivity(struct irdm_engine *e, struct system *s)
{
	double du[IRDM_MAX_CONTACTS][3], v2[IRDM_MAX_CONTACTS];
	double total = e->port_energy_left_j, v2_sum = 0, alpha;

	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		double u[3], work = 0;
		tick_contact_disp(s, i, u);
		v2[i] = 0;
		for (int r = 0; r < 3; r++) {
			du[i][r] = u[r] - c->port_disp_prev_m[r];
			v2[i] += du[i][r] * du[i][r];
			work += s->f[3 * i + r] * du[i][r];
		}
		c->port_energy_j += work;
		c->pc_damping_ns_per_m = 0;
		memcpy(c->port_disp_prev_m, u, sizeof(c->port_disp_prev_m));
		total += c->port_energy_j;
		v2_sum += v2[i];
	}
	if (!e->cfg.passivity_control || total >= 0 || v2_sum == 0)
		return;
	alpha = -total * e->dt_s / v2_sum; /* N s/m, with v = du / dt */
	if (e->cfg.passivity_max_damping_ns_per_m > 0)
		alpha = fmin(alpha, e->cfg.passivity_max_damping_ns_per_m);
	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		double a = port_alpha(e, s, i, du[i], alpha);

		for (int r = 0; r < 3; r++)
			s->f[3 * i + r] += a * du[i][r] / e->dt_s;
		/* one port alone: the total exactly zero, as the law says */
		if (s->m == 1)
			c->port_energy_j = -e->port_energy_left_j;
		else
			c->port_energy_j += a * v2[i] / e->dt_s;
		c->pc_damping_ns_per_m = a;
	}
	e->stats.pc_activations++;
}
