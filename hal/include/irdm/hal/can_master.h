/* SPDX-License-Identifier: MIT */
/*
 * The CANopen master of CiA 402 torque drives (docs/canopen.md): set-up by
 * SDO, then one cycle per loop period: receive what came (TPDO1 latest
 * wins, heartbeats, EMCY; anything else counted and dropped) and judge the
 * drives' health; send every axis's RPDO1 and the SYNC.  Losing any drive
 * (EMCY, fault state, heartbeat or TPDO missing too long, the link down)
 * turns every axis's torque off at once and says which drive and why, in
 * one line (m->why).  Faults latch: only irdm_can_master_reset_faults()
 * (an operator's request) clears them, never the master itself.
 *
 * Transport: a CAN port (irdm/can_port.h).  The cycle (receive, send,
 * safe_off) allocates nothing and never waits; set-up waits for SDO
 * answers through the caller's idle callback, a bounded number of times.
 */
#ifndef IRDM_CAN_MASTER_H
#define IRDM_CAN_MASTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/hal/can_port.h"
#include "irdm/hal/cia402.h"

#define IRDM_CAN_AXES_MAX 3
#define IRDM_CAN_WHY_MAX 160
#define IRDM_CAN_SYNC_COUNTER_MAX 240
#define IRDM_CAN_RX_MAX 256 /* frames one receive takes at most */ /* the counter runs 1..240, then 1 again */

struct irdm_can_axis_cfg {
	unsigned node;             /* 1..127 */
	uint32_t rated_torque_mnm; /* 0x6076, motor side, mN m (> 0) */
	double gear_ratio;         /* motor turns per joint turn (> 0) */
};

/* Constant for the life of a master. */
struct irdm_can_master_cfg {
	unsigned n_axes; /* 1..IRDM_CAN_AXES_MAX */
	struct irdm_can_axis_cfg axis[IRDM_CAN_AXES_MAX];
	uint32_t period_us;            /* the cycle: one SYNC per period */
	uint32_t bitrate;              /* bit/s, 10 000..1 000 000 */
	bool sync_counter;             /* SYNC with a counter byte (1..240) */
	uint16_t heartbeat_ms;         /* written to each drive's 0x1017 (> 0) */
	uint32_t heartbeat_timeout_ms; /* no heartbeat for longer: lost (> heartbeat_ms) */
	unsigned tpdo_missing_periods; /* this many periods in a row without a TPDO: lost */
	unsigned master_node;          /* 1..127, not a drive's: the master's heartbeat */
	uint16_t rpdo_timeout_ms;      /* each drive's RPDO1 deadline, 0x1400:05 (> 0) */
	unsigned sdo_timeout_polls;    /* idle() calls to wait for one SDO answer (> 0) */
	void (*idle)(void *ctx);       /* set-up's wait (a sleep, or the emulator's turn) */
	void *idle_ctx;
};

/* What the master knows of one drive (mutable). */
struct irdm_can_master_axis {
	uint16_t cw;                /* the last controlword sent */
	uint16_t sw;                /* the latest statusword */
	int32_t counts;             /* the latest position actual */
	bool fresh;                 /* a TPDO came since the last receive */
	bool seen;                  /* a TPDO ever came */
	unsigned missing;           /* periods in a row without one */
	uint64_t heartbeat_period;  /* the period of the last heartbeat */
	enum irdm_co_nmt_state nmt; /* as the last heartbeat said */
	enum irdm_cia402_state state;
	bool was_enabled;      /* reached operation enabled since enable */
	uint32_t device_type;  /* 0x1000, read at set-up */
	uint32_t identity[4];  /* 0x1018:01..04: vendor, product, revision, serial */
	uint16_t abort_option; /* 0x6007 as written (2, or 1 if refused) */
};

struct irdm_can_master {
	struct irdm_can_master_cfg cfg;
	struct irdm_can_port port;
	struct irdm_can_master_axis ax[IRDM_CAN_AXES_MAX];
	uint64_t period;                              /* cycles sent */
	uint64_t beats;                               /* heartbeats the master produced */
	unsigned sync_count;                          /* the last SYNC counter sent (0: none yet) */
	bool enable;                                  /* drive the axes toward operation enabled */
	bool reset_request;                           /* fault reset asked for (operator) */
	bool faulted;                                 /* latched: torque off until a reset */
	bool link_lost;                               /* the fault is the link's, not a drive's */
	char why[IRDM_CAN_WHY_MAX];                   /* the first fault, one line */
	struct irdm_can_frame off[IRDM_CAN_AXES_MAX]; /* each axis's torque-off RPDO1 */
	uint64_t bad_frames;                          /* malformed frames of ours (wrong DLC, content) */
	uint64_t unknown_frames;                      /* identifiers we do not expect */
	uint64_t sdo_stragglers;                      /* SDO answers after set-up */
	uint64_t emcy_frames;
	uint64_t tx_dropped; /* sends refused: transmit queue full */
};

/*
 * Worst-case bits on the wire of one cycle: SYNC + n RPDO1 (4 bytes) +
 * n TPDO1 (6 bytes), every frame with its maximum stuff bits.
 */
unsigned irdm_can_master_cycle_bits(const struct irdm_can_master_cfg *cfg);

/*
 * The bus load of one cycle in one line, e.g. "CAN bus load: SYNC + 3 x
 * RPDO1 (4 B) + 3 x TPDO1 (6 B) = 437 bits worst case in 1000 us at
 * 1000000 bit/s: 43.7 %".
 */
void irdm_can_master_load_line(const struct irdm_can_master_cfg *cfg, char *line, size_t len);

/*
 * Check a configuration, including that one cycle fits the period.
 * Return: IRDM_OK; IRDM_EINVAL with err naming the field and the reason
 * (a cycle that does not fit: its bits against the period's).
 */
int irdm_can_master_check(const struct irdm_can_master_cfg *cfg, char *err, size_t errlen);

/*
 * Check cfg, configure every drive by expedited SDO (mode of operation
 * 0x6060 = 10 CST, heartbeat producer 0x1017, rated torque 0x6076, then
 * RPDO1 and TPDO1 by CiA 301's procedure: PDO off (0x1400 / 0x1800:01 bit
 * 31), mapping 0x1600 / 0x1A00 emptied, its entries, their number, the
 * transmission type 1 (every SYNC), PDO on), then NMT start each node.
 * Return: IRDM_OK; IRDM_EINVAL (cfg; err says which field); IRDM_ETIMEDOUT
 * (a drive did not answer: err names the drive and the object);
 * IRDM_EHW (an SDO abort: err names the code); IRDM_EFORMAT (an answer
 * that is not one for the request); IRDM_EIO (the link is down).
 */
int irdm_can_master_init(struct irdm_can_master *m, const struct irdm_can_port *port,
			 const struct irdm_can_master_cfg *cfg, char *err, size_t errlen);

/*
 * Receive everything waiting and judge the drives (the start of a period).
 * Return: IRDM_OK (every axis has a fresh TPDO); IRDM_ETIMEDOUT (one has
 * not, within tpdo_missing_periods); IRDM_EHW when the master is (or has
 * just) faulted: every axis already commanded off, m->why says.
 */
int irdm_can_master_receive(struct irdm_can_master *m);

/*
 * One received frame into the master (receive's body; the fuzz target's
 * entry): a TPDO1, heartbeat or EMCY of a configured node is taken (an
 * EMCY with a non-zero code loses that drive); anything else is counted.
 * Return: IRDM_OK if taken; IRDM_EFORMAT if malformed (bad_frames);
 * IRDM_ENOTSUP if not ours (unknown_frames, sdo_stragglers).
 */
int irdm_can_master_take(struct irdm_can_master *m, const struct irdm_can_frame *f);

/*
 * End a period: each axis's RPDO1 (tau_joint_nm, joint side, N m; NULL or
 * not enabled: zero), then the SYNC.  Once faulted, disable voltage and
 * zero torque to every axis whatever was asked.
 * Return: IRDM_OK; IRDM_EHW if faulted (or the link fails now).
 */
int irdm_can_master_send(struct irdm_can_master *m, const double *tau_joint_nm);

/* Drive the axes toward operation enabled (true) or hold them at disable
 * voltage (false), from the next send on. */
void irdm_can_master_enable(struct irdm_can_master *m, bool on);

/* Every axis reports operation enabled (from its latest TPDO). */
bool irdm_can_master_all_enabled(const struct irdm_can_master *m);

/* The first axis without a TPDO1 in the last receive, or -1. */
int irdm_can_master_first_stale(const struct irdm_can_master *m);

/* The first axis not operation enabled, or -1. */
int irdm_can_master_first_not_enabled(const struct irdm_can_master *m);

/*
 * Torque off now: disable voltage and zero torque to every axis, and a
 * SYNC; the master stops enabling.  Return: IRDM_OK; IRDM_EHW if a frame
 * could not be sent (the torque cannot be confirmed off).
 */
int irdm_can_master_safe_off(struct irdm_can_master *m);

/*
 * Latch a fault from outside the master (e.g. the port's bus-off flag):
 * axis -1 for the link.  Every axis goes off at once; the first reason wins.
 */
void irdm_can_master_lose(struct irdm_can_master *m, int axis, const char *reason);

/*
 * Torque off from a signal handler: the disable-voltage, zero-torque RPDO1
 * of every axis (built at init) and a SYNC, each one irdm_can_send(), and
 * nothing else: async-signal-safe when the port's send is (SocketCAN's is
 * one write(2)).  Touches no other state of the master.
 * Return: IRDM_OK; IRDM_EHW if a frame could not be sent.
 */
int irdm_can_master_emergency_off(const struct irdm_can_master *m);

/* The operator's fault reset: clear the latch and send fault reset
 * (bit 7's rising edge) to faulted drives; they then re-enable only if
 * enabled again. */
void irdm_can_master_reset_faults(struct irdm_can_master *m);

/* Joint torque -> per mille of an axis's rated motor torque, rounded,
 * clamped to int16; not finite -> 0. */
int16_t irdm_can_torque_permille(const struct irdm_can_axis_cfg *a, double tau_joint_nm);

/* Drive k's identity as read at set-up, one line: "drive 1 (node 1): CiA
 * 402 device type 0x00020192, vendor 0x..., product 0x..., revision 0x...,
 * serial 0x...". */
void irdm_can_master_identity_line(const struct irdm_can_master *m, unsigned k, char *line,
				   size_t len);

/* Frames the NMT stop command to every node (at close). */
void irdm_can_master_stop(struct irdm_can_master *m);

#endif /* IRDM_CAN_MASTER_H */
