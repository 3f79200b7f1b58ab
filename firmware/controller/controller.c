/* SPDX-License-Identifier: MIT */
/*
 * The controller: configuration, set-up, and the tick in the order
 * irdm/controller.h gives.  Each step lives in its own file
 * (controller_*.c); this one only orders them and drives the safety state
 * machine.
 */
#include <math.h>
#include <string.h>

#include "controller_priv.h"
#include "irdm/vec3.h"

/* ---- configuration ---- */

void irdm_ctrl_config_default(struct irdm_ctrl_config *cfg)
{
	struct irdm_ctrl_limits *lim = &cfg->limits;

	memset(cfg, 0, sizeof(*cfg));
	cfg->n_devices = 1;
	for (unsigned i = 0; i < IRDM_CTRL_MAX_DEVICES; i++)
		irdm_device_config_default(&cfg->device[i].dev);
	cfg->obj_rot[0] = cfg->obj_rot[4] = cfg->obj_rot[8] = 1;
	lim->max_force_n = cfg->device[0].dev.max_force_n;
	for (unsigned a = 0; a < 3; a++) {
		lim->workspace_min_m[a] = -0.08;
		lim->workspace_max_m[a] = 0.08;
	}
	lim->max_tip_speed_m_per_s = IRDM_CTRL_DEFAULT_MAX_TIP_SPEED_M_PER_S;
	lim->overrun_fault_count = IRDM_CTRL_DEFAULT_OVERRUN_FAULT_COUNT;
	lim->watchdog_us = IRDM_CTRL_DEFAULT_WATCHDOG_US;
	cfg->period_us = IRDM_CTRL_DEFAULT_PERIOD_US;
	irdm_engine_config_haptic(&cfg->engine, cfg->period_us * 1e-6,
				  cfg->device[0].dev.k_max_n_per_m,
				  cfg->device[0].dev.b_device_ns_per_m, lim->max_force_n);
	cfg->engine.max_force_n = IRDM_CTRL_ENGINE_FORCE_GUARD * lim->max_force_n;
	irdm_proxy_config_default(&cfg->proxy);
	cfg->velocity_window = 32;
}

static int positive(double v)
{
	return isfinite(v) && v > 0;
}

static int device_check(const struct irdm_ctrl_device_config *d)
{
	int32_t counts[3];

	if (irdm_device_config_check(&d->dev) || !irdm_v3_finite(d->calib_q_rad) ||
	    irdm_device_counts_from_angles(&d->dev, d->calib_q_rad, counts))
		return IRDM_EINVAL;
	return IRDM_OK;
}

static int limits_check(const struct irdm_ctrl_limits *lim)
{
	if (!positive(lim->max_force_n) || !positive(lim->max_tip_speed_m_per_s) ||
	    !lim->overrun_fault_count || !lim->watchdog_us)
		return IRDM_EINVAL;
	for (unsigned a = 0; a < 3; a++)
		if (!isfinite(lim->workspace_min_m[a]) || !isfinite(lim->workspace_max_m[a]) ||
		    !(lim->workspace_min_m[a] < lim->workspace_max_m[a]))
			return IRDM_EINVAL;
	return IRDM_OK;
}

static int proxy_check(const struct irdm_proxy_config *p)
{
	if (!positive(p->radius_m) || !isfinite(p->max_disp_m) || p->max_disp_m < 0 ||
	    p->max_walk < 1 || p->max_walk > IRDM_CONTACT_MAX_WALK || !(p->mu_s >= 0) ||
	    !isfinite(p->mu_s) || !(p->mu_d >= 0) || !(p->mu_d <= p->mu_s))
		return IRDM_EINVAL;
	return IRDM_OK;
}

int irdm_ctrl_config_check(const struct irdm_ctrl_config *cfg)
{
	if (!cfg || cfg->n_devices < 1 || cfg->n_devices > IRDM_CTRL_MAX_DEVICES)
		return IRDM_EINVAL;
	for (unsigned i = 0; i < cfg->n_devices; i++)
		if (device_check(&cfg->device[i]))
			return IRDM_EINVAL;
	if (ctrl_placement_check(cfg) || limits_check(&cfg->limits) || proxy_check(&cfg->proxy))
		return IRDM_EINVAL;
	if (!cfg->period_us || cfg->engine.max_contacts < cfg->n_devices ||
	    cfg->velocity_window < 2 || cfg->velocity_window > IRDM_VELOCITY_WINDOW_MAX)
		return IRDM_EINVAL;
	return IRDM_OK;
}

int irdm_ctrl_init(struct irdm_ctrl *c, const struct irdm_ctrl_config *cfg,
		   struct irdm_session *s)
{
	double period_s;

	if (!c || !s || !s->img || !s->eng || irdm_ctrl_config_check(cfg))
		return IRDM_EINVAL;
	period_s = cfg->period_us * 1e-6;
	if (!(fabs(s->img->meta->dt_s - period_s) <= 1e-6))
		return IRDM_EINVAL;
	memset(c, 0, sizeof(*c));
	c->cfg = *cfg;
	c->s = s;
	if (!s->cm.hdr)
		return IRDM_EINVAL;
	c->cm = s->cm; /* with the session's face-beyond table */
	for (unsigned i = 0; i < cfg->n_devices; i++)
		for (unsigned j = 0; j < 3; j++)
			if (irdm_velocity_init(&c->dev[i].vel[j], period_s,
					       irdm_device_rad_per_count(&cfg->device[i].dev, j),
					       cfg->velocity_window))
				return IRDM_EINVAL;
	ctrl_placement_init(c);
	irdm_safety_init(&c->safety);
	return IRDM_OK;
}

/* ---- the tick ---- */

/*
 * The fault conditions that fault in a state.  Before calibration a pose
 * means nothing (no range, workspace or speed); out of ENABLED the
 * workspace and speed limits only keep the controller from enabling.
 */
static uint32_t faults_in(int state)
{
	switch (state) {
	case IRDM_SAFETY_INIT:
		return IRDM_FAULT_FATAL & ~(IRDM_FAULT_ENCODER_RANGE | IRDM_FAULT_WORKSPACE |
					    IRDM_FAULT_VELOCITY);
	case IRDM_SAFETY_READY:
		return IRDM_FAULT_FATAL & ~(IRDM_FAULT_WORKSPACE | IRDM_FAULT_VELOCITY);
	case IRDM_SAFETY_ENABLED:
	case IRDM_SAFETY_FAULT:
		return IRDM_FAULT_FATAL;
	default:
		return 0;
	}
}

/* the conditions a pose raises (ctrl_input, ctrl_pose_limits) */
#define POSE_FAULTS (IRDM_FAULT_ENCODER_NAN | IRDM_FAULT_ENCODER_RANGE | IRDM_FAULT_WORKSPACE | \
		     IRDM_FAULT_VELOCITY)

static uint32_t command_faults(uint32_t cmd)
{
	uint32_t f = 0;

	if (cmd & IRDM_CTRL_CMD_SIGNAL)
		f |= IRDM_FAULT_SIGNAL;
	if (cmd & IRDM_CTRL_CMD_HAL_READ_FAILED)
		f |= IRDM_FAULT_HAL_READ;
	if (cmd & IRDM_CTRL_CMD_HAL_WRITE_FAILED)
		f |= IRDM_FAULT_HAL_WRITE;
	if (cmd & IRDM_CTRL_CMD_HAL_FAULT)
		f |= IRDM_FAULT_HAL_FAULT;
	return f;
}

/* Step 3 and 4 for every device: the fault conditions of the poses. */
static uint32_t devices_in(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
			   struct irdm_ctrl_output *out)
{
	uint32_t f = 0;

	for (unsigned i = 0; i < c->cfg.n_devices; i++) {
		c->dev[i].pose_ok = false;
		if (in->cmd & IRDM_CTRL_CMD_HAL_READ_FAILED)
			continue;
		f |= ctrl_input(c, i, in->counts[i], &out->dev[i]);
		if (c->dev[i].pose_ok)
			f |= ctrl_pose_limits(c, &out->dev[i]);
	}
	return f;
}

static void raise_faults(struct irdm_ctrl *c, uint32_t f, struct irdm_ctrl_output *out)
{
	f &= faults_in(c->safety.state);
	if (!f)
		return;
	irdm_safety_fault(&c->safety, f);
	out->new_faults |= f;
}

static void calibrate(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
		      struct irdm_ctrl_output *out)
{
	uint32_t f = 0;

	if (c->safety.state != IRDM_SAFETY_INIT || (in->cmd & IRDM_CTRL_CMD_HAL_READ_FAILED))
		return;
	for (unsigned i = 0; i < c->cfg.n_devices; i++)
		if (ctrl_calibrate(c, i, in->counts[i]))
			return; /* a NaN sample: already raised */
	/* this tick's pose, read again with the new offsets */
	f = devices_in(c, in, out);
	c->active = (c->active & ~POSE_FAULTS) | f;
	if (!(f & IRDM_FAULT_FATAL & ~(IRDM_FAULT_WORKSPACE | IRDM_FAULT_VELOCITY)))
		irdm_safety_calibrated(&c->safety);
}

static void reset(struct irdm_ctrl *c)
{
	int to = c->safety.calibrated ? IRDM_SAFETY_READY : IRDM_SAFETY_INIT;

	/* only the conditions that matter: a cause that still holds, or one
	 * that would fault again at once */
	if (irdm_safety_reset(&c->safety, c->active & (c->safety.faults | faults_in(to))))
		return;
	irdm_engine_reset(c->s->eng);
	ctrl_contacts_end(c);
	for (unsigned i = 0; i < c->cfg.n_devices; i++)
		irdm_v3_zero(c->dev[i].tau_last_nm);
}

/* Step 5, in the order of enum irdm_ctrl_cmd's comment. */
static void commands(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
		     struct irdm_ctrl_output *out)
{
	uint32_t cmd = in->cmd;

	if (cmd & IRDM_CTRL_CMD_SHUTDOWN)
		irdm_safety_shutdown(&c->safety);
	if (cmd & IRDM_CTRL_CMD_CALIBRATE)
		calibrate(c, in, out);
	if (cmd & IRDM_CTRL_CMD_RESET)
		reset(c);
	if (cmd & IRDM_CTRL_CMD_DISABLE)
		irdm_safety_disable(&c->safety);
	/* every condition blocks enabling, the workspace and speed too */
	if ((cmd & IRDM_CTRL_CMD_ENABLE) && !(c->active & IRDM_FAULT_FATAL))
		irdm_safety_enable(&c->safety);
}

/* Steps 6 and 7: contacts and the engine, then the forces. */
static uint32_t forces(struct irdm_ctrl *c, struct irdm_ctrl_output *out)
{
	int state = c->safety.state;
	uint32_t f = 0;

	if (state != IRDM_SAFETY_ENABLED)
		ctrl_contacts_end(c);
	/* the object keeps moving (relaxing) whenever nothing has faulted */
	if (state == IRDM_SAFETY_FAULT || state == IRDM_SAFETY_OFF)
		return 0;
	if (ctrl_contacts(c, out, state == IRDM_SAFETY_ENABLED))
		return IRDM_FAULT_ENGINE;
	if (state != IRDM_SAFETY_ENABLED)
		return 0;
	for (unsigned i = 0; i < c->cfg.n_devices; i++)
		f |= ctrl_force(c, i, &out->dev[i]);
	return f;
}

/* Step 8: zero unless ENABLED; after an overrun, the last safe torque. */
static void torques_out(struct irdm_ctrl *c, struct irdm_ctrl_output *out)
{
	bool on = c->safety.state == IRDM_SAFETY_ENABLED;

	out->held = on && out->overrun;
	for (unsigned i = 0; i < c->cfg.n_devices; i++) {
		double *tau = out->dev[i].torque_nm;

		if (!on)
			irdm_v3_zero(tau);
		else if (out->held)
			memcpy(tau, c->dev[i].tau_last_nm, 3 * sizeof(double));
		memcpy(c->dev[i].tau_last_nm, tau, 3 * sizeof(double));
	}
	if (!on)
		ctrl_contacts_end(c);
}

int irdm_ctrl_tick(struct irdm_ctrl *c, const struct irdm_ctrl_input *in,
		   struct irdm_ctrl_output *out)
{
	uint32_t f;

	if (!c || !in || !out)
		return IRDM_EINVAL;
	memset(out, 0, sizeof(*out));
	out->tick = ++c->tick;
	out->n_devices = c->cfg.n_devices;
	/* the faults that need no pose first: a signal zeroes the torque
	 * whatever the encoders say */
	c->active = ctrl_timing(c, in, out) | command_faults(in->cmd);
	c->active |= devices_in(c, in, out);
	raise_faults(c, c->active, out);
	commands(c, in, out);
	f = forces(c, out);
	raise_faults(c, f, out);
	torques_out(c, out);
	out->state = (int)c->safety.state;
	out->faults = c->safety.faults | (f & IRDM_FAULT_CLAMP);
	out->cause = c->safety.cause;
	return c->safety.state == IRDM_SAFETY_FAULT ? IRDM_EFAULT : IRDM_OK;
}
