/* SPDX-License-Identifier: MIT */
/*
 * A script meets its device: 'home' becomes the tip's resting point, and a
 * hand may not take the stylus far from where it rests (irdm/sim_user.h,
 * "Home").  Runs once, before the loop.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/sim/sim_user.h"

static int fail(const char *name, unsigned hand, char *err, size_t errlen, const char *fmt, ...)
{
	char reason[192];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(reason, sizeof(reason), fmt, ap);
	va_end(ap);
	if (err && errlen)
		snprintf(err, errlen, "%s: hand %u: %s", name ? name : "user script", hand + 1,
			 reason);
	return IRDM_EFORMAT;
}

/* The first place of the hand, or NULL if it never takes hold. */
static const struct irdm_sim_user_seg *first_place(const struct irdm_sim_user_hand *h)
{
	for (unsigned k = 0; k < h->n; k++)
		if (h->seg[k].active)
			return &h->seg[k];
	return NULL;
}

/* p (home-relative if rel) as an absolute point; 0 if within the range. */
static int resolve(const double p[3], int rel, const double home_m[3], double out[3])
{
	for (int i = 0; i < 3; i++) {
		out[i] = rel ? p[i] + home_m[i] : p[i];
		if (fabs(out[i]) > IRDM_SIM_USER_COORD_MAX_M)
			return -1;
	}
	return 0;
}

int irdm_sim_user_start(struct irdm_sim_user *u, unsigned hand, const double home_m[3],
			const char *name, char *err, size_t errlen)
{
	const struct irdm_sim_user_seg *first;
	struct irdm_sim_user_hand *h;
	double at[3], d2 = 0;

	if (!u || !home_m || hand >= IRDM_SIM_USER_HANDS ||
	    !(isfinite(home_m[0]) && isfinite(home_m[1]) && isfinite(home_m[2])))
		return IRDM_EINVAL;
	h = &u->hand[hand];
	first = first_place(h);
	if (!first)
		return IRDM_OK;
	if (resolve(first->from_m, first->from_home, home_m, at))
		return fail(name, hand, err, errlen, "its first place lies beyond +-%g m",
			    IRDM_SIM_USER_COORD_MAX_M);
	for (int i = 0; i < 3; i++)
		d2 += (at[i] - home_m[i]) * (at[i] - home_m[i]);
	if (sqrt(d2) > IRDM_SIM_USER_GRASP_MAX_M)
		return fail(name, hand, err, errlen,
			    "first placed %.1f cm from where the tip rests at the start (at most "
			    "%.0f cm): 'place %u at home', then move",
			    100 * sqrt(d2),
			    100 * IRDM_SIM_USER_GRASP_MAX_M, hand + 1);
	for (unsigned k = 0; k < h->n; k++) {
		struct irdm_sim_user_seg *s = &h->seg[k];
		double from[3], to[3];

		if (resolve(s->from_m, s->from_home, home_m, from) ||
		    resolve(s->to_m, s->to_home, home_m, to))
			return fail(name, hand, err, errlen, "segment %u, from home, lies beyond "
							     "+-%g m",
				    k + 1, IRDM_SIM_USER_COORD_MAX_M);
	}
	/* all in range: now write them (a refused hand is left as it was) */
	for (unsigned k = 0; k < h->n; k++) {
		struct irdm_sim_user_seg *s = &h->seg[k];

		resolve(s->from_m, s->from_home, home_m, s->from_m);
		resolve(s->to_m, s->to_home, home_m, s->to_m);
		s->from_home = s->to_home = 0;
	}
	h->needs_home = 0;
	return IRDM_OK;
}
