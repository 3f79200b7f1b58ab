/* SPDX-License-Identifier: MIT */
/* Running the force engine on a prescribed trajectory (irdm replay). */
#ifndef IRDM_TOOLS_REPLAY_H
#define IRDM_TOOLS_REPLAY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/engine.h"
#include "irdm/error.h"
#include "irdm/session.h"

struct irdm_replay_contact {
	bool is_node;
	uint32_t mesh_node;
	double point_m[3];
};

struct irdm_replay; /* a run in progress (the on_tick hook's handle) */

struct irdm_replay_opts {
	const char *image, *trajectory, *out, *nodes;
	const char *sites; /* per-sample sites (irdm replay --sites), or NULL */
	/* an irdm-fw log and the board it ran on, instead of trajectory and
	 * sites: the engine as the controller configured it (push contacts,
	 * the board's coupling and passivity control), one row per record */
	const char *log, *board;
	unsigned n_contacts;
	struct irdm_replay_contact contact[IRDM_MAX_CONTACTS];
	enum irdm_contact_mode mode;
	enum irdm_solve_mode solve;
	double coupling_k, coupling_b;
	bool passivity; /* the engine's passivity control (a haptic board's) */
	/*
	 * Called after every sample's tick, once its forces are written; a
	 * non-zero return stops the run with that error (irdm render: the
	 * frames).  deform: open the deformation channel for it even without
	 * --nodes (irdm_replay_positions()).
	 */
	int (*on_tick)(void *ctx, struct irdm_replay *r, char *err, size_t errlen);
	void *ctx;
	bool deform;
};

/* What a run did: its samples and, for --log, the largest distance
 * between the engine's forces and the logged ones, beside their peak. */
struct irdm_replay_summary {
	size_t rows;
	double log_max_diff_n, log_peak_n;
};

void irdm_replay_opts_default(struct irdm_replay_opts *o);
/* sum may be NULL.  The forces CSV is written whole or not at all. */
int irdm_replay_run(const struct irdm_replay_opts *o, struct irdm_replay_summary *sum, char *err,
		    size_t errlen);

/* For on_tick: the session (image, engine), the sample (row; the rows in
 * all), the contacts the run drives. */
const struct irdm_session *irdm_replay_session(const struct irdm_replay *r);
size_t irdm_replay_row(const struct irdm_replay *r);
size_t irdm_replay_rows(const struct irdm_replay *r);
unsigned irdm_replay_contacts(const struct irdm_replay *r);
/* Every image node's world position after this sample's tick (3 n_nodes),
 * computed once per sample; NULL without the deformation channel. */
const double *irdm_replay_positions(struct irdm_replay *r);

/* Nearest point of the touchable surface (the image's contact BVH):
 * triangle and barycentrics; -1 if the image has none. */
int irdm_replay_locate(const struct irdm_image *img, const double p[3], uint32_t *tri,
		       double bary[3]);

#endif
