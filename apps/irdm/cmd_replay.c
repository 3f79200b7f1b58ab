/* SPDX-License-Identifier: MIT */
/*
 * irdm replay: run the force engine on a prescribed displacement trajectory
 * and write the contact forces (and chosen nodes' displacements) as CSV.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image/image_response.h"
#include "irdm/engine.h"
#include "replay/replay.h"

static const char usage[] =
	"usage: irdm replay --image IMAGE --contact NODE|x,y,z [--contact NODE|x,y,z]\n"
	"                   --displacement TRAJ.csv -o FORCES.csv [--nodes N,...]\n"
	"                   [--push] [--solve coupled|per-vertex] [--coupling K,B]\n"
	"       irdm replay --image IMAGE --sites SITES.csv --displacement TRAJ.csv\n"
	"                   -o FORCES.csv [--push] [--passivity] ...\n"
	"       irdm replay --image IMAGE --log RUN.log --board BOARD -o FORCES.csv\n"
	"\n"
	"TRAJ.csv: one row per sample (t = 0, dt, 2 dt, ...): t, then ux, uy, uz (m)\n"
	"for each contact: the displacement imposed on the contact point (eq. 8;\n"
	"for a floating object, in the world frame, from its starting position);\n"
	"nan or an empty field releases the contact for that sample.  A first line\n"
	"that is not numeric is a header.  NODE is a mesh node index; x,y,z picks\n"
	"the nearest point of the touchable surface.\n"
	"FORCES.csv: t, then c<i>_fx, c<i>_fy, c<i>_fz: the force applied TO the\n"
	"object at contact i (the device renders its negative), then n<N>_ux.. :\n"
	"displacement u[t] of each --nodes node (any node of the image; for a\n"
	"floating object the world displacement, rigid motion included).\n"
	"--push releases a contact when the object would pull (default: held).\n"
	"--coupling K,B couples through a spring-damper (N/m, N s/m) instead.\n"
	"SITES.csv (instead of --contact): one row per sample as TRAJ.csv: t, then\n"
	"tri, b0, b1, b2 per contact: the contact's site that sample, a surface\n"
	"triangle and barycentrics (tri -1: none; its displacement must be nan), as\n"
	"irdm-fw logs them (irdm log export: dN_site_tri, dN_b0..2, and the targets\n"
	"dN_tx_m.. for TRAJ.csv): a sliding contact replayed tick by tick; the\n"
	"site's normal is its triangle's on the surface as the engine has it, as\n"
	"irdm-fw's proxy gives it.\n"
	"--passivity turns on the engine's passivity control (a haptic board's).\n"
	"--nodes all: every node of the image.\n"
	"RUN.log (instead of --contact or --sites): an irdm-fw log (--log) and the\n"
	"board it ran on: the engine configured as the controller did (the board's\n"
	"coupling and passivity control, push contacts), each record's site and\n"
	"target replayed (a contact the record marks as begun softly begun so),\n"
	"and how far the forces are from the logged ones said.\n";

static int parse_contact(const char *s, struct irdm_replay_contact *c)
{
	char *end;
	double v[3];

	errno = 0;
	unsigned long n = strtoul(s, &end, 10);
	if (end != s && *end == 0 && !errno && n <= UINT32_MAX && s[0] != '-') {
		c->is_node = true;
		c->mesh_node = (uint32_t)n;
		return 0;
	}
	const char *p = s;
	for (int k = 0; k < 3; k++) {
		v[k] = strtod(p, &end);
		if (end == p || !isfinite(v[k]) || (k < 2 && *end != ',') || (k == 2 && *end))
			return -1;
		p = end + 1;
	}
	c->is_node = false;
	memcpy(c->point_m, v, sizeof(v));
	return 0;
}

/* Flags: 1 if a[0] is one (set in o), else 0. */
static int replay_flag(struct irdm_replay_opts *o, const char *a)
{
	if (!strcmp(a, "--push"))
		o->mode = IRDM_CONTACT_PUSH;
	else if (!strcmp(a, "--passivity"))
		o->passivity = true;
	else
		return 0;
	return 1;
}

static int parse_coupling(struct irdm_replay_opts *o, const char *v, const char *cmd)
{
	char *end;

	o->coupling_k = strtod(v, &end);
	if (*end != ',' || !(o->coupling_k > 0) || !isfinite(o->coupling_k)) {
		fprintf(stderr, "irdm %s: --coupling '%s': expected K,B with K > 0\n", cmd, v);
		return -1;
	}
	o->coupling_b = strtod(end + 1, &end);
	if (*end || !(o->coupling_b >= 0) || !isfinite(o->coupling_b)) {
		fprintf(stderr, "irdm %s: --coupling '%s': expected K,B with B >= 0\n", cmd, v);
		return -1;
	}
	return 1;
}

/* Options with a value; *v is it. */
static int replay_value(struct irdm_replay_opts *o, const char *a, const char *v, const char *cmd)
{
	const char **dst = !strcmp(a, "--image")        ? &o->image :
			   !strcmp(a, "--sites")        ? &o->sites :
			   !strcmp(a, "--displacement") ? &o->trajectory :
			   !strcmp(a, "--log")          ? &o->log :
			   !strcmp(a, "--board")        ? &o->board :
							  NULL;

	if (dst) {
		*dst = v;
		return 1;
	}
	if (!strcmp(a, "--contact")) {
		if (o->n_contacts == IRDM_MAX_CONTACTS ||
		    parse_contact(v, &o->contact[o->n_contacts])) {
			fprintf(stderr, "irdm %s: --contact '%s': expected a mesh node or x,y,z (at most %d contacts)\n",
				cmd, v, IRDM_MAX_CONTACTS);
			return -1;
		}
		o->n_contacts++;
		return 1;
	}
	if (!strcmp(a, "--solve")) {
		if (!strcmp(v, "coupled") || !strcmp(v, "per-vertex")) {
			o->solve = !strcmp(v, "coupled") ? IRDM_SOLVE_COUPLED : IRDM_SOLVE_PER_VERTEX;
			return 1;
		}
		fprintf(stderr, "irdm %s: --solve '%s': coupled or per-vertex\n", cmd, v);
		return -1;
	}
	if (!strcmp(a, "--coupling"))
		return parse_coupling(o, v, cmd);
	return 0;
}

int irdm_cli_replay_option(struct irdm_replay_opts *o, int argc, char **argv, int *i,
			   const char *cmd)
{
	const char *a = argv[*i];

	if (replay_flag(o, a))
		return 1;
	if (strcmp(a, "--image") && strcmp(a, "--sites") && strcmp(a, "--displacement") &&
	    strcmp(a, "--log") && strcmp(a, "--board") && strcmp(a, "--contact") &&
	    strcmp(a, "--solve") && strcmp(a, "--coupling"))
		return 0;
	if (*i + 1 >= argc) {
		fprintf(stderr, "irdm %s: %s needs a value\n", cmd, a);
		return -1;
	}
	return replay_value(o, a, argv[++*i], cmd);
}

int irdm_cli_replay_check(const struct irdm_replay_opts *o, const char *cmd)
{
	int inputs = (o->n_contacts > 0) + (o->sites != NULL) + (o->log != NULL);

	if (inputs > 1) {
		fprintf(stderr, "irdm %s: --contact, --sites and --log exclude each other (see --help)\n", cmd);
		return -1;
	}
	if (o->log && (!o->board || o->trajectory || o->coupling_k > 0 || o->passivity ||
		       o->mode != IRDM_CONTACT_GRAB)) {
		fprintf(stderr, "irdm %s: --log needs --board (which sets the coupling, passivity and push contacts) and takes no --displacement (see --help)\n",
			cmd);
		return -1;
	}
	if (o->board && !o->log) {
		fprintf(stderr, "irdm %s: --board goes with --log (see --help)\n", cmd);
		return -1;
	}
	if (!o->image || !inputs || (!o->log && !o->trajectory)) {
		fprintf(stderr, "irdm %s: needs --image, and --contact or --sites with --displacement, or --log with --board (see --help)\n",
			cmd);
		return -1;
	}
	return 0;
}

int irdm_cmd_replay(int argc, char **argv)
{
	struct irdm_replay_opts o;
	struct irdm_replay_summary sum;
	char err[1024];

	irdm_replay_opts_default(&o);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		int got;
		if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
			fputs(usage, stdout);
			return 0;
		}
		got = irdm_cli_replay_option(&o, argc, argv, &i, "replay");
		if (got < 0)
			return 2;
		if (got)
			continue;
		if (strcmp(a, "-o") && strcmp(a, "--nodes")) {
			fprintf(stderr, "irdm replay: unknown option '%s' (see --help)\n", a);
			return 2;
		}
		if (i + 1 >= argc) {
			fprintf(stderr, "irdm replay: %s needs a value\n", a);
			return 2;
		}
		*(!strcmp(a, "-o") ? &o.out : &o.nodes) = argv[++i];
	}
	if (irdm_cli_replay_check(&o, "replay"))
		return 2;
	if (!o.out) {
		fprintf(stderr, "irdm replay: needs -o FORCES.csv (see --help)\n");
		return 2;
	}
	int rc = irdm_replay_run(&o, &sum, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("replay", rc, err);
		return 1;
	}
	if (o.log)
		printf("replay: %zu records of %s; the engine's forces within %.3g N of the logged ones (peak %.4g N)\n",
		       sum.rows, o.log, sum.log_max_diff_n, sum.log_peak_n);
	return 0;
}
