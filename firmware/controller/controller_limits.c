/* SPDX-License-Identifier: MIT */
/*
 * Limits the safety state machine acts on: the tick's own timing (watchdog,
 * consecutive overruns; the policy is in irdm/controller.h) and the pose of
 * each device (workspace box, tip speed).
 */
#include "controller_priv.h"

uint32_t ctrl_timing(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
		     struct irdm_ctrl_output *out)
{
	const struct irdm_ctrl_limits *lim = &c->cfg.limits;
	uint64_t period_ns = (uint64_t)c->cfg.period_us * 1000u;
	/* saturating: two huge reports must not wrap into a short tick */
	uint64_t took = in->prev_latency_ns + in->prev_compute_ns;
	uint32_t f = 0;

	if (took < in->prev_latency_ns)
		took = UINT64_MAX;
	if (took > c->longest_ns)
		c->longest_ns = took;
	out->overrun = took > period_ns;
	if (out->overrun) {
		c->overruns++;
		if (c->overrun_run < lim->overrun_fault_count)
			c->overrun_run++;
	} else {
		c->overrun_run = 0;
	}
	out->overrun_run = c->overrun_run;
	if (c->overrun_run >= lim->overrun_fault_count)
		f |= IRDM_FAULT_OVERRUN;
	if (in->prev_compute_ns > (uint64_t)lim->watchdog_us * 1000u)
		f |= IRDM_FAULT_WATCHDOG;
	return f;
}

uint32_t ctrl_pose_limits(const struct irdm_ctrl *c, const struct irdm_ctrl_device_output *o)
{
	const struct irdm_ctrl_limits *lim = &c->cfg.limits;
	uint32_t f = 0;

	for (unsigned a = 0; a < 3; a++)
		if (!(o->tip_m[a] >= lim->workspace_min_m[a] && o->tip_m[a] <= lim->workspace_max_m[a]))
			f |= IRDM_FAULT_WORKSPACE;
	if (!(o->speed_m_per_s <= lim->max_tip_speed_m_per_s))
		f |= IRDM_FAULT_VELOCITY;
	return f;
}
