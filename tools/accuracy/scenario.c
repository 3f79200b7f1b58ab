/* SPDX-License-Identifier: MIT */
/* The report's scenarios and their commands tick by tick. */
#include <math.h>
#include <string.h>

#include "irdm/error.h"
#include "replay/replay.h"
#include "accuracy/scenario.h"

/* The paper's Fig. 6a: the top centre pushed 1 cm at once and held. */
const struct irdm_report_scenario irdm_report_step = {
	.name = "step",
	.what = "top centre node pushed 1 cm at once, held 3 s",
	.duration_s = 3.0,
	.n_contacts = 1,
	.path = { { .on_node = true, .on_s = 0, .off_s = 1e9, .depth_m = 0.01 } },
};

/* Free vibration after a let-go: the same push for 1 s, then 2 s free. */
const struct irdm_report_scenario irdm_report_release = {
	.name = "release",
	.what = "top centre node pushed 1 cm at once, let go after 1 s, 2 s free",
	.duration_s = 3.0,
	.n_contacts = 1,
	.path = { { .on_node = true, .on_s = 0, .off_s = 1.0, .depth_m = 0.01 } },
};

/* Fig. 6b: one point held, a second pushed beside it. */
const struct irdm_report_scenario irdm_report_two_points = {
	.name = "two-points",
	.what = "top centre node held 5 mm down; the node one cell away diagonally (2.5 cm on the 4x4x8 mesh) pushed to 1 cm over 0.5 s from 0.2 s, both held to 2 s",
	.duration_s = 2.0,
	.n_contacts = 2,
	.path = { { .on_node = true, .on_s = 0, .off_s = 1e9, .depth_m = 0.005 },
		  { .on_node = true, .from_m = { 0.025, 0.025 }, .on_s = 0.2, .off_s = 1e9, .depth_m = 0.01, .ramp_s = 0.5 } },
};

/* Fig. 6c: a point pressed and stroked across the top's triangles. */
const struct irdm_report_scenario irdm_report_stroke = {
	.name = "stroke",
	.what = "a point pressed 5 mm over 0.1 s, stroked 2.1 cm across the top's triangles (beside the centre) in 1 s, held to 2 s",
	.duration_s = 2.0,
	.n_contacts = 1,
	.path = { { .on_node = false, .from_m = { 0.002, 0.011 }, .to_m = { 0.023, 0.014 }, .slide_begin_s = 0.2, .slide_end_s = 1.2, .on_s = 0, .off_s = 1e9, .depth_m = 0.005, .ramp_s = 0.1 } },
};

/*
 * The paper's Fig. 9 (the swing of test_floating): the floating cube
 * grabbed at the top centre node, the grab point moved 3 cm sideways
 * (+x) and back, to 3 cm the other way and back, twice (1 Hz); no gravity,
 * so the cube follows and turns about the grab point.
 */
const struct irdm_report_scenario irdm_report_swing = {
	.name = "swing",
	.what = "floating cube grabbed at the top centre node, the grab point moved +-3 cm sideways (x) at 1 Hz, 2 periods",
	.duration_s = 2.0,
	.n_contacts = 1,
	.path = { { .on_node = true, .on_s = 0, .off_s = 1e9, .depth_m = 0.03, .dir = { 1, 0, 0 }, .shape = IRDM_REPORT_SINE, .wave_hz = 1.0 } },
};

/*
 * Fig. 10's tap, on a side: the centre node of the cube's +x face (6 cm
 * out and 6 cm down from the top centre) pushed 2 mm into the cube (-x)
 * over 10 ms and back over 10 ms, then let go: the cube flies off turning
 * and vibrating.
 */
const struct irdm_report_scenario irdm_report_tap = {
	.name = "tap",
	.what = "floating cube: the centre node of its +x face pushed 2 mm in (-x) over 10 ms, back over 10 ms, let go, 1 s of free flight",
	.duration_s = 1.0,
	.n_contacts = 1,
	.path = { { .on_node = true, .from_m = { 0.06, 0, -0.06 }, .on_s = 0, .off_s = 0.02, .depth_m = 0.002, .ramp_s = 0.01, .dir = { -1, 0, 0 }, .shape = IRDM_REPORT_TAP } },
};

size_t irdm_report_scenario_ticks(const struct irdm_report_scenario *sc, double dt_s)
{
	return (size_t)llround(sc->duration_s / dt_s);
}

/* Centre of the top face: the image's highest nodes. */
static void top_centre(const struct irdm_image *img, double c[3])
{
	double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY }, zmax = -INFINITY;

	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		if (img->nodes[r].pos_m[2] > zmax)
			zmax = img->nodes[r].pos_m[2];
	for (uint32_t r = 0; r < img->meta->n_nodes; r++) {
		if (img->nodes[r].pos_m[2] < zmax - 1e-6)
			continue;
		for (int a = 0; a < 2; a++) {
			lo[a] = fmin(lo[a], img->nodes[r].pos_m[a]);
			hi[a] = fmax(hi[a], img->nodes[r].pos_m[a]);
		}
	}
	c[0] = 0.5 * (lo[0] + hi[0]);
	c[1] = 0.5 * (lo[1] + hi[1]);
	c[2] = zmax;
}

static uint32_t nearest_column(const struct irdm_image *img, const double p[3])
{
	double best = INFINITY;
	uint32_t br = 0;

	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		const float *q = img->nodes[img->columns[c]].pos_m;
		double d = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
			   (q[2] - p[2]) * (q[2] - p[2]);
		if (d < best) {
			best = d;
			br = img->columns[c];
		}
	}
	return br;
}

static double clamp01(double x)
{
	return x < 0 ? 0 : (x > 1 ? 1 : x);
}

/* The fraction of depth_m the path is at, time_s from its start. */
static double depth_fraction(const struct irdm_report_path *p, double time_s)
{
	double s = time_s - p->on_s;

	switch (p->shape) {
	case IRDM_REPORT_SINE:
		return sin(2 * M_PI * p->wave_hz * s);
	case IRDM_REPORT_TAP:
		return clamp01(fmin(s, 2 * p->ramp_s - s) / p->ramp_s);
	case IRDM_REPORT_HOLD:
	default:
		return p->ramp_s > 0 ? clamp01(s / p->ramp_s) : 1;
	}
}

int irdm_report_scenario_cmds(const struct irdm_report_scenario *sc,
			      const struct irdm_image *img, double dt_s, size_t t,
			      struct irdm_report_cmd *cmd)
{
	double c[3], time_s = (double)t * dt_s;

	top_centre(img, c);
	for (unsigned i = 0; i < sc->n_contacts; i++) {
		const struct irdm_report_path *p = &sc->path[i];
		double s = p->slide_end_s > p->slide_begin_s ?
				   clamp01((time_s - p->slide_begin_s) / (p->slide_end_s - p->slide_begin_s)) :
				   0;
		double depth = p->depth_m * depth_fraction(p, time_s);
		bool down = !p->dir[0] && !p->dir[1] && !p->dir[2];
		double at[3] = { c[0] + p->from_m[0] + s * (p->to_m[0] - p->from_m[0]),
				 c[1] + p->from_m[1] + s * (p->to_m[1] - p->from_m[1]),
				 c[2] + p->from_m[2] };

		memset(&cmd[i], 0, sizeof(cmd[i]));
		cmd[i].active = time_s >= p->on_s && time_s < p->off_s;
		cmd[i].on_node = p->on_node;
		for (int a = 0; a < 3; a++)
			cmd[i].target_m[a] = down ? (a == 2 ? -depth : 0) : depth * p->dir[a];
		if (p->on_node)
			cmd[i].row = nearest_column(img, at);
		else if (irdm_replay_locate(img, at, &cmd[i].tri, cmd[i].bary))
			return IRDM_ECONTACT;
	}
	return IRDM_OK;
}
