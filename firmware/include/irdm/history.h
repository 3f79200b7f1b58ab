/* SPDX-License-Identifier: MIT */
/* The force history the engine keeps and hands to the deformation context. */
#ifndef IRDM_HISTORY_H
#define IRDM_HISTORY_H

#include <stdint.h>

#include "irdm/limits.h" /* IRDM_MAX_FORCE_NODES */

/* The forces of one tick, applied at up to IRDM_MAX_FORCE_NODES columns. */
struct irdm_force_tick {
	uint32_t n;                          /* force nodes this tick */
	uint32_t col[IRDM_MAX_FORCE_NODES];  /* column index of each */
	double f_n[IRDM_MAX_FORCE_NODES][3]; /* force on the object, object frame */
};

/*
 * FIR history: ring[(head - s) mod T] holds the forces of tick t - s, s < T;
 * head is the slot of the newest tick.
 */
struct irdm_fir_ring {
	uint32_t T;
	uint32_t head;
	struct irdm_force_tick *tick; /* T entries */
};

/* Rigid pose of a floating object (identity for a grounded one). */
struct irdm_pose {
	double com_m[3]; /* world position of the centre of mass */
	double q[4];     /* orientation (w, x, y, z), body -> world */
};

#endif
