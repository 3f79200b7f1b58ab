/* SPDX-License-Identifier: MIT */
/*
 * CANopen frames (irdm/canopen.h; the layouts in docs/canopen.md).  Each
 * builder fills the whole frame (unused bytes zero); each parser checks
 * the identifier, the length and every byte it gives meaning to.
 */
#include <string.h>

#include "irdm/hal/canopen.h"

static void put16(uint8_t *p, uint16_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
}

static uint16_t get16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get32(const uint8_t *p)
{
	return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
	       ((uint32_t)p[3] << 24);
}

static bool node_ok(unsigned node)
{
	return node >= IRDM_CO_NODE_MIN && node <= IRDM_CO_NODE_MAX;
}

static void frame(struct irdm_can_frame *f, uint32_t id, uint8_t dlc)
{
	memset(f, 0, sizeof(*f));
	f->id = id;
	f->dlc = dlc;
}

int irdm_co_nmt(struct irdm_can_frame *f, enum irdm_co_nmt_cmd cmd, unsigned node)
{
	if (node > IRDM_CO_NODE_MAX)
		return IRDM_EINVAL;
	frame(f, IRDM_CO_NMT, 2);
	f->data[0] = (uint8_t)cmd;
	f->data[1] = (uint8_t)node;
	return IRDM_OK;
}

int irdm_co_sync(struct irdm_can_frame *f, unsigned counter)
{
	if (counter > 240)
		return IRDM_EINVAL;
	frame(f, IRDM_CO_SYNC, counter ? 1 : 0);
	f->data[0] = (uint8_t)counter;
	return IRDM_OK;
}

int irdm_co_rpdo_cst(struct irdm_can_frame *f, unsigned node, uint16_t controlword,
		     int16_t torque_permille)
{
	if (!node_ok(node))
		return IRDM_EINVAL;
	frame(f, IRDM_CO_RPDO1 + node, 4);
	put16(f->data, controlword);
	put16(f->data + 2, (uint16_t)torque_permille);
	return IRDM_OK;
}

/* Byte 0 of an expedited transfer of size bytes: n = 4 - size, e = s = 1. */
static uint8_t expedited(uint8_t command, unsigned size)
{
	return (uint8_t)(command | ((4 - size) << 2) | 0x03);
}

int irdm_co_sdo_write(struct irdm_can_frame *f, unsigned node, uint16_t index, uint8_t sub,
		      uint32_t value, unsigned size)
{
	if (!node_ok(node) || size < 1 || size > 4)
		return IRDM_EINVAL;
	frame(f, IRDM_CO_SDO_RX + node, 8);
	f->data[0] = expedited(0x20, size); /* initiate download */
	put16(f->data + 1, index);
	f->data[3] = sub;
	for (unsigned k = 0; k < size; k++)
		f->data[4 + k] = (uint8_t)(value >> (8 * k));
	return IRDM_OK;
}

int irdm_co_sdo_read(struct irdm_can_frame *f, unsigned node, uint16_t index, uint8_t sub)
{
	if (!node_ok(node))
		return IRDM_EINVAL;
	frame(f, IRDM_CO_SDO_RX + node, 8);
	f->data[0] = 0x40; /* initiate upload */
	put16(f->data + 1, index);
	f->data[3] = sub;
	return IRDM_OK;
}

unsigned irdm_co_node_of(const struct irdm_can_frame *f, enum irdm_co_function fn)
{
	unsigned node = f->id - (uint32_t)fn;

	return f->id > (uint32_t)fn && node_ok(node) ? node : 0;
}

static bool from(const struct irdm_can_frame *f, enum irdm_co_function fn, unsigned node,
		 uint8_t dlc)
{
	return node_ok(node) && f->id == (uint32_t)fn + node && f->dlc == dlc;
}

int irdm_co_tpdo_cst(const struct irdm_can_frame *f, unsigned node, uint16_t *statusword,
		     int32_t *position_counts)
{
	if (!from(f, IRDM_CO_TPDO1, node, 6))
		return IRDM_EFORMAT;
	*statusword = get16(f->data);
	*position_counts = (int32_t)get32(f->data + 2);
	return IRDM_OK;
}

int irdm_co_heartbeat(const struct irdm_can_frame *f, unsigned node,
		      enum irdm_co_nmt_state *state)
{
	uint8_t s;

	if (!from(f, IRDM_CO_HEARTBEAT, node, 1))
		return IRDM_EFORMAT;
	s = f->data[0] & 0x7F; /* bit 7: the toggle of node guarding */
	if (s != IRDM_CO_STATE_BOOTUP && s != IRDM_CO_STATE_STOPPED &&
	    s != IRDM_CO_STATE_OPERATIONAL && s != IRDM_CO_STATE_PRE_OPERATIONAL)
		return IRDM_EFORMAT;
	*state = (enum irdm_co_nmt_state)s;
	return IRDM_OK;
}

int irdm_co_emcy(const struct irdm_can_frame *f, unsigned node, struct irdm_co_emcy *e)
{
	if (!from(f, IRDM_CO_EMCY, node, 8))
		return IRDM_EFORMAT;
	e->code = get16(f->data);
	e->reg = f->data[2];
	memcpy(e->vendor, f->data + 3, sizeof(e->vendor));
	return IRDM_OK;
}

int irdm_co_sdo_answer(const struct irdm_can_frame *f, unsigned node, uint16_t index,
		       uint8_t sub, uint32_t *value, unsigned *size, uint32_t *abort_code)
{
	uint8_t cmd = f->data[0];

	if (!from(f, IRDM_CO_SDO_TX, node, 8) || get16(f->data + 1) != index || f->data[3] != sub)
		return IRDM_EFORMAT;
	*value = 0;
	*size = 0;
	if (cmd == 0x80) { /* abort */
		*abort_code = get32(f->data + 4);
		return IRDM_EHW;
	}
	if (cmd == 0x60) /* download confirmed */
		return IRDM_OK;
	if ((cmd & 0xF3) != 0x43) /* expedited upload, size given */
		return IRDM_EFORMAT;
	*size = 4 - ((cmd >> 2) & 3);
	for (unsigned k = 0; k < *size; k++)
		*value |= (uint32_t)f->data[4 + k] << (8 * k);
	return IRDM_OK;
}

static const struct {
	uint32_t code;
	const char *name;
} aborts[] = {
	{ 0x05030000, "toggle bit not alternated" },
	{ 0x05040000, "SDO protocol timed out" },
	{ 0x05040001, "command specifier not valid or unknown" },
	{ 0x05040005, "out of memory" },
	{ 0x06010000, "unsupported access to an object" },
	{ 0x06010001, "attempt to read a write-only object" },
	{ 0x06010002, "attempt to write a read-only object" },
	{ 0x06020000, "object does not exist in the object dictionary" },
	{ 0x06040041, "object cannot be mapped to the PDO" },
	{ 0x06040042, "the mapped objects would exceed the PDO length" },
	{ 0x06040043, "general parameter incompatibility" },
	{ 0x06040047, "general internal incompatibility in the device" },
	{ 0x06060000, "access failed due to a hardware error" },
	{ 0x06070010, "data type does not match: length of service parameter" },
	{ 0x06070012, "data type does not match: length too high" },
	{ 0x06070013, "data type does not match: length too low" },
	{ 0x06090011, "sub-index does not exist" },
	{ 0x06090030, "invalid value for parameter" },
	{ 0x06090031, "value of parameter written too high" },
	{ 0x06090032, "value of parameter written too low" },
	{ 0x06090036, "maximum value is less than minimum value" },
	{ 0x08000000, "general error" },
	{ 0x08000020, "data cannot be transferred or stored to the application" },
	{ 0x08000021, "data cannot be stored: local control" },
	{ 0x08000022, "data cannot be stored: present device state" },
	{ 0x08000023, "no object dictionary" },
	{ 0x08000024, "no data available" },
};

const char *irdm_co_abort_name(uint32_t code)
{
	for (size_t k = 0; k < sizeof(aborts) / sizeof(aborts[0]); k++)
		if (aborts[k].code == code)
			return aborts[k].name;
	return "unknown abort code";
}

const char *irdm_co_emcy_class(uint16_t code)
{
	static const char *const cls[16] = {
		"no error (reset)",
		"generic",
		"current",
		"voltage",
		"temperature",
		"device hardware",
		"device software",
		"additional modules",
		"monitoring",
		"external",
		"unknown class",
		"unknown class",
		"unknown class",
		"unknown class",
		"unknown class",
		"device specific",
	};

	return cls[code >> 12];
}

unsigned irdm_can_frame_bits(unsigned dlc, bool worst_case)
{
	unsigned bits = 47 + 8 * dlc, stuffed = 34 + 8 * dlc;

	return worst_case ? bits + (stuffed - 1) / 4 : bits;
}
