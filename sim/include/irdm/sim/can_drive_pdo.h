/* SPDX-License-Identifier: MIT */
/*
 * One PDO of an emulated drive as a strict real drive keeps it (CiA 301,
 * docs/canopen.md): its communication object (0x1400 / 0x1800: :01 the
 * COB-ID, bit 31 set = not valid; :02 the transmission type) and its
 * mapping's sub-index 0 (0x1600 / 0x1A00:00, the number of entries).  The
 * mapping may change only while the PDO is not valid and sub 0 is 0; the
 * only entries taken are the CST mapping's own, the only transmission type
 * 1 (every SYNC).  The PDO runs only valid, with its entries mapped and
 * synchronous: event-driven PDOs are not emulated.  The drive serves no
 * remote request (RTR): a TPDO's COB-ID must keep bit 30 ("no RTR
 * allowed") set, as it boots, and one written with it clear is refused
 * (0x06090030), as such drives do.  :05 is the event timer (ms): on an
 * RPDO the drive's deadline (can_drives.c), on a TPDO kept and unused.
 */
#ifndef IRDM_CAN_DRIVE_PDO_H
#define IRDM_CAN_DRIVE_PDO_H

#include <stdbool.h>
#include <stdint.h>

#define IRDM_CAN_PDO_INVALID 0x80000000u  /* COB-ID bit 31: the PDO does not exist */
#define IRDM_CAN_PDO_NO_RTR 0x40000000u   /* COB-ID bit 30: no remote request allowed */
#define IRDM_CAN_PDO_EXTENDED 0x20000000u /* COB-ID bit 29: a 29-bit identifier */
#define IRDM_CAN_PDO_ENTRIES 2            /* the CST mapping's entries */
#define IRDM_CAN_PDO_SYNC_EVERY 1         /* transmission type: synchronous, every SYNC */
#define IRDM_CAN_PDO_ASYNC 0xFF           /* transmission type: event-driven (as booted) */

struct irdm_can_pdo {
	uint32_t cob_id;         /* :01, with bit 31 */
	uint8_t transmission;    /* :02 */
	uint8_t n_mapped;        /* mapping :00 */
	bool no_rtr;             /* a TPDO of a drive that serves no RTR */
	uint16_t event_timer_ms; /* :05 (0: none) */
	const uint32_t *map;     /* the entries it takes, IRDM_CAN_PDO_ENTRIES */
};

/* The stored configuration a drive boots with, as many real drives ship:
 * valid on id, map mapped, but event-driven (transmission type 0xFF), so
 * the PDO does not run until a master makes it synchronous.  An id with
 * IRDM_CAN_PDO_NO_RTR (a TPDO) keeps that bit: writes must too. */
void irdm_can_pdo_boot(struct irdm_can_pdo *p, uint32_t id, const uint32_t *map);

/* Valid and mapped: sent (TPDO) or taken (RPDO). */
bool irdm_can_pdo_live(const struct irdm_can_pdo *p);

/* A download of size bytes to the communication object's sub.
 * Return: the abort code, 0 when taken. */
uint32_t irdm_can_pdo_write_comm(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size);

/* A download to the mapping object's sub.  Return: the abort code, 0 when taken. */
uint32_t irdm_can_pdo_write_map(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size);

#endif /* IRDM_CAN_DRIVE_PDO_H */
