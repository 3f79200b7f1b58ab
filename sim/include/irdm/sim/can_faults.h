/* SPDX-License-Identifier: MIT */
/*
 * Faults the CAN drive emulator injects on a schedule counted in SYNCs
 * (irdm/can_drives.h), so a run is the same whatever the wall clock does.
 * Each is written on a command line as one word:
 *
 *   drop:NODE:SYNC:K            NODE's TPDOs for SYNCs SYNC..SYNC+K-1 are not sent
 *   delay:NODE:SYNC:K:US        those TPDOs are sent US microseconds late (wall clock)
 *   heartbeat-stop:NODE:SYNC    NODE sends no heartbeat from SYNC on
 *   emcy:NODE:SYNC:CODE         NODE sends EMCY CODE (0x.. or decimal) and faults
 *   fault:NODE:SYNC             NODE faults without an EMCY (its statusword says so)
 *   sdo-wrong:NODE              NODE's SDO answers name another object (from start)
 *   flood:SYNC:COUNT            COUNT 8-byte frames of id 0x001 at SYNC (bounded)
 *
 * SYNC counts from 1 (the first SYNC the drives see).  Parsing is pure.
 */
#ifndef IRDM_CAN_FAULTS_H
#define IRDM_CAN_FAULTS_H

#include <stddef.h>
#include <stdint.h>

#define IRDM_CAN_FAULTS_MAX 16
#define IRDM_CAN_FAULT_K_MAX 100000u         /* periods a drop or delay may last */
#define IRDM_CAN_FAULT_DELAY_US_MAX 1000000u /* one second: past every time-out */
#define IRDM_CAN_FAULT_FLOOD_MAX 10000u      /* frames of one flood */
#define IRDM_CAN_FLOOD_ID 0x001u             /* wins arbitration over all but NMT */

enum irdm_can_fault_kind {
	IRDM_CAN_FAULT_DROP,
	IRDM_CAN_FAULT_DELAY,
	IRDM_CAN_FAULT_HEARTBEAT_STOP,
	IRDM_CAN_FAULT_EMCY,
	IRDM_CAN_FAULT_STATE,
	IRDM_CAN_FAULT_SDO_WRONG,
	IRDM_CAN_FAULT_FLOOD,
};

struct irdm_can_fault {
	enum irdm_can_fault_kind kind;
	unsigned node;    /* 1..127; 0 for a flood */
	uint64_t at_sync; /* 0: from the start (sdo-wrong) */
	uint32_t count;   /* drop/delay: periods; flood: frames */
	uint32_t delay_us;
	uint16_t code; /* EMCY error code */
};

/*
 * One word as above into *f.  err gets "fault 'WORD': reason".
 * Return: IRDM_OK; IRDM_EFORMAT for an unknown kind, a missing or extra
 * field, a number that is malformed or out of its range.
 */
int irdm_can_fault_parse(const char *word, struct irdm_can_fault *f, char *err, size_t errlen);

#endif /* IRDM_CAN_FAULTS_H */
