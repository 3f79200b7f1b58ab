/* SPDX-License-Identifier: MIT */
/*
 * CANopen frames for CiA 402 drives in cyclic synchronous torque mode
 * (docs/canopen.md): building the frames a master sends and checking the
 * frames it receives.  Pure functions on caller memory: no allocation, no
 * system call; the force tick may call every one of them.
 *
 * Frames are classical CAN: an 11-bit identifier (COB-ID = function code +
 * node id 1..127) and 0..8 data bytes; every multi-byte field is little
 * endian.  A parser trusts nothing: a frame of the wrong identifier,
 * length or content is refused with IRDM_EFORMAT and the caller counts it.
 */
#ifndef IRDM_CANOPEN_H
#define IRDM_CANOPEN_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/error.h"

struct irdm_can_frame {
	uint32_t id; /* 11-bit COB-ID */
	uint8_t dlc; /* data bytes, 0..8 */
	uint8_t data[8];
};

/* Function codes (the COB-ID less the node id). */
enum irdm_co_function {
	IRDM_CO_NMT = 0x000,
	IRDM_CO_SYNC = 0x080,
	IRDM_CO_EMCY = 0x080, /* + node id 1..127 (SYNC is node id 0) */
	IRDM_CO_TPDO1 = 0x180,
	IRDM_CO_RPDO1 = 0x200,
	IRDM_CO_TPDO2 = 0x280,
	IRDM_CO_RPDO2 = 0x300,
	IRDM_CO_SDO_TX = 0x580, /* drive -> master (the server's answer) */
	IRDM_CO_SDO_RX = 0x600, /* master -> drive (the client's request) */
	IRDM_CO_HEARTBEAT = 0x700,
};

#define IRDM_CO_NODE_MIN 1
#define IRDM_CO_NODE_MAX 127

/* NMT commands and the states a heartbeat reports. */
enum irdm_co_nmt_cmd {
	IRDM_CO_NMT_START = 0x01,
	IRDM_CO_NMT_STOP = 0x02,
	IRDM_CO_NMT_PRE_OPERATIONAL = 0x80,
	IRDM_CO_NMT_RESET_NODE = 0x81,
	IRDM_CO_NMT_RESET_COMM = 0x82,
};
enum irdm_co_nmt_state {
	IRDM_CO_STATE_BOOTUP = 0x00,
	IRDM_CO_STATE_STOPPED = 0x04,
	IRDM_CO_STATE_OPERATIONAL = 0x05,
	IRDM_CO_STATE_PRE_OPERATIONAL = 0x7F,
};

/* ---- building (master -> bus) ---- */

/* NMT command to node (0: every node).  IRDM_EINVAL: node > 127. */
int irdm_co_nmt(struct irdm_can_frame *f, enum irdm_co_nmt_cmd cmd, unsigned node);

/* SYNC: no data, or one counter byte when counter is 1..240 (0: none). */
int irdm_co_sync(struct irdm_can_frame *f, unsigned counter);

/* The CST set-point RPDO1 of node: controlword (0x6040) and target torque
 * (0x6071, per mille of the rated torque 0x6076), 4 bytes. */
int irdm_co_rpdo_cst(struct irdm_can_frame *f, unsigned node, uint16_t controlword,
		     int16_t torque_permille);

/*
 * Expedited SDO download (write) of 1..4 bytes of value to index:sub of
 * node; and upload (read) request.  IRDM_EINVAL: node or size out of range.
 */
int irdm_co_sdo_write(struct irdm_can_frame *f, unsigned node, uint16_t index, uint8_t sub,
		      uint32_t value, unsigned size);
int irdm_co_sdo_read(struct irdm_can_frame *f, unsigned node, uint16_t index, uint8_t sub);

/* ---- parsing (bus -> master); IRDM_EFORMAT for anything else ---- */

/* Node id of a frame from a node with this function code, or 0. */
unsigned irdm_co_node_of(const struct irdm_can_frame *f, enum irdm_co_function fn);

/* TPDO1 of node: statusword (0x6041) and position actual (0x6064), 6 bytes. */
int irdm_co_tpdo_cst(const struct irdm_can_frame *f, unsigned node, uint16_t *statusword,
		     int32_t *position_counts);

/* Heartbeat of node: its NMT state (one byte, a known state). */
int irdm_co_heartbeat(const struct irdm_can_frame *f, unsigned node,
		      enum irdm_co_nmt_state *state);

/* EMCY of node: error code (0x603F/0x1003 style), error register, 8 bytes. */
struct irdm_co_emcy {
	uint16_t code;
	uint8_t reg;
	uint8_t vendor[5];
};
int irdm_co_emcy(const struct irdm_can_frame *f, unsigned node, struct irdm_co_emcy *e);

/*
 * The answer of node's SDO server to a request for index:sub.
 * Return: IRDM_OK with *value (uploads; 0 for a download's confirmation)
 * and *size (bytes of an expedited upload, 0 for a download);
 * IRDM_EHW with *abort_code for an abort (name: irdm_co_abort_name());
 * IRDM_EFORMAT if it is not a well-formed answer for that object.
 */
int irdm_co_sdo_answer(const struct irdm_can_frame *f, unsigned node, uint16_t index,
		       uint8_t sub, uint32_t *value, unsigned *size, uint32_t *abort_code);

/* What an SDO abort code means (CiA 301), or "unknown abort code". */
const char *irdm_co_abort_name(uint32_t code);

/* What an EMCY error code's class is (the high byte), e.g. "current". */
const char *irdm_co_emcy_class(uint16_t code);

/* ---- bus load ---- */

/*
 * Bits on the wire of a classical CAN data frame with an 11-bit identifier
 * and dlc data bytes: 47 + 8 dlc without stuff bits; worst case adds one
 * stuff bit per 4 bits of the stuffed part (start of frame to CRC:
 * 34 + 8 dlc bits), (34 + 8 dlc - 1) / 4 of them.
 */
unsigned irdm_can_frame_bits(unsigned dlc, bool worst_case);

#endif /* IRDM_CANOPEN_H */
