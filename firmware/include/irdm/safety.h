/* SPDX-License-Identifier: MIT */
/*
 * The controller's safety state machine (irdm/controller.h runs it every
 * tick): pure bookkeeping on one small struct, no clock, no I/O.
 *
 *   INIT --calibrated--> READY --enable--> ENABLED --disable--> READY
 *   INIT, READY, ENABLED --any fault--> FAULT --reset (cause gone)--> READY
 *   (INIT if never calibrated);  any state --shutdown--> OFF (final).
 *
 * Torque may be commanded in ENABLED only.  A fault latches: FAULT is left
 * by an explicit reset alone, and only once every cause is gone (a
 * signal never goes: the process is being stopped).  The numbers of the
 * states and of the fault bits are stable: the telemetry record stores
 * them and `irdm log export` prints them.
 */
#ifndef IRDM_SAFETY_H
#define IRDM_SAFETY_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/error.h"

enum irdm_safety_state {
	IRDM_SAFETY_INIT = 0,    /* not calibrated: torque off */
	IRDM_SAFETY_READY = 1,   /* calibrated, torque off */
	IRDM_SAFETY_ENABLED = 2, /* torque on */
	IRDM_SAFETY_FAULT = 3,   /* torque off until an explicit reset */
	IRDM_SAFETY_OFF = 4,     /* shut down: torque off for good */
};

/* Fault flags: a u32 bit set (bit numbers shared with the telemetry log). */
enum irdm_safety_fault {
	IRDM_FAULT_CLAMP = 1u << 0,         /* informational: force or torque clamped */
	IRDM_FAULT_WORKSPACE = 1u << 1,     /* tip outside the workspace box */
	IRDM_FAULT_VELOCITY = 1u << 2,      /* tip faster than the limit */
	IRDM_FAULT_WATCHDOG = 1u << 3,      /* one tick computed longer than the watchdog */
	IRDM_FAULT_OVERRUN = 1u << 4,       /* K consecutive overruns */
	IRDM_FAULT_ENCODER_NAN = 1u << 5,   /* encoder not a number (or a non-finite pose) */
	IRDM_FAULT_ENCODER_RANGE = 1u << 6, /* encoder count outside its range */
	IRDM_FAULT_SIGNAL = 1u << 7,        /* a signal asked the process to end */
	IRDM_FAULT_HAL_READ = 1u << 8,      /* the HAL read failed */
	IRDM_FAULT_HAL_WRITE = 1u << 9,     /* the HAL write failed */
	IRDM_FAULT_HAL_FAULT = 1u << 10,    /* the HAL polled an asynchronous fault */
	IRDM_FAULT_ENGINE = 1u << 11,       /* the force engine or the contact step failed */
};

#define IRDM_FAULT_BITS 12
#define IRDM_FAULT_ALL ((1u << IRDM_FAULT_BITS) - 1)
/* every bit but CLAMP stops the torque */
#define IRDM_FAULT_FATAL (IRDM_FAULT_ALL & ~IRDM_FAULT_CLAMP)

struct irdm_safety {
	enum irdm_safety_state state;
	bool calibrated;
	uint32_t faults;   /* latched fatal bits since the last reset */
	uint32_t cause;    /* the bit that entered FAULT (the reason to log) */
	uint64_t n_faults; /* entries into FAULT */
};

/* INIT, not calibrated, no fault. */
void irdm_safety_init(struct irdm_safety *s);

/*
 * INIT -> READY once the device was calibrated at its known pose.
 * Return: IRDM_OK; IRDM_EINVAL if the state is not INIT.
 */
int irdm_safety_calibrated(struct irdm_safety *s);

/*
 * READY -> ENABLED.
 * Return: IRDM_OK (also when already ENABLED); IRDM_EINVAL from INIT, FAULT
 * or OFF (a faulted controller never re-enables without a reset).
 */
int irdm_safety_enable(struct irdm_safety *s);

/*
 * ENABLED -> READY.
 * Return: IRDM_OK (also when already READY); IRDM_EINVAL from any other state.
 */
int irdm_safety_disable(struct irdm_safety *s);

/*
 * Raise faults: the fatal bits of `faults` latch, and INIT, READY or
 * ENABLED go to FAULT (cause = the lowest new fatal bit).  In FAULT they
 * latch too; OFF stays OFF.  CLAMP alone changes nothing.
 * Return: IRDM_OK; IRDM_EINVAL if `faults` has no fatal bit.
 */
int irdm_safety_fault(struct irdm_safety *s, uint32_t faults);

/*
 * FAULT -> READY (INIT if the fault came before calibration), clearing the
 * latched bits.  `active` holds the fault conditions that hold NOW (the
 * controller measures them every tick).
 * Return: IRDM_OK; IRDM_EINVAL if the state is not FAULT; IRDM_EFAULT if a
 * fatal bit of `active` is set or SIGNAL is latched (the state stays FAULT).
 */
int irdm_safety_reset(struct irdm_safety *s, uint32_t active);

/* Any state -> OFF, for good. */
void irdm_safety_shutdown(struct irdm_safety *s);

/* True in ENABLED: the only state with torque. */
bool irdm_safety_torque_allowed(const struct irdm_safety *s);

/*
 * For the log: the name of the lowest set bit of `faults` ("clamp",
 * "workspace", "velocity", "watchdog", "overrun", "encoder-nan",
 * "encoder-range", "signal", "hal-read", "hal-write", "hal-fault",
 * "engine"), "none" for 0, "unknown" for a bit above the known ones.
 */
const char *irdm_safety_fault_name(uint32_t faults);

/* "init", "ready", "enabled", "fault", "off"; "unknown" otherwise. */
const char *irdm_safety_state_name(int state);

#endif /* IRDM_SAFETY_H */
