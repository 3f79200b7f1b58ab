/* SPDX-License-Identifier: MIT */
/*
 * The virtual user at a time t: the hand's target (a minimum-jerk blend
 * inside a segment) and its spring-damper force (irdm/sim_user.h).
 * Pure arithmetic on the loaded script: called every tick.
 */
#include <math.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/sim/sim_user.h"

/* Minimum jerk: s(0) = 0, s(1) = 1 exactly; s' = s'' = 0 at both ends. */
static double min_jerk(double u)
{
	return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

/*
 * The last segment starting at or before t (several may share a start: the
 * last of them is the hand's state), or NULL before the first.  Binary
 * search: a tick's cost does not grow with the script's length.
 */
static const struct irdm_sim_user_seg *segment_at(const struct irdm_sim_user_hand *h,
						  double t_s)
{
	unsigned lo = 0, hi = h->n; /* first index with t0 > t lies in [lo, hi] */

	while (lo < hi) {
		unsigned mid = lo + (hi - lo) / 2;

		if (h->seg[mid].t0_s <= t_s)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo ? &h->seg[lo - 1] : NULL;
}

static void blend(const struct irdm_sim_user_seg *s, double t_s, double target_m[3])
{
	double w;
	int i;

	if (t_s >= s->t1_s) {
		memcpy(target_m, s->to_m, 3 * sizeof(double));
		return;
	}
	w = min_jerk((t_s - s->t0_s) / (s->t1_s - s->t0_s));
	/*
	 * from + w (to - from), not (1 - w) from + w to: a coordinate the move
	 * does not change stays bit for bit where it is.  The keyframes are
	 * exact anyway: u = 0 gives from, and t >= t1 returns to above.
	 */
	for (i = 0; i < 3; i++)
		target_m[i] = s->from_m[i] + w * (s->to_m[i] - s->from_m[i]);
}

/* The hand's segment at t (NULL before its first) and its target. */
static int evaluate(const struct irdm_sim_user *u, unsigned hand, double t_s, double target_m[3],
		    const struct irdm_sim_user_seg **seg)
{
	if (!u || !target_m || hand >= IRDM_SIM_USER_HANDS || !isfinite(t_s) ||
	    u->hand[hand].needs_home)
		return IRDM_EINVAL;
	*seg = segment_at(&u->hand[hand], t_s);
	if (*seg)
		blend(*seg, t_s, target_m);
	else
		memset(target_m, 0, 3 * sizeof(double));
	return IRDM_OK;
}

int irdm_sim_user_target(const struct irdm_sim_user *u, unsigned hand, double t_s,
			 double target_m[3], int *active)
{
	const struct irdm_sim_user_seg *s;
	int ret;

	if (!active)
		return IRDM_EINVAL;
	ret = evaluate(u, hand, t_s, target_m, &s);
	if (!ret)
		*active = s && s->active;
	return ret;
}

int irdm_sim_user_hand_force(const struct irdm_sim_user *u, unsigned hand, double t_s,
			     const double tip_m[3], const double tip_vel_m_per_s[3],
			     double force_n[3])
{
	const struct irdm_sim_user_seg *s;
	double target_m[3];
	int ret, i;

	if (!force_n)
		return IRDM_EINVAL;
	memset(force_n, 0, 3 * sizeof(double));
	if (!tip_m || !tip_vel_m_per_s)
		return IRDM_EINVAL;
	ret = evaluate(u, hand, t_s, target_m, &s);
	if (ret)
		return ret;
	for (i = 0; i < 3; i++)
		if (!isfinite(tip_m[i]) || !isfinite(tip_vel_m_per_s[i]))
			return IRDM_EFAULT;
	if (!s || !s->active)
		return IRDM_OK;
	for (i = 0; i < 3; i++)
		force_n[i] = s->k_n_per_m * (target_m[i] - tip_m[i]) -
			     s->b_ns_per_m * tip_vel_m_per_s[i];
	return IRDM_OK;
}
