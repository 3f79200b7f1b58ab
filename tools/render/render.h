/* SPDX-License-Identifier: MIT */
/*
 * irdm render: a replay (or an irdm-fw log, replayed) with the whole
 * displayed surface kept every so often: VTK XML frames (.vtu) and a .pvd
 * collection for ParaView, a frames CSV (time, contact point, force) and
 * the forces CSV of every sample, all in one directory written whole or
 * not at all.  tools/scripts/plot-surface.py and plot-forces.py draw them.
 */
#ifndef IRDM_TOOLS_RENDER_H
#define IRDM_TOOLS_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "replay/replay.h"

#define IRDM_RENDER_MAX_FRAMES 5000

struct irdm_render_opts {
	struct irdm_replay_opts in; /* the inputs as irdm replay's (its out unused) */
	const char *out_dir;
	bool force;     /* replace out_dir even if irdm render did not write it */
	double every_s; /* a frame every every_s, rounded to samples (> 0) */
};

/* The displayed surface (render_surface.c): what the frames can show. */
struct irdm_render_surface {
	uint32_t nodes, tris;
	uint32_t open_edges; /* edges of one triangle: 0 for a closed surface */
	char display[64];    /* the scene's display key (provenance), "" if unknown */
};

struct irdm_render_summary {
	struct irdm_replay_summary replay;
	struct irdm_render_surface surface;
	size_t frames, every_rows;
	double max_disp_m, max_disp_t_s; /* over the frames' nodes */
	unsigned debris_removed;         /* interrupted runs' directories beside DIR, removed */
};

int irdm_render_run(const struct irdm_render_opts *o, struct irdm_render_summary *sum,
		    char *err, size_t errlen);

void irdm_render_surface(const struct irdm_image *img, struct irdm_render_surface *s);

/* render_vtu.c: one frame (the replay's current sample, at t_s) as .vtu at
 * path (0 or errno); the collection's head, one entry, tail. */
int irdm_render_write_vtu(const char *path, struct irdm_replay *r, double t_s, const double *pos_m);
void irdm_render_pvd_begin(FILE *f);
void irdm_render_pvd_entry(FILE *f, double t_s, const char *file);
void irdm_render_pvd_end(FILE *f);

#endif
