/* SPDX-License-Identifier: MIT */
/*
 * Fixed limits of the force tick, shared by the engine, the force history
 * and the deformation channel: every array the tick touches is sized by
 * them at compile time (no allocation in the loop).
 */
#ifndef IRDM_LIMITS_H
#define IRDM_LIMITS_H

#define IRDM_MAX_CONTACTS 4
#define IRDM_MAX_FORCE_NODES (3 * IRDM_MAX_CONTACTS) /* a contact spreads over <= 3 nodes */
/*
 * Largest contact target the engine takes (metres, per axis).  A device
 * reports positions within a metre or two; a target of 1e300 m is a broken
 * input, not a position, and its finite force (6e304 N under a rigid
 * coupling) overflowed the energy observer's F . du.
 */
#define IRDM_MAX_TARGET_M 1e6

#endif /* IRDM_LIMITS_H */
