/* SPDX-License-Identifier: MIT */
/*
 * The CiA 402 state machine (irdm/cia402.h).  Transition numbers in the
 * comments are the profile's (docs/canopen.md draws the graph).
 */
#include "irdm/hal/cia402.h"

/* statusword mask -> value of each state */
static const struct {
	uint16_t mask, value;
	enum irdm_cia402_state state;
} decode_table[] = {
	{ 0x4F, 0x00, IRDM_CIA402_NOT_READY },
	{ 0x4F, 0x40, IRDM_CIA402_SWITCH_ON_DISABLED },
	{ 0x6F, 0x21, IRDM_CIA402_READY_TO_SWITCH_ON },
	{ 0x6F, 0x23, IRDM_CIA402_SWITCHED_ON },
	{ 0x6F, 0x27, IRDM_CIA402_OPERATION_ENABLED },
	{ 0x6F, 0x07, IRDM_CIA402_QUICK_STOP_ACTIVE },
	{ 0x4F, 0x0F, IRDM_CIA402_FAULT_REACTION_ACTIVE },
	{ 0x4F, 0x08, IRDM_CIA402_FAULT },
};

enum irdm_cia402_state irdm_cia402_decode(uint16_t sw)
{
	for (unsigned k = 0; k < sizeof(decode_table) / sizeof(decode_table[0]); k++)
		if ((sw & decode_table[k].mask) == decode_table[k].value)
			return decode_table[k].state;
	return IRDM_CIA402_UNKNOWN;
}

const char *irdm_cia402_name(enum irdm_cia402_state s)
{
	static const char *const names[] = {
		"not ready to switch on",
		"switch on disabled",
		"ready to switch on",
		"switched on",
		"operation enabled",
		"quick stop active",
		"fault reaction active",
		"fault",
		"unknown",
	};

	return s <= IRDM_CIA402_UNKNOWN ? names[s] : "unknown";
}

uint16_t irdm_cia402_next(enum irdm_cia402_state s, bool reset_fault, uint16_t prev_cw)
{
	switch (s) {
	case IRDM_CIA402_SWITCH_ON_DISABLED:
		return IRDM_CIA402_CW_SHUTDOWN; /* 2 */
	case IRDM_CIA402_READY_TO_SWITCH_ON:
		return IRDM_CIA402_CW_SWITCH_ON; /* 3 */
	case IRDM_CIA402_SWITCHED_ON:
	case IRDM_CIA402_OPERATION_ENABLED:
		return IRDM_CIA402_CW_ENABLE_OPERATION; /* 4, then hold */
	case IRDM_CIA402_FAULT:
		/* 15 on a rising edge of bit 7: 0x80 only after a 0x00 */
		if (reset_fault && !(prev_cw & IRDM_CIA402_CW_FAULT_RESET))
			return IRDM_CIA402_CW_FAULT_RESET;
		return IRDM_CIA402_CW_DISABLE_VOLTAGE;
	case IRDM_CIA402_QUICK_STOP_ACTIVE: /* 12, then up again */
	case IRDM_CIA402_NOT_READY:
	case IRDM_CIA402_FAULT_REACTION_ACTIVE:
	case IRDM_CIA402_UNKNOWN:
	default:
		return IRDM_CIA402_CW_DISABLE_VOLTAGE;
	}
}

void irdm_cia402_drive_init(struct irdm_cia402_drive *d)
{
	d->state = IRDM_CIA402_SWITCH_ON_DISABLED; /* 0 then 1: self-test passed */
	d->last_cw = 0;
}

/* The command a controlword gives (bit 7 clear), as the profile decodes it. */
enum command { CMD_NONE,
	       CMD_DISABLE_VOLTAGE,
	       CMD_QUICK_STOP,
	       CMD_SHUTDOWN,
	       CMD_SWITCH_ON,
	       CMD_ENABLE_OPERATION };

static enum command command_of(uint16_t cw)
{
	if (cw & 0x80)
		return CMD_NONE;
	if ((cw & 0x02) == 0x00)
		return CMD_DISABLE_VOLTAGE; /* 0xxx xx0x */
	if ((cw & 0x06) == 0x02)
		return CMD_QUICK_STOP; /* 0xxx x01x */
	if ((cw & 0x07) == 0x06)
		return CMD_SHUTDOWN; /* 0xxx x110 */
	if ((cw & 0x0F) == 0x07)
		return CMD_SWITCH_ON; /* 0xxx 0111 */
	return CMD_ENABLE_OPERATION;  /* 0xxx 1111 */
}

static enum irdm_cia402_state after(enum irdm_cia402_state s, enum command c)
{
	switch (s) {
	case IRDM_CIA402_SWITCH_ON_DISABLED:
		return c == CMD_SHUTDOWN ? IRDM_CIA402_READY_TO_SWITCH_ON : s; /* 2 */
	case IRDM_CIA402_READY_TO_SWITCH_ON:
		if (c == CMD_SWITCH_ON)
			return IRDM_CIA402_SWITCHED_ON; /* 3 */
		if (c == CMD_ENABLE_OPERATION)
			return IRDM_CIA402_OPERATION_ENABLED; /* 3 + 4 */
		if (c == CMD_DISABLE_VOLTAGE || c == CMD_QUICK_STOP)
			return IRDM_CIA402_SWITCH_ON_DISABLED; /* 7 */
		return s;
	case IRDM_CIA402_SWITCHED_ON:
		if (c == CMD_ENABLE_OPERATION)
			return IRDM_CIA402_OPERATION_ENABLED; /* 4 */
		if (c == CMD_SHUTDOWN)
			return IRDM_CIA402_READY_TO_SWITCH_ON; /* 6 */
		if (c == CMD_DISABLE_VOLTAGE || c == CMD_QUICK_STOP)
			return IRDM_CIA402_SWITCH_ON_DISABLED; /* 10 */
		return s;
	case IRDM_CIA402_OPERATION_ENABLED:
		if (c == CMD_SWITCH_ON)
			return IRDM_CIA402_SWITCHED_ON; /* 5 */
		if (c == CMD_SHUTDOWN)
			return IRDM_CIA402_READY_TO_SWITCH_ON; /* 8 */
		if (c == CMD_DISABLE_VOLTAGE)
			return IRDM_CIA402_SWITCH_ON_DISABLED; /* 9 */
		if (c == CMD_QUICK_STOP)
			return IRDM_CIA402_QUICK_STOP_ACTIVE; /* 11 */
		return s;
	case IRDM_CIA402_QUICK_STOP_ACTIVE:
		if (c == CMD_DISABLE_VOLTAGE)
			return IRDM_CIA402_SWITCH_ON_DISABLED; /* 12 */
		if (c == CMD_ENABLE_OPERATION)
			return IRDM_CIA402_OPERATION_ENABLED; /* 16 */
		return s;
	default:
		return s;
	}
}

void irdm_cia402_drive_command(struct irdm_cia402_drive *d, uint16_t cw)
{
	bool edge = (cw & 0x80) && !(d->last_cw & 0x80);

	if (d->state == IRDM_CIA402_FAULT) {
		if (edge)
			d->state = IRDM_CIA402_SWITCH_ON_DISABLED; /* 15 */
	} else {
		d->state = after(d->state, command_of(cw));
	}
	d->last_cw = cw;
}

void irdm_cia402_drive_fault(struct irdm_cia402_drive *d)
{
	if (d->state != IRDM_CIA402_FAULT)
		d->state = IRDM_CIA402_FAULT_REACTION_ACTIVE; /* 13 */
}

void irdm_cia402_drive_settle(struct irdm_cia402_drive *d)
{
	if (d->state == IRDM_CIA402_FAULT_REACTION_ACTIVE)
		d->state = IRDM_CIA402_FAULT; /* 14 */
}

uint16_t irdm_cia402_statusword(enum irdm_cia402_state s)
{
	/* bit 4 (voltage enabled) while the power stage is on */
	static const uint16_t sw[] = { 0x0000, 0x0040, 0x0021, 0x0033, 0x0037, 0x0017, 0x001F,
				       0x0008, 0x0000 };

	return s <= IRDM_CIA402_UNKNOWN ? sw[s] : 0;
}
