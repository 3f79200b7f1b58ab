/* SPDX-License-Identifier: MIT */
/*
 * irdm view RUN.log: a recorded irdm-fw run made into the view's recording
 * (docs/view.md).  The log holds what the controller did each tick (state,
 * tips, forces, compute time, the engine's command); the deformed surface
 * is not in it, so the run is replayed on its image and board (irdm
 * replay's --log, tools/replay/) and the surface kept every every_s.
 */
#ifndef IRDM_TOOLS_VIEW_PLAYBACK_H
#define IRDM_TOOLS_VIEW_PLAYBACK_H

#include <stddef.h>

#include "view/view_server.h"

struct view_playback_opts {
	const char *log, *board, *image;
	double every_s; /* a frame every every_s of the run (> 0) */
};

struct view_playback_summary {
	size_t records, frames;
	double duration_s;
	double log_max_diff_n, log_peak_n; /* the replay's forces against the log's */
};

/* Set s's hello and recording.  Return: IRDM_OK, or the replay's or the
 * log's error (err says why); s is then unchanged or partly recorded. */
int view_playback_load(struct view_server *s, const struct view_playback_opts *o,
		       struct view_playback_summary *sum, char *err, size_t errlen);

/*
 * irdm view DIR: a directory irdm render wrote (frames.pvd and its .vtu
 * frames) as s's hello and recording: the surface and each contact's point
 * and force, no controller state (view_render_dir.c).  Return: IRDM_OK;
 * IRDM_EIO (a file unreadable), IRDM_EFORMAT (not what irdm render
 * writes), IRDM_ENOMEM; err names the file.
 */
int view_render_dir_load(struct view_server *s, const char *dir,
			 struct view_playback_summary *sum, char *err, size_t errlen);

#endif
