/* SPDX-License-Identifier: MIT */
/*
 * Soft engagement (irdm_engine_contact_soften()): a contact that begins
 * with the tool already inside the object couples to an anchor that starts
 * at the contact point and moves to the tool along a raised cosine,
 *   anchor = target - w offset,  w = (1 + cos(pi n / N)) / 2,  n = 0..N,
 * offset = target - free displacement at the first tick.  At n = 0 the
 * spring is slack and the damper sees no motion (start_fresh() set the
 * past to the free displacement), so the force starts at zero; the anchor's
 * speed is zero at both ends, so neither the spring nor the damper jumps.
 * This is the force ramp haptic toolkits apply when forces are switched on
 * with the tool in an object, done per contact.
 */
#include <math.h>
#include <string.h>

#include "tick_priv.h"

static double fade_weight(uint32_t n, uint32_t total)
{
	return 0.5 * (1.0 + cos(M_PI * (double)n / (double)total));
}

const struct irdm_contact_cmd *tick_engage(struct irdm_engine *e, const struct system *s,
					   const struct irdm_contact_cmd *cmd,
					   struct irdm_contact_cmd *eff)
{
	bool copied = false;

	for (int i = 0; i < s->m; i++) {
		struct irdm_contact_state *c = &e->c[s->idx[i]];
		double *p = eff[s->idx[i]].target_m;

		if (!c->engage_ticks)
			continue;
		if (!copied) {
			memcpy(eff, cmd, e->cfg.max_contacts * sizeof(*eff));
			copied = true;
		}
		if (c->engage_done == 0)
			irdm_v3_sub(c->engage_offset_m, p, s->u_free[i]);
		irdm_v3_axpy(p, -fade_weight(c->engage_done, c->engage_ticks), c->engage_offset_m);
		if (++c->engage_done > c->engage_ticks)
			c->engage_ticks = 0; /* done: the full coupling from now on */
	}
	return copied ? eff : cmd;
}
