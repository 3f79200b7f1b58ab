/* SPDX-License-Identifier: MIT */
/*
 * One PDO of an emulated drive as a strict real drive keeps it (CiA 301,
 * docs/canopen.md): its communication object (0x1400 / 0x1800: :01 the
 * COB-ID, bit 31 set = not valid; :02 the transmission type) and its
 * mapping's sub-index 0 (0x1600 / 0x1A00:00, the number of entries).  The
 * mapping may change only while the PDO is not valid and sub 0 is 0; the
 * only entries taken are the CST mapping's own, the only transmission type
 * 1 (every SYNC).  The PDO runs only valid, with its entries mapped and
 * synchronous: event-driven PDOs are not emulated.
 */
#ifndef IRDM_CAN_DRIVE_PDO_H
#define IRDM_CAN_DRIVE_PDO_H

#include <stdbool.h>
#include <stdint.h>

#define IRDM_CAN_PDO_INVALID 0x80000000u   /* COB-ID bit 31: the PDO does not exist */
#define IRDM_CAN_PDO_ENTRIES 2             /* the CST mapping's entries */
#define IRDM_CAN_PDO_SYNC_EVERY 1          /* transmission type: synchronous, every SYNC */
#define IRDM_CAN_PDO_ASYNC 0xFF            /* transmission type: event-driven (as booted) */

struct irdm_can_pdo {
	uint32_t cob_id;                /* :01, with bit 31 */
	uint8_t transmission;           /* :02 */
	uint8_t n_mapped;               /* mapping :00 */
	const uint32_t *map;            /* the entries it takes, IRDM_CAN_PDO_ENTRIES */
};

/* The stored configuration a drive boots with, as many real drives ship:
 * valid on id, map mapped, but event-driven (transmission type 0xFF), so
 * the PDO does not run until a master makes it synchronous. */
void irdm_can_pdo_boot(struct irdm_can_pdo *p, uint32_t id, const uint32_t *map);

/* Valid and mapped: sent (TPDO) or taken (RPDO). */
bool irdm_can_pdo_live(const struct irdm_can_pdo *p);

/* A download of size bytes to the communication object's sub.
 * Return: the abort code, 0 when taken. */
uint32_t irdm_can_pdo_write_comm(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size);

/* A download to the mapping object's sub.  Return: the abort code, 0 when taken. */
uint32_t irdm_can_pdo_write_map(struct irdm_can_pdo *p, uint8_t sub, uint32_t v, unsigned size);

#endif /* IRDM_CAN_DRIVE_PDO_H */
