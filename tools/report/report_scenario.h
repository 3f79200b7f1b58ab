/* SPDX-License-Identifier: MIT */
/*
 * Report scenarios: prescribed contact trajectories on the top face of a
 * grounded object, in offsets from the top centre of the image's nodes,
 * resolved on an image to a contact site and a target per tick.
 */
#ifndef IRDM_TOOLS_REPORT_SCENARIO_H
#define IRDM_TOOLS_REPORT_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "irdm/limits.h"

/* One contact: a node (the column nearest to from_m) or a point on the
 * surface that slides from from_m to to_m; pushed down depth_m along -z,
 * reached over ramp_s (0: a step), active in [on_s, off_s). */
struct irdm_report_path {
	bool on_node;
	double from_m[2], to_m[2];
	double slide_begin_s, slide_end_s;
	double on_s, off_s;
	double depth_m, ramp_s;
};

struct irdm_report_scenario {
	const char *name;
	const char *what;               /* one line for the report */
	double duration_s;
	unsigned n_contacts;
	struct irdm_report_path path[2];
};

/* A contact of one tick, resolved on an image. */
struct irdm_report_cmd {
	bool active;
	bool on_node;
	uint32_t row;                   /* on_node: the image node */
	uint32_t tri;                   /* else: the surface triangle */
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

/* The shipped scenarios. */
extern const struct irdm_report_scenario irdm_report_step, irdm_report_release,
	irdm_report_two_points, irdm_report_stroke;

#endif
