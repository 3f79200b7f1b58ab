/* SPDX-License-Identifier: MIT */
/*
 * The simulated arm (irdm/sim_device.h) behind the HAL (irdm/hal.h), in
 * process.  Register it with irdm_hal_register(&irdm_hal_sim_backend); the
 * board file names it "sim".
 *
 * Each read advances the arm by config->period_s (the simulated time between
 * two ticks), then samples its encoders: a torque written in one tick acts
 * over the next.  Options (config->options, "key=value" words separated by
 * spaces or commas): write_delay, read_delay, substeps and end_stops, the
 * back-end's option table (irdm_hal_sim_backend.options,
 * docs/hal-options.md); everything else from irdm_sim_params_default(),
 * starting at rest in the home pose.  No I/O and no system call: the tick
 * stays free of them.
 *
 * The virtual user (irdm/sim/sim_user.h): once attached, its hand pushes the
 * arm at the start of every read (of a "sim" or "canemu" instance), at the
 * time of that read's tick: the caller above the HAL only reads.
 */
#ifndef IRDM_HAL_SIM_H
#define IRDM_HAL_SIM_H

#include <stdint.h>

#include "irdm/board.h"
#include "irdm/hal/hal.h"
#include "irdm/sim/sim_device.h"
#include "irdm/sim/sim_user.h"

extern const struct irdm_hal_backend irdm_hal_sim_backend;

/*
 * Tests and the virtual user: latch fault bits (enum irdm_hal_fault) as the
 * hardware would; the drives drop their torque at once.
 * Return: IRDM_OK; IRDM_EINVAL if dev is not an open sim instance.
 */
int irdm_hal_sim_inject_fault(struct irdm_hal_dev *dev, uint32_t faults);

/* The simulated arm behind an open sim or canemu instance (true state, the
 * hand's force), or NULL if dev is neither. */
struct irdm_sim_device *irdm_hal_sim_device(struct irdm_hal_dev *dev);

/*
 * Hand `hand` (0-based) of script u takes the arm of an open sim or canemu
 * instance, placed by board b (u and b outlive the instance's reads).  The
 * instance's reads from here on are the ticks 0, 1, 2, ... of a loop on
 * b's period_us (each device is read once a tick: irdm/hal.h), and the
 * hand pushes at t = tick x period, as irdm_sim_user_push() does.  Call it
 * after open, before the first read; open forgets the hand.
 * Return: IRDM_OK; IRDM_EINVAL if dev is neither an open sim nor canemu
 * instance, u or b is NULL or hand >= IRDM_SIM_USER_HANDS.
 */
int irdm_hal_sim_attach_user(struct irdm_hal_dev *dev, const struct irdm_sim_user *u,
			     unsigned hand, const struct irdm_board *b);

#endif /* IRDM_HAL_SIM_H */
