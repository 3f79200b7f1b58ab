/* SPDX-License-Identifier: MIT */
/*
 * irdm render: the deformed object of a replay or of an irdm-fw run, frame
 * by frame, for ParaView and for plot-surface.py / plot-forces.py.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render/render.h"

static const char usage[] =
	"usage: irdm render --image IMAGE --contact NODE|x,y,z [--contact ...]\n"
	"                   --displacement TRAJ.csv -o DIR [--every S] [--nodes N,...|all]\n"
	"                   [--push] [--force] ...\n"
	"       irdm render --image IMAGE --sites SITES.csv --displacement TRAJ.csv -o DIR ...\n"
	"       irdm render --image IMAGE --log RUN.log --board BOARD -o DIR [--every S]\n"
	"\n"
	"The inputs are irdm replay's (irdm replay --help: TRAJ.csv, SITES.csv,\n"
	"--push, --solve, --coupling, --passivity; --log replays an irdm-fw run on\n"
	"the board it ran on).  Every S seconds of samples (default 0.02, rounded to\n"
	"the image's dt; at most 5000 frames) the whole displayed surface is kept.\n"
	"DIR is written whole or not at all, and replaces an existing DIR only if\n"
	"irdm render wrote it (its .irdm-output marker lists the files) or it is\n"
	"empty; --force replaces any directory of files.  DIR holds:\n"
	"  frame_NNNNN.vtu  VTK XML UnstructuredGrid: the image's nodes at their\n"
	"                   deformed positions, the displayed surface's triangles,\n"
	"                   point data displacement_m and mesh_node, field data\n"
	"                   time_s, contact, contact_point_m, contact_force_n\n"
	"  frames.pvd       the frames with their times (open it in ParaView)\n"
	"  frames.csv       frame, t_s, file, per contact on, point (m), force on\n"
	"                   the object (N), and the largest displacement (m)\n"
	"  forces.csv       every sample's forces, as irdm replay -o writes them, and\n"
	"                   the displacement of the --nodes (mesh nodes) every sample\n"
	"A frame after sample t (forces held over [t dt, (t+1) dt)) is the surface\n"
	"at (t+1) dt, where the contact stands at sample t's displacement; frames\n"
	"fall on S, 2 S, ... as irdm-fw --frames-every's do.\n"
	"Pictures: tools/scripts/plot-surface.py DIR/frames.pvd --each PNGDIR and\n"
	"tools/scripts/plot-forces.py DIR/forces.csv OUT.png.\n";

static int parse_every(const char *v, double *every_s)
{
	char *end;

	*every_s = strtod(v, &end);
	if (end == v || *end || !isfinite(*every_s) || !(*every_s > 0)) {
		fprintf(stderr, "irdm render: --every '%s': expected seconds > 0\n", v);
		return -1;
	}
	return 0;
}

/* Render's own options: 1 taken, 0 not one of them, -1 bad (said). */
static int render_option(struct irdm_render_opts *o, int argc, char **argv, int *i)
{
	const char *a = argv[*i];

	if (!strcmp(a, "--force")) {
		o->force = true;
		return 1;
	}
	if (strcmp(a, "-o") && strcmp(a, "--every") && strcmp(a, "--nodes"))
		return 0;
	if (*i + 1 >= argc) {
		fprintf(stderr, "irdm render: %s needs a value\n", a);
		return -1;
	}
	if (strcmp(a, "--every")) {
		*(!strcmp(a, "-o") ? &o->out_dir : &o->in.nodes) = argv[++*i];
		return 1;
	}
	return parse_every(argv[++*i], &o->every_s) ? -1 : 1;
}

/* 0: parsed; 1: --help shown; -1: a bad argument (said). */
static int parse_args(struct irdm_render_opts *o, int argc, char **argv)
{
	for (int i = 1; i < argc; i++) {
		int got;
		if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
			fputs(usage, stdout);
			return 1;
		}
		got = irdm_cli_replay_option(&o->in, argc, argv, &i, "render");
		if (!got)
			got = render_option(o, argc, argv, &i);
		if (got < 0)
			return -1;
		if (!got) {
			fprintf(stderr, "irdm render: unknown option '%s' (see --help)\n", argv[i]);
			return -1;
		}
	}
	if (irdm_cli_replay_check(&o->in, "render"))
		return -1;
	if (!o->out_dir) {
		fprintf(stderr, "irdm render: needs -o DIR (see --help)\n");
		return -1;
	}
	return 0;
}

/* The frames show what the image holds: say when that is not the whole object. */
static void surface_note(const struct irdm_render_opts *o, const struct irdm_render_surface *s)
{
	if (!s->open_edges)
		return;
	fprintf(stderr, "irdm render: note: %s displays part of the object only (display = %s): "
			"its %u triangles leave %u edges open; the frames show that part (precompute with "
			"--display surface for the whole surface)\n",
		o->in.image, s->display[0] ? s->display : "?", s->tris, s->open_edges);
}

int irdm_cmd_render(int argc, char **argv)
{
	struct irdm_render_opts o = { .every_s = 0.02 };
	struct irdm_render_summary sum;
	char err[1024];
	int rc;

	irdm_replay_opts_default(&o.in);
	rc = parse_args(&o, argc, argv);
	if (rc)
		return rc > 0 ? 0 : 2;
	rc = irdm_render_run(&o, &sum, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("render", rc, err);
		return 1;
	}
	surface_note(&o, &sum.surface);
	if (sum.debris_removed)
		fprintf(stderr, "irdm render: note: %s: removed %u director%s left by interrupted runs\n",
			o.out_dir, sum.debris_removed, sum.debris_removed == 1 ? "y" : "ies");
	printf("render: %zu frames every %zu samples of %zu -> %s/frames.pvd (%u nodes, %u triangles); "
	       "largest displacement %.4g mm at t = %.3f s\n",
	       sum.frames, sum.every_rows,
	       sum.replay.rows, o.out_dir, sum.surface.nodes, sum.surface.tris,
	       sum.max_disp_m * 1e3, sum.max_disp_t_s);
	if (o.in.log)
		printf("render: %s replayed: the engine's forces within %.3g N of the logged ones "
		       "(peak %.4g N)\n",
		       o.in.log, sum.replay.log_max_diff_n, sum.replay.log_peak_n);
	return 0;
}
