/* SPDX-License-Identifier: MIT */
/*
 * Report scenarios: prescribed contact trajectories on an object, in
 * offsets from the top centre of the image's nodes, resolved on an image
 * to a contact site and a target per tick.  The target is the grabbed
 * point's displacement from its rest position, in the world frame (for a
 * floating object the engine's world, docs/architecture.md).
 */
#ifndef IRDM_TOOLS_ACCURACY_SCENARIO_H
#define IRDM_TOOLS_ACCURACY_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "irdm/limits.h"

/* How a path's depth goes over time from on_s. */
enum irdm_report_shape {
	IRDM_REPORT_HOLD = 0, /* reached over ramp_s (0: a step), held */
	IRDM_REPORT_TAP,      /* in over ramp_s, back out over ramp_s */
	IRDM_REPORT_SINE,     /* depth sin(2 pi wave_hz t): there and back */
};

/* One contact: a node (the column nearest to from_m) or a point on the top
 * surface that slides from from_m to to_m (x, y; to_m's z unused); pushed
 * depth_m along dir (a unit vector; all zero: -z, down), in the shape of
 * `shape`, active in [on_s, off_s). */
struct irdm_report_path {
	bool on_node;
	double from_m[3], to_m[3];
	double slide_begin_s, slide_end_s;
	double on_s, off_s;
	double depth_m, ramp_s;
	double dir[3];
	enum irdm_report_shape shape;
	double wave_hz;
};

struct irdm_report_scenario {
	const char *name;
	const char *what; /* one line for the report */
	double duration_s;
	unsigned n_contacts;
	struct irdm_report_path path[2];
};

/* A contact of one tick, resolved on an image. */
struct irdm_report_cmd {
	bool active;
	bool on_node;
	uint32_t row; /* on_node: the image node */
	uint32_t tri; /* else: the surface triangle */
	double bary[3];
	double target_m[3];
};

/* The scenario's commands at tick t (cmd[0..n_contacts)).
 * Return: IRDM_OK; IRDM_ECONTACT if a point has no touchable surface. */
int irdm_report_scenario_cmds(const struct irdm_report_scenario *sc,
			      const struct irdm_image *img, double dt_s, size_t t,
			      struct irdm_report_cmd *cmd);

/* Ticks the scenario runs at dt_s. */
size_t irdm_report_scenario_ticks(const struct irdm_report_scenario *sc, double dt_s);

/* The shipped scenarios: grounded, then the floating cube's (12 cm). */
extern const struct irdm_report_scenario irdm_report_step, irdm_report_release,
	irdm_report_two_points, irdm_report_stroke;
extern const struct irdm_report_scenario irdm_report_swing, irdm_report_tap;

#endif
