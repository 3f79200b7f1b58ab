/* SPDX-License-Identifier: MIT */
/* The sim back-end of the HAL (irdm/hal_sim.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/sim/hal_canemu.h"
#include "irdm/sim/hal_sim.h"

#include "hal_sim_hand.h"

enum sim_state { SIM_CLOSED = 0,
		 SIM_OPEN,
		 SIM_RUNNING,
		 SIM_OFF };

struct sim_data {
	struct irdm_sim_device arm;
	enum sim_state state;
	uint32_t faults;
	uint64_t seq;
	struct sim_hand hand; /* the virtual user's, if one holds the arm */
};

static struct sim_data *data_of(struct irdm_hal_dev *dev)
{
	return dev->data;
}

#define SP(member) IRDM_OPT_FIELD(struct irdm_sim_params, member)
#define UPTO(lo, hi) .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = (lo), .max = (hi)

/* Its hal_options (docs/hal-options.md); the rest of the arm's figures are
 * irdm_sim_params_default()'s. */
static const struct irdm_opt sim_opts[] = {
	{ .name = "write_delay", .type = IRDM_OPT_UNSIGNED, SP(write_delay_ticks), UPTO(0, IRDM_SIM_DELAY_MAX), .metavar = "K", .help = "ticks a written torque waits on the simulated bus", IRDM_OPT_DEFAULT(IRDM_SIM_DEFAULT_DELAY_TICKS) },
	{ .name = "read_delay", .type = IRDM_OPT_UNSIGNED, SP(read_delay_ticks), UPTO(0, IRDM_SIM_DELAY_MAX), .metavar = "K", .help = "ticks an encoder sample waits on the simulated bus", IRDM_OPT_DEFAULT(IRDM_SIM_DEFAULT_DELAY_TICKS) },
	{ .name = "substeps", .type = IRDM_OPT_UNSIGNED, SP(substeps), UPTO(1, IRDM_SIM_SUBSTEPS_MAX), .metavar = "N", .help = "integration (RK4) steps of the arm per tick", IRDM_OPT_DEFAULT(IRDM_SIM_DEFAULT_SUBSTEPS) },
	{ .name = "end_stops", .type = IRDM_OPT_INT, SP(end_stops), UPTO(0, 1), .metavar = "0 | 1", .help = "the arm's mechanical stops just inside count_min..count_max; 0: an arm "
													    "that can leave its encoders' range (a test of that fault)",
	  IRDM_OPT_DEFAULT(IRDM_SIM_DEFAULT_END_STOPS) },
};

static const struct irdm_opt_table sim_table = {
	.what = "sim option",
	.see = "docs/hal-options.md",
	.opts = sim_opts,
	.n_opts = sizeof(sim_opts) / sizeof(sim_opts[0]),
};

/* Space, comma or tab separated "key=value" words into p (defaults first). */
static int parse_options(const char *options, const char *where, struct irdm_sim_params *p,
			 char *err, size_t errlen)
{
	irdm_sim_params_default(p);
	return irdm_opt_parse_words(&sim_table, p, where, options, " ,\t", err, errlen) ?
		       IRDM_EINVAL :
		       IRDM_OK;
}

static int sim_check_options(const char *options, const char *where, char *err, size_t errlen)
{
	struct irdm_sim_params p;

	return parse_options(options, where, &p, err, errlen);
}

/* Why the simulated arm refuses this device (the board passed its own checks). */
static void arm_why(const struct irdm_device_config *dev, const struct irdm_sim_params *p,
		    char *why, size_t len)
{
	if (irdm_device_config_check(dev)) {
		snprintf(why, len, "the arm is not valid (irdm_device_config_check)");
		return;
	}
	for (unsigned i = 0; i < 3; i++) {
		double span = fabs(irdm_device_rad_per_count(dev, i)) *
			      ((double)dev->count_max[i] - dev->count_min[i] + 1.0);

		if (p->end_stops && !(span > 2 * p->stop_inset_rad)) {
			snprintf(why, len, "joint %u: count_min..count_max spans %.3g rad, end stops "
					   "need > %.3g (end_stops=0)",
				 i + 1, span, 2 * p->stop_inset_rad);
			return;
		}
	}
	snprintf(why, len, "the start pose is outside count_min..count_max");
}

static int sim_open(struct irdm_hal_dev *dev)
{
	struct sim_data *d = data_of(dev);
	const struct irdm_hal_config *cfg = dev->config;
	struct irdm_sim_params p;
	int rc;

	if (d->state != SIM_CLOSED)
		return IRDM_EBUSY;
	if (!cfg->device || !(isfinite(cfg->period_s) && cfg->period_s > 0))
		return IRDM_EINVAL;
	rc = parse_options(cfg->options, "hal_options", &p, dev->why, sizeof(dev->why));
	if (rc != IRDM_OK)
		return rc;
	rc = irdm_sim_device_init(&d->arm, cfg->device, &p);
	if (rc != IRDM_OK) {
		arm_why(cfg->device, &p, dev->why, sizeof(dev->why));
		return rc;
	}
	d->faults = 0;
	d->seq = 0;
	d->hand.user = NULL;
	d->state = SIM_OPEN;
	return IRDM_OK;
}

static int sim_start(struct irdm_hal_dev *dev)
{
	struct sim_data *d = data_of(dev);

	if (d->state == SIM_CLOSED)
		return IRDM_EINVAL;
	if (d->faults)
		return IRDM_EHW;
	d->state = SIM_RUNNING;
	return IRDM_OK;
}

static int sim_read(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st)
{
	struct sim_data *d = data_of(dev);
	int32_t counts[IRDM_HAL_JOINTS];
	int rc;

	if (d->state == SIM_CLOSED)
		return IRDM_EINVAL;
	sim_hand_push(&d->hand, &d->arm);
	if (d->faults)
		return IRDM_EHW;
	rc = irdm_sim_device_step(&d->arm, dev->config->period_s);
	if (rc == IRDM_OK)
		rc = irdm_sim_device_read_counts(&d->arm, counts);
	if (rc != IRDM_OK)
		return IRDM_EFAULT;
	memcpy(st->counts, counts, sizeof(st->counts));
	st->seq = ++d->seq;
	return IRDM_OK;
}

static int sim_write(struct irdm_hal_dev *dev, const double tau_nm[IRDM_HAL_JOINTS])
{
	struct sim_data *d = data_of(dev);

	if (d->state != SIM_RUNNING)
		return IRDM_EINVAL;
	if (d->faults)
		return IRDM_EHW;
	return irdm_sim_device_set_torque(&d->arm, tau_nm);
}

static int sim_safe_off(struct irdm_hal_dev *dev)
{
	struct sim_data *d = data_of(dev);

	irdm_sim_device_torque_off(&d->arm);
	if (d->state == SIM_RUNNING)
		d->state = SIM_OFF;
	return IRDM_OK;
}

/* Plain stores: the arm's commanded torque zero (async-signal-safe). */
static int sim_emergency_off(struct irdm_hal_dev *dev)
{
	irdm_sim_device_torque_off(&data_of(dev)->arm);
	return IRDM_OK;
}

static int sim_poll(struct irdm_hal_dev *dev, uint32_t *faults)
{
	struct sim_data *d = data_of(dev);

	if (d->state == SIM_CLOSED)
		return IRDM_EINVAL;
	*faults = d->faults;
	return d->faults ? IRDM_EHW : IRDM_OK;
}

static void sim_close(struct irdm_hal_dev *dev)
{
	struct sim_data *d = data_of(dev);

	irdm_sim_device_torque_off(&d->arm);
	d->state = SIM_CLOSED;
}

static const struct irdm_hal_ops sim_ops = {
	.open = sim_open,
	.start = sim_start,
	.read = sim_read,
	.write = sim_write,
	.safe_off = sim_safe_off,
	.poll = sim_poll,
	.close = sim_close,
	.emergency_off = sim_emergency_off,
};

const struct irdm_hal_backend irdm_hal_sim_backend = {
	.name = "sim",
	.ops = &sim_ops,
	.data_size = sizeof(struct sim_data),
	.options = &sim_table,
	.check_options = sim_check_options,
};

static int is_open_sim(const struct irdm_hal_dev *dev)
{
	return dev && dev->backend == &irdm_hal_sim_backend &&
	       ((const struct sim_data *)dev->data)->state != SIM_CLOSED;
}

int irdm_hal_sim_inject_fault(struct irdm_hal_dev *dev, uint32_t faults)
{
	if (!is_open_sim(dev))
		return IRDM_EINVAL;
	data_of(dev)->faults |= faults;
	irdm_sim_device_torque_off(&data_of(dev)->arm);
	return IRDM_OK;
}

struct irdm_sim_device *irdm_hal_sim_device(struct irdm_hal_dev *dev)
{
	struct irdm_can_drives *emulated = irdm_hal_canemu_drives(dev);

	if (emulated)
		return &emulated->arm; /* the arm behind the emulated CAN drives */
	return is_open_sim(dev) ? &data_of(dev)->arm : NULL;
}

int irdm_hal_sim_attach_user(struct irdm_hal_dev *dev, const struct irdm_sim_user *u,
			     unsigned hand, const struct irdm_board *b)
{
	struct sim_hand *h = is_open_sim(dev) ? &data_of(dev)->hand : irdm_hal_canemu_hand(dev);

	if (!h || !u || !b || hand >= IRDM_SIM_USER_HANDS)
		return IRDM_EINVAL;
	sim_hand_attach(h, u, hand, b);
	return IRDM_OK;
}
