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
 * starting at rest in the home pose.  No I/O and no system call: the tick stays free of them.
 */
#ifndef IRDM_HAL_SIM_H
#define IRDM_HAL_SIM_H

#include <stdint.h>

#include "irdm/hal.h"
#include "irdm/sim_device.h"

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

#endif /* IRDM_HAL_SIM_H */
