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
	"dN_tx_m.. for TRAJ.csv): a sliding contact replayed tick by tick.\n"
	"--passivity turns on the engine's passivity control (a haptic board's).\n";

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

int irdm_cmd_replay(int argc, char **argv)
{
	struct irdm_replay_opts o;
	char err[1024];

	irdm_replay_opts_default(&o);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
			fputs(usage, stdout);
			return 0;
		}
		if (!strcmp(a, "--push")) {
			o.mode = IRDM_CONTACT_PUSH;
			continue;
		}
		if (!strcmp(a, "--passivity")) {
			o.passivity = true;
			continue;
		}
		if (i + 1 >= argc) {
			fprintf(stderr, "irdm replay: %s needs a value\n", a);
			return 2;
		}
		const char *v = argv[++i];
		if (!strcmp(a, "--image")) {
			o.image = v;
		} else if (!strcmp(a, "--sites")) {
			o.sites = v;
		} else if (!strcmp(a, "--displacement")) {
			o.trajectory = v;
		} else if (!strcmp(a, "-o")) {
			o.out = v;
		} else if (!strcmp(a, "--nodes")) {
			o.nodes = v;
		} else if (!strcmp(a, "--contact")) {
			if (o.n_contacts == IRDM_MAX_CONTACTS ||
			    parse_contact(v, &o.contact[o.n_contacts])) {
				fprintf(stderr, "irdm replay: --contact '%s': expected a mesh node or x,y,z (at most %d contacts)\n",
					v, IRDM_MAX_CONTACTS);
				return 2;
			}
			o.n_contacts++;
		} else if (!strcmp(a, "--solve")) {
			if (!strcmp(v, "coupled"))
				o.solve = IRDM_SOLVE_COUPLED;
			else if (!strcmp(v, "per-vertex"))
				o.solve = IRDM_SOLVE_PER_VERTEX;
			else {
				fprintf(stderr, "irdm replay: --solve '%s': coupled or per-vertex\n", v);
				return 2;
			}
		} else if (!strcmp(a, "--coupling")) {
			char *end;
			o.coupling_k = strtod(v, &end);
			if (*end != ',' || !(o.coupling_k > 0) || !isfinite(o.coupling_k)) {
				fprintf(stderr, "irdm replay: --coupling '%s': expected K,B with K > 0\n", v);
				return 2;
			}
			o.coupling_b = strtod(end + 1, &end);
			if (*end || !(o.coupling_b >= 0) || !isfinite(o.coupling_b)) {
				fprintf(stderr, "irdm replay: --coupling '%s': expected K,B with B >= 0\n", v);
				return 2;
			}
		} else {
			fprintf(stderr, "irdm replay: unknown option '%s' (see --help)\n", a);
			return 2;
		}
	}
	if (o.sites && o.n_contacts) {
		fprintf(stderr, "irdm replay: --sites and --contact exclude each other (see --help)\n");
		return 2;
	}
	if (!o.image || !o.trajectory || !o.out || (!o.n_contacts && !o.sites)) {
		fprintf(stderr, "irdm replay: needs --image, --contact (or --sites), --displacement and -o (see --help)\n");
		return 2;
	}
	int rc = irdm_replay_run(&o, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("replay", rc, err);
		return 1;
	}
	return 0;
}
