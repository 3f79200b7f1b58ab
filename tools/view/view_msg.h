/* SPDX-License-Identifier: MIT */
/*
 * The view's messages (docs/view.md, "Messages"): little-endian binary
 * WebSocket messages, read by the page with a DataView.  The hello carries
 * the mesh at rest; a frame carries the controller's state, each device's
 * tip, proxy site and force, the chart's samples since the previous frame,
 * and, when a new one is there, every node's deformed position.
 * Writers here: irdm-fw's publisher (live) and irdm view (playback).
 */
#ifndef IRDM_TOOLS_VIEW_MSG_H
#define IRDM_TOOLS_VIEW_MSG_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "irdm/telemetry.h"

#define VIEW_MAGIC 0x56445249u /* "IRDV" */
#define VIEW_VERSION 1u
#define VIEW_KIND_HELLO 1u
#define VIEW_KIND_FRAME 2u
#define VIEW_MODE_LIVE 0u
#define VIEW_MODE_PLAYBACK 1u
#define VIEW_DEVICES 2u /* a frame always holds two device slots */
#define VIEW_HELLO_HEAD 108u
#define VIEW_FRAME_HEAD 200u
#define VIEW_SAMPLE_BYTES 16u
#define VIEW_FRAME_POSITIONS 1u /* frame flag: node positions follow */
#define VIEW_STATE_NONE 255u    /* a frame without the controller (irdm render's) */

struct view_hello {
	uint32_t mode, n_nodes, n_tris, n_dev;
	float period_s, scale_m, duration_s;
	uint32_t n_frames;    /* playback: the recording's frames (0 live) */
	const char *name;     /* the board's; cut to 63 bytes */
	const float *rest_m;  /* 3 n_nodes */
	const uint32_t *tris; /* 3 n_tris, each < n_nodes */
};

struct view_dev {
	float tip_m[3], force_n[3]; /* object frame; the force on the object */
	/* (view_frame_from_record() copies the record's tip, which is in the
	 * device frame: the caller moves it, irdm_board_device_to_object()) */
	float bary[3], target_m[3]; /* the proxy's site (tri, bary) when in contact */
	uint32_t tri;               /* UINT32_MAX: no contact */
	uint32_t proxy;             /* enum irdm_proxy_event */
};

/* One tick of the strip chart. */
struct view_sample {
	float t_s, force_n[VIEW_DEVICES], compute_us;
};

struct view_frame {
	uint32_t state, faults, n_dev;
	double tick;        /* the positions' engine tick (or the newest) */
	double t_s;         /* the frame's time in the run */
	double newest_tick; /* the loop's newest tick when the frame left */
	double sent_ms;     /* wall clock at publishing (ms since the epoch), 0 playback */
	double dropped;     /* records the view's ring dropped so far */
	struct view_dev dev[VIEW_DEVICES];
};

size_t view_hello_size(uint32_t n_nodes, uint32_t n_tris);
/*
 * The hello of an image (malloc'd into *buf, its length returned; 0: out
 * of memory): h's mode, devices, period, duration, frames and name, the
 * image's rest positions and triangles, and the colour scale fixed for
 * the run: a tenth of the object's smallest extent.
 */
size_t view_hello_image(unsigned char **buf, const struct irdm_image *img, struct view_hello *h);
/* That scale for n rest positions (3 n floats). */
float view_colour_scale(const float *rest_m, uint32_t n);
/* buf holds view_hello_size(); returns the bytes written. */
size_t view_hello_write(unsigned char *buf, const struct view_hello *h);

size_t view_frame_size(uint32_t n_nodes, uint32_t n_samples);
/* pos: 3 n_nodes floats, or NULL (no positions in this frame). */
size_t view_frame_write(unsigned char *buf, const struct view_frame *f, const float *pos,
			uint32_t n_nodes, const struct view_sample *smp, uint32_t n_samples);

/* From a telemetry record (irdm/telemetry.h): the chart's sample, and the
 * frame's state, faults and devices (its times are the caller's). */
void view_sample_from_record(struct view_sample *s, const struct irdm_tick_record *r,
			     double period_s);
void view_frame_from_record(struct view_frame *f, const struct irdm_tick_record *r);

#endif
