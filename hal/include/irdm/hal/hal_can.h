/* SPDX-License-Identifier: MIT */
/*
 * The HAL back-end around the CANopen master (irdm/can_master.h), shared by
 * the two that register it: "socketcan" (hal/can/hal_socketcan.c, a real
 * bus) and "canemu" (sim/hal/hal_canemu.c, the same master on an in-memory
 * bus with emulated drives).  What differs is the link (struct
 * irdm_hal_can_link): how the port opens, what happens while set-up waits,
 * whether frames sent are answered at once (the emulator's turn), the
 * link's own fault flags.
 *
 * HAL ops on the master:
 *   open      parse the options, open the port, SDO set-up, NMT start;
 *             dev->info: the bus load; dev->why: the reason of a failure
 *   start     the cycle with the drives disabled until every drive has
 *             answered IRDM_HAL_CAN_STEADY_PERIODS SYNCs in a row, then
 *             enable every drive; both within enable_timeout_ms
 *   read      receive and judge; a period nobody wrote is closed first
 *             (zero torque, the SYNC) so every period has its SYNC
 *   write     RPDO1 per axis, then the SYNC
 *   safe_off  disable voltage + zero torque to every axis and a SYNC, now
 *   poll      the master's latched fault as LINK or DRIVE, dev->why
 * Options: irdm_hal_socketcan_options, irdm_hal_canemu_options (below;
 * docs/hal-options.md is written from them).
 */
#ifndef IRDM_HAL_CAN_H
#define IRDM_HAL_CAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/hal/can_master.h"
#include "irdm/hal/hal.h"

#define IRDM_HAL_CAN_IFNAME_MAX 16
#define IRDM_HAL_CAN_STEADY_PERIODS 5 /* start: disabled SYNCs answered in a row first */

/* The board's hal_options, parsed. */
struct irdm_hal_can_opts {
	char iface[IRDM_HAL_CAN_IFNAME_MAX];
	unsigned n_nodes;
	unsigned nodes[IRDM_CAN_AXES_MAX];
	uint32_t rated_torque_mnm[IRDM_CAN_AXES_MAX];
	uint32_t bitrate;
	uint16_t heartbeat_ms;
	uint32_t heartbeat_timeout_ms;
	unsigned tpdo_missing_periods;
	bool sync_counter;
	uint32_t sdo_timeout_ms;
	uint32_t enable_timeout_ms;
	unsigned substeps;        /* canemu only: the emulated arm's steps a period */
	unsigned master_node;     /* the master's own node id (its heartbeat) */
	uint32_t rpdo_timeout_ms; /* each drive's RPDO1 deadline (0: 3 periods) */
	unsigned emcy_drive;      /* canemu only: drive (1..) that faults, 0: none */
	uint32_t emcy_at_ms;      /*   at this virtual time, with EMCY 0x2310 */
};

/* Which options a back-end takes beyond the common ones. */
enum irdm_hal_can_extra {
	IRDM_HAL_CAN_IFACE = 1u << 0, /* iface= (required) */
	IRDM_HAL_CAN_SUBSTEPS = 1u << 1,
	IRDM_HAL_CAN_EMCY_AT = 1u << 2, /* emcy_at=DRIVE:MS (an injected fault) */
};

/* The options each back-end takes (docs/hal-options.md). */
extern const struct irdm_opt_table irdm_hal_socketcan_options;
extern const struct irdm_opt_table irdm_hal_canemu_options;

/*
 * Parse "key=value key=value" (whitespace between options, commas inside a
 * list) into o, the table's defaults first: socketcan's table with
 * IRDM_HAL_CAN_IFACE in extra, canemu's otherwise.  Return: IRDM_OK;
 * IRDM_EINVAL with err = "WHERE: key = value: reason", "WHERE: unknown
 * ... 'key'" or "WHERE: key: missing (...)".
 */
int irdm_hal_can_parse(const char *options, unsigned extra, const char *where,
		       struct irdm_hal_can_opts *o, char *err, size_t errlen);

/* The same without a struct to keep: a back-end's check_options. */
int irdm_hal_can_check(const char *options, unsigned extra, const char *where, char *err,
		       size_t errlen);

struct irdm_hal_can_link {
	/* Open the port; IRDM_OK or an error with err set. */
	int (*open)(struct irdm_hal_dev *dev, struct irdm_can_port *port, char *err,
		    size_t errlen);
	/* Frames were sent: let the other side run (the emulator; NULL: a wire). */
	void (*pump)(struct irdm_hal_dev *dev);
	/* Set-up's wait, about one period (ctx: the dev). */
	void (*idle)(void *ctx);
	/* The link's own fault flags into the master (bus-off), or NULL. */
	void (*check)(struct irdm_hal_dev *dev, struct irdm_can_master *m);
	void (*close)(struct irdm_hal_dev *dev);
};

enum irdm_hal_can_state { HAL_CAN_CLOSED = 0,
			  HAL_CAN_OPEN,
			  HAL_CAN_RUNNING,
			  HAL_CAN_OFF };

/* The start of every CAN back-end's data (dev->data points at it). */
struct irdm_hal_can {
	const struct irdm_hal_can_link *link;
	struct irdm_hal_can_opts opts;
	struct irdm_can_master m;
	enum irdm_hal_can_state state;
	bool written; /* this period's SYNC already sent */
	uint64_t seq;
};

/* open with this link and these extra options (each back-end's open). */
int irdm_hal_can_open(struct irdm_hal_dev *dev, const struct irdm_hal_can_link *link,
		      unsigned extra);

/* The other ops, as irdm/hal.h documents them. */
int irdm_hal_can_start(struct irdm_hal_dev *dev);
int irdm_hal_can_read(struct irdm_hal_dev *dev, struct irdm_hal_joint_state *st);
int irdm_hal_can_write(struct irdm_hal_dev *dev, const double tau_nm[IRDM_HAL_JOINTS]);
int irdm_hal_can_safe_off(struct irdm_hal_dev *dev);
int irdm_hal_can_poll(struct irdm_hal_dev *dev, uint32_t *faults);
void irdm_hal_can_close(struct irdm_hal_dev *dev);
/* emergency_off on a port whose send is one write(2) (SocketCAN): the
 * master's frames built at open, irdm_can_master_emergency_off(). */
int irdm_hal_can_emergency_off(struct irdm_hal_dev *dev);

/* A CAN back-end's ops table: its own open, the shared rest. */
#define IRDM_HAL_CAN_OPS(open_fn, emergency_fn) \
	{ \
		.open = (open_fn), .start = irdm_hal_can_start, .read = irdm_hal_can_read, \
		.write = irdm_hal_can_write, .safe_off = irdm_hal_can_safe_off, \
		.poll = irdm_hal_can_poll, .close = irdm_hal_can_close, \
		.emergency_off = (emergency_fn), \
	}

/* The operator's fault reset (tests; the controller has no such command yet). */
void irdm_hal_can_reset_faults(struct irdm_hal_dev *dev);

#endif /* IRDM_HAL_CAN_H */
