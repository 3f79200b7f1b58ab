/* SPDX-License-Identifier: MIT */
/*
 * Fixed limits of the force tick, shared by the engine, the force history
 * and the deformation channel: every array the tick touches is sized by
 * them at compile time (no allocation in the loop).
 */
#ifndef IRDM_LIMITS_H
#define IRDM_LIMITS_H

#define IRDM_MAX_CONTACTS 4
#define IRDM_MAX_FORCE_NODES (3 * IRDM_MAX_CONTACTS)  /* a contact spreads over <= 3 nodes */

#endif /* IRDM_LIMITS_H */
