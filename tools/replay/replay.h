/* SPDX-License-Identifier: MIT */
/* Running the force engine on a prescribed trajectory (irdm replay). */
#ifndef IRDM_TOOLS_REPLAY_H
#define IRDM_TOOLS_REPLAY_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/engine.h"
#include "irdm/error.h"

struct irdm_replay_contact {
	bool is_node;
	uint32_t mesh_node;
	double point_m[3];
};

struct irdm_replay_opts {
	const char *image, *trajectory, *out, *nodes;
	const char *sites;              /* per-sample sites (irdm replay --sites), or NULL */
	unsigned n_contacts;
	struct irdm_replay_contact contact[IRDM_MAX_CONTACTS];
	enum irdm_contact_mode mode;
	enum irdm_solve_mode solve;
	double coupling_k, coupling_b;
	bool passivity;                 /* the engine's passivity control (a haptic board's) */
};

void irdm_replay_opts_default(struct irdm_replay_opts *o);
int irdm_replay_run(const struct irdm_replay_opts *o, char *err, size_t errlen);

/* Nearest point of the touchable surface (the image's contact BVH):
 * triangle and barycentrics; -1 if the image has none. */
int irdm_replay_locate(const struct irdm_image *img, const double p[3], uint32_t *tri,
		       double bary[3]);

#endif
