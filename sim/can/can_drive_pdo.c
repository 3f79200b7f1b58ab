/* SPDX-License-Identifier: MIT */
/* One PDO of an emulated drive, its objects as a strict drive keeps them
 * (irdm/can_drive_pdo.h). */
#include "irdm/sim/can_drive_pdo.h"

/* CiA 301 abort codes (names: irdm_co_abort_name()) */
#define AB_UNSUPPORTED_ACCESS 0x06010000u /* the mapping of a valid PDO, or sub 0 != 0 */
#define AB_READ_ONLY 0x06010002u
#define AB_NOT_MAPPABLE 0x06040041u
#define AB_LENGTH 0x06070010u
#define AB_NO_SUB 0x06090011u
#define AB_INVALID_VALUE 0x06090030u

void irdm_can_pdo_boot(struct irdm_can_pdo *p, uint32_t id, const uint32_t *map)
{
	p->cob_id = id;
	p->no_rtr = (id & IRDM_CAN_PDO_NO_RTR) != 0;
	p->event_timer_ms = 0;
	p->transmission = IRDM_CAN_PDO_ASYNC;
	p->n_mapped = IRDM_CAN_PDO_ENTRIES;
	p->map = map;
}

bool irdm_can_pdo_live(const struct irdm_can_pdo *p)
{
	return !(p->cob_id & IRDM_CAN_PDO_INVALID) && p->n_mapped == IRDM_CAN_PDO_ENTRIES &&
	       p->transmission == IRDM_CAN_PDO_SYNC_EVERY;
}

uint32_t irdm_can_pdo_write_comm(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size)
{
	switch (sub) {
	case 0:
		return AB_READ_ONLY; /* the highest sub-index */
	case 1:
		if (size != 4)
			return AB_LENGTH;
		/* the identifier is the default one (11 bits, not extended) */
		if ((v & (IRDM_CAN_PDO_EXTENDED | 0x1FFFFFFFu)) != (p->cob_id & 0x7FFu))
			return AB_INVALID_VALUE;
		/* no RTR served: a TPDO that would allow it is refused */
		if (p->no_rtr && !(v & IRDM_CAN_PDO_NO_RTR))
			return AB_INVALID_VALUE;
		p->cob_id = v;
		return 0;
	case 2:
		if (size != 1)
			return AB_LENGTH;
		if (v != IRDM_CAN_PDO_SYNC_EVERY)
			return AB_INVALID_VALUE;
		p->transmission = (uint8_t)v;
		return 0;
	case 5:
		if (size != 2)
			return AB_LENGTH;
		p->event_timer_ms = (uint16_t)v;
		return 0;
	default:
		return AB_NO_SUB;
	}
}

uint32_t irdm_can_pdo_write_map(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size)
{
	if (sub > IRDM_CAN_PDO_ENTRIES)
		return AB_NO_SUB;
	if (size != (sub == 0 ? 1u : 4u))
		return AB_LENGTH;
	/* a running PDO's layout must not change under the receiver's feet */
	if (!(p->cob_id & IRDM_CAN_PDO_INVALID))
		return AB_UNSUPPORTED_ACCESS;
	if (sub == 0) {
		if (v != 0 && v != IRDM_CAN_PDO_ENTRIES)
			return AB_INVALID_VALUE; /* the emulator runs the whole mapping only */
		p->n_mapped = (uint8_t)v;
		return 0;
	}
	if (p->n_mapped != 0)
		return AB_UNSUPPORTED_ACCESS; /* entries change only with the mapping off */
	return v == p->map[sub - 1] ? 0 : AB_NOT_MAPPABLE;
}
