/* SPDX-License-Identifier: MIT */
/* irdm replay inside: its CSV inputs (replay_input.c). */
#ifndef IRDM_TOOLS_REPLAY_PRIV_H
#define IRDM_TOOLS_REPLAY_PRIV_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/telemetry.h"

struct trajectory {
	size_t n_rows, n_cols;
	double *v; /* n_rows x n_cols */
};

/* t, then ux, uy, uz per contact (nan or empty: released); |u| <= 10 m. */
int read_trajectory(const char *path, size_t n_contacts, double dt, struct trajectory *tr,
		    char *err, size_t errlen);

/* t, then tri, b0, b1, b2 per contact: tri -1 (no contact) or a surface
 * triangle < n_tris with barycentrics >= 0 summing to 1 (to 1e-9). */
int read_sites(const char *path, size_t n_contacts, double dt, uint32_t n_tris,
	       struct trajectory *tr, char *err, size_t errlen);

void irdm_trajectory_free(struct trajectory *tr);

/*
 * An irdm-fw log (irdm/telemetry.h) as the same tables (replay_log.c): per
 * record and device the engine's command (sites: tri, b0..2, -1 when none;
 * tr: its target, nan when none) and the force the controller's engine
 * gave (forces: t, then fx, fy, fz per device).  The log's period must be
 * dt and no record may be missing; *board gets the board's name it
 * recorded (IRDM_LOG_NAME_LEN bytes).
 */
struct replay_log {
	struct trajectory tr, sites, forces;
	struct trajectory softened; /* t, then 1 or 0 per device: began softly */
	unsigned n_devices;
	char board[IRDM_LOG_NAME_LEN];
};
int read_log(const char *path, double dt, uint32_t n_tris, struct replay_log *lg, char *err,
	     size_t errlen);
void replay_log_free(struct replay_log *lg);

/* How many contacts a sites file describes (its first numeric row). */
int sites_contacts(const char *path, unsigned *n, char *err, size_t errlen);

#endif
