/* SPDX-License-Identifier: MIT */
/*
 * CiA 402 drives in emulation: one node per joint of the simulated arm
 * (irdm/sim_device.h), on a CAN port (docs/canopen.md).  Each answers NMT
 * and expedited SDOs for the objects the master configures, strictly as
 * a real drive does for the PDOs (irdm/can_drive_pdo.h: a mapping changes
 * only with its PDO switched off), takes its RPDO1 (controlword + target
 * torque; latest wins) while that PDO is valid, and at every SYNC sends
 * its TPDO1 while valid (statusword + position counts sampled then), applies
 * the set-point and moves the arm one period: a one-period bus delay, as
 * real synchronous PDOs have.  Heartbeats at the configured producer time
 * on the emulated clock (which SYNCs advance), or, with wall_heartbeat, on
 * the wall clock the caller gives irdm_can_drives_wall() (a process on a
 * real bus: a master that stops sending SYNC still hears heartbeats).
 * Faults a test injects: stop the heartbeat, drop or delay TPDOs, answer
 * SDOs wrongly, raise an EMCY and fault, flood the bus; set by hand or on
 * a schedule counted in SYNCs (irdm/can_faults.h).
 *
 * As strict as a standard device at its defaults (CiA 301 / 402,
 * docs/canopen.md): a SYNC whose length does not match its 0x1019 (0: no
 * counter, DLC 0; 2..240: DLC 1) is answered with EMCY 0x8240 and the
 * drive drops to pre-operational; 0x1019 is written only while 0x1006 is
 * 0 (else abort 0x08000022); a TPDO COB-ID allowing RTR is refused
 * (0x06090030).  It runs the deadlines it is given, each from the first
 * frame it watches: the consumer heartbeat (0x1016:01, the master's node
 * and time) and the RPDO1 event timer (0x1400:05); on a time-out it sends
 * EMCY 0x8130 or 0x8250 (bytes 3-4: the torque it applies from then on,
 * per mille: 0) and takes the reaction 0x6007 names (0 none, 1 fault,
 * 2 disable voltage, 3 quick stop; each but 0 zero torque at once).  The
 * deadlines run on the clock the heartbeats do (SYNCs', or the wall's).  A hook may act on the
 * arm before each SYNC's step (the virtual user's hand).  No allocation
 * after init; the caller owns the struct.
 */
#ifndef IRDM_CAN_DRIVES_H
#define IRDM_CAN_DRIVES_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/sim/can_drive_pdo.h"
#include "irdm/sim/can_faults.h"
#include "irdm/hal/can_port.h"
#include "irdm/hal/cia402.h"
#include "irdm/sim/sim_device.h"

#define IRDM_CAN_DRIVES_MAX 3

struct irdm_can_drive {
	unsigned node;
	enum irdm_co_nmt_state nmt;
	struct irdm_cia402_drive fsa;
	int8_t mode;                      /* 0x6060: 10 = cyclic synchronous torque */
	uint16_t heartbeat_ms;            /* 0x1017: 0 = none */
	uint32_t rated_torque_mnm;        /* 0x6076: motor side, mN m */
	struct irdm_can_pdo rpdo1;        /* 0x1400, 0x1600: controlword + target torque */
	struct irdm_can_pdo tpdo1;        /* 0x1800, 0x1A00: statusword + position */
	uint32_t cycle_us;                /* 0x1006: communication cycle period (0: none) */
	uint8_t sync_overflow;            /* 0x1019: 0 SYNC without counter; 2..240 with */
	uint32_t hb_consumer;             /* 0x1016:01: node << 16 | time ms (0: off) */
	int16_t abort_option;             /* 0x6007: reaction to a lost connection */
	bool master_beat_seen, rpdo_seen; /* deadlines run from the first frame */
	uint64_t master_beat_us, rpdo_us; /* the last one (deadline clock) */
	uint16_t lost_code;               /* the time-out taken (EMCY code), 0: none */
	uint64_t lost_at_us;
	uint16_t rpdo_cw; /* the latest RPDO1 */
	int16_t rpdo_torque_permille;
	uint64_t heartbeat_next_us;
	/* injected faults */
	bool no_heartbeat;
	unsigned drop_tpdos;  /* the next k TPDOs are not sent */
	bool sdo_wrong;       /* SDO answers name another object */
	unsigned delay_tpdos; /* the next k TPDOs are held delay_us (wall) */
	uint32_t delay_us;
	bool held; /* a delayed TPDO waits for held_due_us */
	struct irdm_can_frame held_frame;
	uint64_t held_due_us;
};

struct irdm_can_drives;
/* Called at each SYNC before the arm steps; syncs counts this one (1..). */
typedef void (*irdm_can_drives_hook)(void *ctx, struct irdm_can_drives *dr);

struct irdm_can_drives {
	struct irdm_can_port port;
	struct irdm_sim_device arm;
	unsigned n;
	struct irdm_can_drive d[IRDM_CAN_DRIVES_MAX];
	double period_s;
	uint64_t now_us;
	uint8_t sync_counter; /* the last SYNC's counter byte (0: none) */
	uint64_t syncs, bad_frames, sync_length_errors;
	uint64_t tpdos_sent, tpdos_dropped, tpdos_delayed, flood_sent, faults_fired;
	bool wall_heartbeat; /* heartbeats on irdm_can_drives_wall()'s clock */
	bool docked;         /* the arm rests in its calibration dock (no
					 * steps) until a drive first applies torque */
	uint64_t wall_us;    /* the last wall time given */
	irdm_can_drives_hook before_step;
	void *hook_ctx;
	struct irdm_can_fault fault[IRDM_CAN_FAULTS_MAX];
	unsigned n_faults;
};

/*
 * n drives (1..3) on nodes first_node.., the arm dev with parameters p,
 * one SYNC = period_s.  Each drive starts pre-operational, switch on
 * disabled, and sends its boot-up heartbeat.
 * Return: IRDM_OK; IRDM_EINVAL (bad count, node range, period, or the arm
 * refused, irdm_sim_device_init()).
 */
int irdm_can_drives_init(struct irdm_can_drives *dr, const struct irdm_can_port *port,
			 const struct irdm_device_config *dev, const struct irdm_sim_params *p,
			 unsigned n, unsigned first_node, double period_s);

/* Everything waiting on the bus, answered.
 * Return: frames handled; IRDM_EIO if the port says the link is gone. */
int irdm_can_drives_poll(struct irdm_can_drives *dr);

/*
 * The wall clock moved to now_us (monotonic, microseconds): send the
 * heartbeats due on it (with wall_heartbeat) and the delayed TPDOs due.
 * Return: the wall time of the next thing due (UINT64_MAX: none).
 */
uint64_t irdm_can_drives_wall(struct irdm_can_drives *dr, uint64_t now_us);

/*
 * Schedule fault f (irdm/can_faults.h); one with at_sync 0 applies now.
 * Return: IRDM_OK; IRDM_EINVAL if its node is not one of these drives;
 * IRDM_ENOMEM if IRDM_CAN_FAULTS_MAX are scheduled.
 */
int irdm_can_drives_schedule(struct irdm_can_drives *dr, const struct irdm_can_fault *f);

/* Injected: drive k raises EMCY code (error register 0x01) and faults. */
void irdm_can_drives_fault(struct irdm_can_drives *dr, unsigned k, uint16_t code);

#endif /* IRDM_CAN_DRIVES_H */
