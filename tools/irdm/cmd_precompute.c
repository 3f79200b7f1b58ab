/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "precompute/precompute.h"

static const char usage[] =
	"usage: irdm precompute [--scene FILE] [--KEY VALUE]... -o IMAGE\n"
	"       irdm precompute ... --part BEGIN:END -o PART     (time-domain share)\n"
	"       irdm precompute ... --merge PART[,PART]... -o IMAGE\n"
	"       irdm precompute ... --count-inputs\n"
	"\n"
	"Builds the object, its modes and responses, checks the stability of every\n"
	"touchable node's force recursion and writes a flash image atomically.\n"
	"Scene keys (file lines 'key = value' or options '--key value'; options win):\n";

#define MAX_PARTS 256

static int split_parts(char *list, const char **parts, size_t *n)
{
	char *save = NULL;

	*n = 0;
	for (char *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
		if (*n == MAX_PARTS)
			return -1;
		parts[(*n)++] = t;
	}
	return *n ? 0 : -1;
}

static int parse_range(const char *s, size_t *b, size_t *e)
{
	char *end;
	unsigned long long x, y;

	errno = 0;
	x = strtoull(s, &end, 10);
	if (end == s || *end != ':' || errno)
		return -1;
	s = end + 1;
	y = strtoull(s, &end, 10);
	if (end == s || *end || errno || y <= x)
		return -1;
	*b = (size_t)x;
	*e = (size_t)y;
	return 0;
}

static void print_report(const struct irdm_scene *sc, const struct irdm_precompute_opts *o,
			 const struct irdm_precompute_report *r)
{
	printf("mesh          %zu nodes, %zu tets, %zu free DoFs\n", r->mesh_nodes, r->mesh_tets,
	       r->free_dofs);
	printf("modes         %zu of %zu elastic, first %.4f Hz\n", r->modes, r->modes_total,
	       r->first_elastic_hz);
	printf("image nodes   %zu rows, %zu touchable columns, %zu triangles\n", r->rows, r->cols,
	       r->tris);
	if (o->part_out) {
		printf("part          %s written\n", o->part_out);
	} else {
		printf("stability     max spectral radius %.6f, %zu of %zu columns unstable%s\n",
		       r->max_spectral_radius, r->unstable_cols, r->cols,
		       r->unstable_cols ? " (the firmware must couple these through a virtual coupling)" : "");
		printf("image         %s, %zu bytes (%.2f MiB), %s\n", o->out_path, r->image_bytes,
		       (double)r->image_bytes / (1 << 20),
		       sc->representation == IRDM_REPR_FIR ? "FIR" : "modal");
	}
	printf("time          %.2f s total: mesh %.2f, FEM %.2f, eigen %.2f, responses %.2f, stability %.2f\n",
	       r->seconds_total, r->seconds_mesh, r->seconds_fem, r->seconds_eig,
	       r->seconds_responses, r->seconds_stability);
}

int irdm_cmd_precompute(int argc, char **argv)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	struct irdm_precompute_report rep;
	struct irdm_cli_progress prog = { 0 };
	const char *parts[MAX_PARTS];
	char err[1024], where[128];
	int count_only = 0;

	irdm_scene_defaults(&sc);
	/* the scene file first, so options override it wherever they appear */
	for (int i = 1; i < argc; i++)
		if (!strcmp(argv[i], "--scene")) {
			if (i + 1 >= argc) {
				fprintf(stderr, "irdm precompute: --scene needs a file\n");
				return 2;
			}
			int rc = irdm_scene_load(&sc, argv[i + 1], err, sizeof(err));
			if (rc) {
				irdm_cli_fail("precompute", rc, err);
				return 1;
			}
		}
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
			fputs(usage, stdout);
			fputs(irdm_scene_help, stdout);
			return 0;
		}
		if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
			prog.quiet = 1;
			continue;
		}
		if (!strcmp(a, "--count-inputs")) {
			count_only = 1;
			continue;
		}
		if (strncmp(a, "--", 2) && strcmp(a, "-o")) {
			fprintf(stderr, "irdm precompute: unexpected argument '%s'\n", a);
			return 2;
		}
		if (i + 1 >= argc) {
			fprintf(stderr, "irdm precompute: %s needs a value\n", a);
			return 2;
		}
		const char *v = argv[++i];
		if (!strcmp(a, "--scene"))
			continue;
		if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
			o.out_path = v;
		} else if (!strcmp(a, "--part")) {
			if (parse_range(v, &o.part_begin, &o.part_end)) {
				fprintf(stderr, "irdm precompute: --part '%s': expected BEGIN:END with BEGIN < END\n", v);
				return 2;
			}
		} else if (!strcmp(a, "--merge")) {
			if (split_parts(argv[i], parts, &o.n_merge)) {
				fprintf(stderr, "irdm precompute: --merge: expected 1 to %d comma-separated part files\n", MAX_PARTS);
				return 2;
			}
			o.merge = parts;
		} else {
			snprintf(where, sizeof(where), "%.100s", a);
			int rc = irdm_scene_set(&sc, a + 2, v, where, err, sizeof(err));
			if (rc) {
				irdm_cli_fail("precompute", rc, err);
				return 2;
			}
		}
	}
	if (count_only) {
		size_t n;
		int rc = irdm_precompute_count_inputs(&sc, &n, err, sizeof(err));
		if (rc) {
			irdm_cli_fail("precompute", rc, err);
			return 1;
		}
		printf("%zu\n", n);
		return 0;
	}
	if (!o.out_path) {
		fprintf(stderr, "irdm precompute: missing -o IMAGE (see --help)\n");
		return 2;
	}
	if (o.part_end) {
		o.part_out = o.out_path;
		o.out_path = NULL;
		if (sc.method != IRDM_METHOD_TIME_DOMAIN) {
			fprintf(stderr, "irdm precompute: --part splits time-domain work: set --method time-domain\n");
			return 2;
		}
	}
	if (o.n_merge && sc.method != IRDM_METHOD_TIME_DOMAIN) {
		fprintf(stderr, "irdm precompute: --merge takes time-domain parts: set --method time-domain\n");
		return 2;
	}
	o.progress = irdm_cli_progress;
	o.ctx = &prog;
	int rc = irdm_precompute(&sc, &o, &rep, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("precompute", rc, err);
		return 1;
	}
	if (!prog.quiet)
		print_report(&sc, &o, &rep);
	return 0;
}
