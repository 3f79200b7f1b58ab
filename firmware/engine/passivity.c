/* SPDX-License-Identifier: MIT */
/*
 * The Hannaford-Ryu passivity observer and controller at each contact port.
 */


#include <string.h>

#include "tick_priv.h"

/*
 * Hannaford-Ryu at each contact port: E = sum F . du is the work done on
 * the object.  When the model has given out more than it received (E < 0)
 * the controller adds the damping alpha = -E / (dt |v|^2) along the
 * contact velocity, which returns E to zero.  du is measured between the
 * displacements the solve gave, before the controller's own force: that
 * force moves the point too (by R[0] times it), and a du taken from the
 * moved point one tick and the solved one the next mixes two ports, so
 * the zero the controller sets would not be the port's energy (a grab on
 * a ringing surface then kept handing energy to the tool, test_passivity).
 */
void tick_passivity(struct irdm_engine *e, struct system *s)
{
	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		double u[3], du[3], v2 = 0, work = 0;
		tick_contact_disp(s, i, u);
		for (int r = 0; r < 3; r++) {
			du[r] = u[r] - c->port_disp_prev_m[r];
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
		memcpy(c->port_disp_prev_m, u, sizeof(c->port_disp_prev_m));
	}
}
