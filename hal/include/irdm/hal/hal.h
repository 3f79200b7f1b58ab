/* SPDX-License-Identifier: MIT */
/*
 * Hardware abstraction for the force loop: one ops table, back-ends found
 * by the name the board file gives.  The loop sees only this header; a
 * back-end's internals (a CAN socket, the in-process simulator) stay behind
 * its ops.
 *
 * Shape (as Zephyr's device drivers): a back-end is a const struct
 * irdm_hal_backend (name, const ops table, size of its mutable state); an
 * instance is a struct irdm_hal_dev binding a back-end, a CONSTANT
 * configuration (struct irdm_hal_config: the board's arm, the back-end's
 * options, the tick period) and the back-end's MUTABLE state in memory the
 * caller provides.  Nothing here allocates.
 *
 * Life cycle:  irdm_hal_init -> open -> start -> (read, write)* -> close
 *   open    connect, check the hardware; torque stays off.  read works from
 *           here on (calibration reads the encoders before torque is on).
 *   start   enable the drives; write works from here until safe_off.
 *   safe_off  zero torque NOW, from any state; write then refuses until
 *           start is called again (by the controller's state machine, never
 *           by a back-end on its own).
 *   poll    asynchronous faults (drive, link, e-stop): latched until close.
 *   close   torque off, disconnect.
 *   emergency_off  zero torque from a signal handler (optional): the way
 *           out of a process that is about to end.
 * read, write, safe_off and poll run in the force tick: they must not
 * allocate, block beyond the back-end's own I/O, or print.
 *
 * Torques are joint-side N m; encoder counts are raw (the device model,
 * irdm/device.h, converts and validates them).
 *
 * Registration: a static table of IRDM_HAL_BACKENDS_MAX entries that the
 * composition root (irdm-fw's main, a test) fills once at start with
 * irdm_hal_register(), before any thread runs; irdm-fw registers the
 * back-ends its build configuration carries (CONFIG_IRDM_HAL_<NAME>).  The table cannot name the
 * back-ends itself: the simulator's back-end lives in sim/, above hal/ in
 * the layers (the Makefile links sim before hal, and hal/ may not include
 * sim/ headers), and a build without a back-end simply does not register
 * it.
 */
#ifndef IRDM_HAL_H
#define IRDM_HAL_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/device.h"
#include "irdm/error.h"
#include "irdm/options.h"

#define IRDM_HAL_JOINTS IRDM_DEVICE_JOINTS
#define IRDM_HAL_BACKENDS_MAX 8
#define IRDM_HAL_WHY_MAX 192  /* bytes of a back-end's one-line reason */
#define IRDM_HAL_INFO_MAX 640 /* bytes of what to print after open (lines) */

/* Asynchronous fault bits (poll); a back-end sets the ones it can detect. */
enum irdm_hal_fault {
	IRDM_HAL_FAULT_LINK = 1u << 0,    /* link to the drives lost or timed out */
	IRDM_HAL_FAULT_DRIVE = 1u << 1,   /* a drive faulted (current, temperature) */
	IRDM_HAL_FAULT_ENCODER = 1u << 2, /* an encoder reported an error */
	IRDM_HAL_FAULT_ESTOP = 1u << 3,   /* the emergency stop was pressed */
	IRDM_HAL_FAULT_POWER = 1u << 4,   /* supply under- or over-voltage */
};

struct irdm_hal_joint_state {
	int32_t counts[IRDM_HAL_JOINTS]; /* raw encoder counts */
	uint64_t seq;                    /* sample number: +1 per successful read */
};

/* Constant for the life of an instance. */
struct irdm_hal_config {
	const struct irdm_device_config *device; /* the board's arm */
	const char *options;                     /* the back-end's options from the board file:
				 * "key=value key=value" (may be NULL or empty) */
	double period_s;                         /* the force tick's period */
};

struct irdm_hal_dev;

struct irdm_hal_ops {
	/*
	 * Connect and check the hardware (parses config->options); torque off.
	 * Return: IRDM_OK; IRDM_EINVAL if an option is unknown or invalid, or
	 * the configuration is (bad device, period not finite and positive);
	 * IRDM_EBUSY if already open; IRDM_EIO if the link cannot be opened;
	 * IRDM_ETIMEDOUT if the hardware does not answer; IRDM_EHW if it
	 * answers with a fault.
	 */
	int (*open)(struct irdm_hal_dev *dev);

	/*
	 * Enable the drives (torque zero until the first write).
	 * Return: IRDM_OK; IRDM_EINVAL if not open; IRDM_EHW if a fault is
	 * latched; IRDM_ETIMEDOUT if the drives do not enable in time.
	 */
	int (*start)(struct irdm_hal_dev *dev);

	/*
	 * This tick's encoder sample (open, started or safe-off).
	 * Return: IRDM_OK; IRDM_EINVAL if not open; IRDM_EHW if a fault is
	 * latched (the torque is already off); IRDM_EFAULT if the sample is
	 * invalid (an encoder out of its range); IRDM_ETIMEDOUT if no fresh
	 * sample arrived this tick; IRDM_EIO on a link error.  st is written
	 * only on IRDM_OK.
	 */
	int (*read)(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st);

	/*
	 * Command joint torques, N m (the caller has saturated them).
	 * Return: IRDM_OK; IRDM_EINVAL if not started or after safe_off
	 * (nothing is sent; the torque stays zero); IRDM_EFAULT if a torque is
	 * not finite (zero is commanded instead); IRDM_EHW if a fault is
	 * latched; IRDM_EIO on a link error.
	 */
	int (*write)(struct irdm_hal_dev *dev, const double tau_nm[IRDM_HAL_JOINTS]);

	/*
	 * Zero the torque at once, bypassing any queue, from any state (also
	 * after a fault, also twice).  write refuses until start.
	 * Return: IRDM_OK; IRDM_EHW if the back-end cannot confirm the torque
	 * is off (the caller must then assume it is not: cut the power).
	 */
	int (*safe_off)(struct irdm_hal_dev *dev);

	/*
	 * Asynchronous faults since open (latched), as enum irdm_hal_fault bits.
	 * Return: IRDM_OK (*faults == 0); IRDM_EHW if any is latched (*faults
	 * holds them); IRDM_EINVAL if not open.
	 */
	int (*poll)(struct irdm_hal_dev *dev, uint32_t *faults);

	/* Torque off, disconnect; the instance may be opened again. */
	void (*close)(struct irdm_hal_dev *dev);

	/*
	 * Optional (NULL: none).  Zero the torque from a signal handler that
	 * may have interrupted any other op, in any thread, just before the
	 * process ends: async-signal-safe (no lock, no allocation, no stdio;
	 * write(2) of frames built at open, or plain stores), and leaves the
	 * instance unusable but for close.
	 * Return: IRDM_OK; IRDM_EHW if the torque-off could not be sent.
	 */
	int (*emergency_off)(struct irdm_hal_dev *dev);
};

struct irdm_hal_backend {
	const char *name; /* as the board file names it */
	const struct irdm_hal_ops *ops;
	size_t data_size; /* bytes of mutable state per instance */
	/*
	 * Its hal_options keys, for help and docs/hal-options.md (NULL: it
	 * takes none).  open parses config->options through this table.
	 */
	const struct irdm_opt_table *options;
	/*
	 * Optional: parse options as open would, without opening, so that the
	 * caller can name where they came from ("boards/x.board:3:
	 * hal_options").  Return: IRDM_OK; IRDM_EINVAL with err = "WHERE:
	 * key = value: reason", "WHERE: unknown ... 'key'" or "WHERE: key:
	 * missing (...)".
	 */
	int (*check_options)(const char *options, const char *where, char *err, size_t errlen);
};

struct irdm_hal_dev {
	const struct irdm_hal_backend *backend;
	const struct irdm_hal_config *config;
	void *data; /* backend->data_size bytes, max_align_t aligned */
	/*
	 * Written by the back-end, read by the caller (both may stay empty):
	 * why   the reason of the last error or of the latched fault, one line
	 *       naming the part and the cause ("drive 2 (node 2): SDO abort
	 *       0x06020000 ... writing 0x6060:00"); set where the error is
	 *       returned (open, start) or the fault latched (poll, read).
	 * info  what the caller should print once after open (e.g. a bus load,
	 *       the drives found), one or more lines separated by '\n'.
	 */
	char why[IRDM_HAL_WHY_MAX];
	char info[IRDM_HAL_INFO_MAX];
};

/*
 * Add a back-end to the table (at start, single-threaded).  Registering the
 * same back-end twice is harmless.
 * Return: IRDM_OK; IRDM_EINVAL if its name or an op is missing; IRDM_EBUSY
 * if another back-end has that name; IRDM_ENOMEM if the table is full.
 */
int irdm_hal_register(const struct irdm_hal_backend *backend);

/* The back-end of that name, or NULL. */
const struct irdm_hal_backend *irdm_hal_find(const char *name);

/* The i-th back-end registered (from 0), or NULL past the last: for help
 * and docs listing every back-end of a build. */
const struct irdm_hal_backend *irdm_hal_backend_at(unsigned i);

/*
 * Bind an instance of the back-end `name` to cfg and to the caller's memory
 * (cleared here); then call irdm_hal_open().
 * Return: IRDM_OK; IRDM_ENOTSUP if no back-end of that name is registered;
 * IRDM_ENOMEM if mem is smaller than the back-end's data_size; IRDM_EINVAL
 * if mem is NULL or not aligned for max_align_t, or cfg is NULL.
 */
int irdm_hal_init(struct irdm_hal_dev *dev, const char *name, const struct irdm_hal_config *cfg,
		  void *mem, size_t mem_size);

/* The ops, through the instance (each documents its errors above). */
static inline int irdm_hal_open(struct irdm_hal_dev *dev)
{
	return dev->backend->ops->open(dev);
}

static inline int irdm_hal_start(struct irdm_hal_dev *dev)
{
	return dev->backend->ops->start(dev);
}

static inline int irdm_hal_read(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st)
{
	return dev->backend->ops->read(dev, st);
}

static inline int irdm_hal_write(struct irdm_hal_dev *dev, const double tau_nm[IRDM_HAL_JOINTS])
{
	return dev->backend->ops->write(dev, tau_nm);
}

static inline int irdm_hal_safe_off(struct irdm_hal_dev *dev)
{
	return dev->backend->ops->safe_off(dev);
}

static inline int irdm_hal_poll(struct irdm_hal_dev *dev, uint32_t *faults)
{
	return dev->backend->ops->poll(dev, faults);
}

static inline void irdm_hal_close(struct irdm_hal_dev *dev)
{
	dev->backend->ops->close(dev);
}

/* Async-signal-safe; IRDM_ENOTSUP if the back-end has no emergency_off. */
static inline int irdm_hal_emergency_off(struct irdm_hal_dev *dev)
{
	const struct irdm_hal_ops *o = dev->backend->ops;

	return o->emergency_off ? o->emergency_off(dev) : IRDM_ENOTSUP;
}

#endif /* IRDM_HAL_H */
