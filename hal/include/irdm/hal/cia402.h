/* SPDX-License-Identifier: MIT */
/*
 * The CiA 402 drive state machine (docs/canopen.md), both sides:
 *  - the master's: a statusword decoded to a state, and the controlword
 *    that moves a drive one step toward "operation enabled" (or resets its
 *    fault, on request only: a faulted device never re-enables by itself);
 *  - the drive's (the emulator's): the transitions a controlword and a
 *    fault cause, and the statusword of each state.
 * Pure functions and a two-field struct: no allocation, no system call.
 */
#ifndef IRDM_CIA402_H
#define IRDM_CIA402_H

#include <stdbool.h>
#include <stdint.h>

enum irdm_cia402_state {
	IRDM_CIA402_NOT_READY = 0, /* self-test after power-on */
	IRDM_CIA402_SWITCH_ON_DISABLED,
	IRDM_CIA402_READY_TO_SWITCH_ON,
	IRDM_CIA402_SWITCHED_ON,
	IRDM_CIA402_OPERATION_ENABLED, /* the only state that applies torque */
	IRDM_CIA402_QUICK_STOP_ACTIVE,
	IRDM_CIA402_FAULT_REACTION_ACTIVE,
	IRDM_CIA402_FAULT,
	IRDM_CIA402_UNKNOWN, /* a statusword no state has */
};

/* Controlword commands (0x6040); fault reset is bit 7's rising edge. */
#define IRDM_CIA402_CW_DISABLE_VOLTAGE 0x0000
#define IRDM_CIA402_CW_QUICK_STOP 0x0002
#define IRDM_CIA402_CW_SHUTDOWN 0x0006
#define IRDM_CIA402_CW_SWITCH_ON 0x0007 /* also "disable operation" */
#define IRDM_CIA402_CW_ENABLE_OPERATION 0x000F
#define IRDM_CIA402_CW_FAULT_RESET 0x0080

enum irdm_cia402_state irdm_cia402_decode(uint16_t statusword);
const char *irdm_cia402_name(enum irdm_cia402_state s);

/*
 * Master: the controlword for a drive in state s.  prev_cw is the last one
 * sent (a fault reset needs bit 7 to rise: 0x80 after a 0x00).  Toward
 * operation enabled from every state but FAULT, which is reset only when
 * reset_fault is true (else held at disable voltage).
 */
uint16_t irdm_cia402_next(enum irdm_cia402_state s, bool reset_fault, uint16_t prev_cw);

/* Drive: its state and the last controlword (for bit 7's edge). */
struct irdm_cia402_drive {
	enum irdm_cia402_state state;
	uint16_t last_cw;
};

/* Power-on: self-test done, switch on disabled. */
void irdm_cia402_drive_init(struct irdm_cia402_drive *d);

/* A controlword arrives: the transition it commands, if any. */
void irdm_cia402_drive_command(struct irdm_cia402_drive *d, uint16_t controlword);

/* A fault: to fault reaction active; irdm_cia402_drive_settle() ends the
 * reaction in FAULT (transition 14). */
void irdm_cia402_drive_fault(struct irdm_cia402_drive *d);
void irdm_cia402_drive_settle(struct irdm_cia402_drive *d);

/* The statusword (0x6041) the drive reports in state s. */
uint16_t irdm_cia402_statusword(enum irdm_cia402_state s);

#endif /* IRDM_CIA402_H */
