/* SPDX-License-Identifier: MIT */
/*
 * The CANopen master of CiA 402 torque drives (docs/canopen.md): set-up by
 * SDO, then one cycle per loop period: read what came (TPDO1 latest wins,
 * heartbeats, EMCY; anything else counted and dropped), judge the drives'
 * health, send every axis's RPDO1 and the SYNC.  Losing any drive (EMCY,
 * fault state, heartbeat or TPDO missing too long) turns every axis's
 * torque off at once and says which drive and why.  Transport: a CAN port
 * (irdm/can_port.h).  The cycle allocates nothing and never waits; set-up
 * waits for SDO answers through the caller's idle callback.
 */
#ifndef IRDM_CAN_MASTER_H
#define IRDM_CAN_MASTER_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/can_port.h"
#include "irdm/cia402.h"

#define IRDM_CAN_AXES_MAX 3

struct irdm_can_axis_cfg {
	unsigned node;                  /* 1..127 */
	uint32_t rated_torque_mnm;      /* 0x6076, motor side, mN m */
	double gear_ratio;              /* joint turns per motor turn, inverted: motor / joint */
};

struct irdm_can_master_cfg {
	unsigned n_axes;
	struct irdm_can_axis_cfg axis[IRDM_CAN_AXES_MAX];
	uint16_t heartbeat_ms;          /* written to each drive's 0x1017 */
	unsigned heartbeat_timeout_periods;     /* no heartbeat for this long: lost */
	unsigned tpdo_missing_periods;  /* this many periods in a row without a TPDO: lost */
	unsigned sdo_timeout_polls;     /* idle() calls to wait for one SDO answer */
	void (*idle)(void *ctx);        /* set-up's wait (a sleep, or the emulator's turn) */
	void *idle_ctx;
};

struct irdm_can_master_axis {
	uint16_t cw, sw;
	int32_t counts;
	bool fresh;                     /* a TPDO came this period */
	unsigned missing;               /* periods in a row without one */
	uint64_t heartbeat_period;      /* when the last heartbeat came */
	enum irdm_cia402_state state;
};

struct irdm_can_master {
	struct irdm_can_master_cfg cfg;
	struct irdm_can_port port;
	struct irdm_can_master_axis ax[IRDM_CAN_AXES_MAX];
	uint64_t period;                /* cycles run */
	bool faulted;                   /* latched: torque off until reset */
	char why[160];                  /* the first fault, one line */
	uint64_t bad_frames, emcy_frames;
};

/*
 * Check cfg and configure every drive by SDO: mode 10 (CST), heartbeat
 * producer time, rated torque, the RPDO1/TPDO1 mappings; then NMT start.
 * Return: IRDM_OK; IRDM_EINVAL (cfg; err says which field); IRDM_ETIMEDOUT
 * (a drive did not answer: err names drive and object); IRDM_EHW (an SDO
 * abort, by name); IRDM_EFORMAT (an answer that is not one).
 */
int irdm_can_master_init(struct irdm_can_master *m, const struct irdm_can_port *port,
			 const struct irdm_can_master_cfg *cfg, char *err, size_t errlen);

/*
 * One period: tau_joint_nm (joint side; NULL: zero) applied if enable and
 * every drive is operation enabled, counts[] the latest positions.
 * Return: IRDM_OK; IRDM_EHW when the master is (or has just) faulted:
 * every axis commanded to disable voltage with zero torque; m->why says.
 */
int irdm_can_master_cycle(struct irdm_can_master *m, const double *tau_joint_nm, bool enable,
			  int32_t counts[IRDM_CAN_AXES_MAX]);

/* Torque off now: zero torque and disable voltage to every axis, and a SYNC. */
void irdm_can_master_safe_off(struct irdm_can_master *m);

/* Joint torque -> per mille of an axis's rated motor torque, clamped to int16. */
int16_t irdm_can_torque_permille(const struct irdm_can_axis_cfg *a, double tau_joint_nm);

#endif /* IRDM_CAN_MASTER_H */
