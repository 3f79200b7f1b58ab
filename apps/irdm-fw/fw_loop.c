/* SPDX-License-Identifier: MIT */
/*
 * The force loop around the controller's tick: wait for the period, read
 * the HAL, tick, write the HAL.
 * Nothing here allocates, prints or locks; on a fault the torque goes off
 * (safe_off on every device) in the same period, before anything else.
 */
#include <string.h>
#include <time.h>

#include "irdm/device.h"
#include "irdm/error.h"
#include "irdm/hal/hal.h"
#include "irdm/posix/rt.h"

#include "fw.h"

static void safe_off_all(struct fw *fw)
{
	for (unsigned i = 0; i < fw->board.devices; i++)
		irdm_hal_safe_off(&fw->hal[i]);
}

/* HAL reads and polls into the controller's input; failures become flags. */
static void read_devices(struct fw *fw, struct irdm_ctrl_input *in)
{
	struct irdm_hal_joint_state st;
	uint32_t faults;

	for (unsigned i = 0; i < fw->board.devices; i++) {
		if (irdm_hal_read(&fw->hal[i], &st)) {
			in->cmd |= IRDM_CTRL_CMD_HAL_READ_FAILED;
			for (int j = 0; j < 3; j++)
				in->counts[i][j] = IRDM_CTRL_COUNT_NAN;
		} else {
			memcpy(in->counts[i], st.counts, sizeof(in->counts[i]));
		}
		if (irdm_hal_poll(&fw->hal[i], &faults))
			in->cmd |= IRDM_CTRL_CMD_HAL_FAULT;
	}
}

static uint32_t write_devices(struct fw *fw, const struct irdm_ctrl_output *out)
{
	uint32_t failed = 0;

	if (out->state != IRDM_SAFETY_ENABLED)
		return 0;
	for (unsigned i = 0; i < fw->board.devices; i++)
		if (irdm_hal_write(&fw->hal[i], out->dev[i].torque_nm))
			failed = IRDM_CTRL_CMD_HAL_WRITE_FAILED;
	return failed;
}

static double now_ns(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/*
 * Commands of the run: calibrate at the first tick (the arm starts at its
 * calibration pose), ask to enable from the second on until the torque
 * has been enabled once (a limit that holds, e.g. the arm still too fast,
 * refuses it; the request stands until it clears), shut down at the end.
 * A signal raises SIGNAL (the reason, logged) and shuts down in the same
 * tick: state off.  Once enabled, nothing re-enables: a later fault ends
 * the run.
 */
static uint32_t run_commands(uint64_t tick, uint64_t last, bool signalled, bool enabled_once)
{
	uint32_t cmd = 0;

	if (tick == 0)
		cmd |= IRDM_CTRL_CMD_CALIBRATE;
	if (tick >= 1 && !enabled_once)
		cmd |= IRDM_CTRL_CMD_ENABLE;
	if (tick == last)
		cmd |= IRDM_CTRL_CMD_SHUTDOWN;
	if (signalled)
		cmd |= IRDM_CTRL_CMD_SIGNAL | IRDM_CTRL_CMD_SHUTDOWN;
	return cmd;
}

/* Whether the torque came on; if not, what held it off this tick. */
static void watch_enable(struct fw *fw, const struct irdm_ctrl_input *in,
			 const struct irdm_ctrl_output *out)
{
	if (out->state == IRDM_SAFETY_ENABLED)
		fw->enabled_once = true;
	else if ((in->cmd & IRDM_CTRL_CMD_ENABLE) && out->state == IRDM_SAFETY_READY)
		fw->enable_blocked = fw->ctrl.active & IRDM_FAULT_FATAL;
	else if ((in->cmd & IRDM_CTRL_CMD_ENABLE) && out->state == IRDM_SAFETY_INIT)
		fw->enable_blocked = 0; /* not calibrated: main says so */
}

/* The run's exit code from its last tick. */
static int run_end(const struct fw *fw, const struct irdm_ctrl_output *out, bool sig)
{
	if (sig)
		return FW_EXIT_SIGNAL;
	if (out->state == IRDM_SAFETY_FAULT)
		return FW_EXIT_FAULT;
	return fw->enabled_once ? FW_EXIT_OK : FW_EXIT_NEVER_ENABLED;
}

int fw_loop_run(struct fw *fw, volatile sig_atomic_t *signalled)
{
	uint64_t n_ticks = fw->run_ticks, prev_lat = 0, prev_comp = 0;
	uint32_t carry = 0;
	struct irdm_ctrl_input in;
	struct irdm_ctrl_output out;
	int rc = FW_EXIT_OK;

	irdm_clock_start(&fw->clock, (enum irdm_clock_mode)fw->args.clock, fw->board.period_us);
	for (uint64_t k = 0; k < n_ticks; k++) {
		int64_t latency_ns = irdm_clock_wait(&fw->clock);
		double t0 = now_ns(), compute_ns;
		bool sig = *signalled != 0;

		memset(&in, 0, sizeof(in));
		read_devices(fw, &in);
		in.cmd |= carry | run_commands(k, n_ticks - 1, sig, fw->enabled_once);
		in.prev_latency_ns = prev_lat;
		in.prev_compute_ns = prev_comp;
		if (irdm_ctrl_tick(&fw->ctrl, &in, &out) == IRDM_EFAULT || sig)
			safe_off_all(fw);
		else
			carry = write_devices(fw, &out);
		compute_ns = now_ns() - t0;
		/* virtual time reports no timing to the controller: its runs
		 * (and logs) are the same every time */
		if (fw->args.clock == IRDM_CLOCK_REAL) {
			prev_lat = (uint64_t)(latency_ns > 0 ? latency_ns : 0);
			prev_comp = (uint64_t)irdm_clock_elapsed_ns(&fw->clock);
		}
		watch_enable(fw, &in, &out);
		/* after the tick's timing: what the monitor does is not the tick's */
		fw_monitor_tick(fw, &out);
		irdm_hist_add(&fw->compute_measured, (int64_t)compute_ns);
		fw_log_record(fw, &out, fw->args.clock == IRDM_CLOCK_REAL ? latency_ns : 0,
			      (int64_t)prev_comp);
		fw->ticks = out.tick;
		fw->last_state = out.state;
		fw->last_cause = out.cause;
		if (out.state == IRDM_SAFETY_FAULT || out.state == IRDM_SAFETY_OFF) {
			safe_off_all(fw);
			rc = run_end(fw, &out, sig);
			break;
		}
	}
	return rc;
}
