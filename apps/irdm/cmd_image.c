/* SPDX-License-Identifier: MIT */
/* irdm image info | verify | export */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "image/image_response.h"
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/options.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/options_doc.h"

static const char usage[] =
	"usage: irdm image info IMAGE\n"
	"       irdm image verify [--require-stable] IMAGE\n"
	"       irdm image export IMAGE --column NODE [--rows NODE,...] [--samples N] [-o FILE.csv]\n"
	"       irdm image config IMAGE [--board BOARD]   # the build configuration it needs\n"
	"\n"
	"NODE is a mesh node index (0-based), as 'image info' lists for the columns.\n"
	"export writes one CSV row per sample s: s, t_s (= (s+1) dt, when the\n"
	"displacement is observed), then for each row node nR the 3x3 block\n"
	"nR_u<i>_f<j>: displacement along i at nR per newton held along j at NODE.\n";

static const char *elem_name(uint32_t e)
{
	static const char *const names[] = { "bytes", "f16", "f32", "f64", "u32" };

	return e < 5 ? names[e] : "?";
}

static int open_image(const char *path, struct irdm_image *img)
{
	char err[512];
	int rc = irdm_image_map(path, 0, img, err, sizeof(err));

	if (rc) {
		irdm_cli_fail("image", rc, err);
		return -1;
	}
	return 0;
}

/* COLUMN_SCALE: the range of the force columns' storage scales. */
static void print_scales(const struct irdm_image *img)
{
	double lo = INFINITY, hi = 0;

	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		lo = fmin(lo, irdm_image_col_scale(img, c));
		hi = fmax(hi, irdm_image_col_scale(img, c));
	}
	printf("scales        per force column, 2^%d to 2^%d (the values stored divided by them)\n",
	       ilogb(lo), ilogb(hi));
}

/* STATIC_CORR_CLUSTERS: its clusters, its pairs by kind, its bytes. */
static void print_clusters(const struct irdm_image *img)
{
	uint32_t n = img->corr_clusters->n_clusters, top = 0;
	unsigned long long dense = 0, low = 0;

	for (uint32_t a = 0; a < n; a++)
		for (uint32_t b = a; b < n; b++) {
			uint32_t rank = irdm_image_corr_pair(img, a, b)->rank;
			dense += rank == IRDM_CORR_PAIR_DENSE;
			low += rank != IRDM_CORR_PAIR_DENSE;
			if (rank != IRDM_CORR_PAIR_DENSE && rank > top)
				top = rank;
		}
	printf("clusters      %u over %u columns, pairs %llu dense, %llu low-rank (largest rank %u), "
	       "%llu bytes\n",
	       n, img->meta->n_cols, dense, low, top,
	       (unsigned long long)irdm_image_find(img, IRDM_SEC_STATIC_CORR_CLUSTERS)->size);
}

static int cmd_info(const char *path)
{
	struct irdm_image img;

	if (open_image(path, &img))
		return 1;
	const struct irdm_meta *m = img.meta;
	const struct irdm_image_header *h = (const void *)img.base;
	printf("image         %s (%zu bytes, format %u.%u)\n", path, img.size, h->version_major,
	       h->version_minor);
	printf("made by       %s from mesh %s (%u nodes, %u tets, hash %016llx)\n", m->tool_version,
	       m->mesh_name, m->mesh_nodes, m->mesh_tets, (unsigned long long)m->mesh_hash);
	if (m->representation == IRDM_REPR_FIR)
		printf("responses     FIR, T = %u samples (%.3f s), %s%s\n", m->fir_length,
		       m->fir_length * m->dt_s, elem_name(m->precision),
		       m->flags & IRDM_META_TIME_DOMAIN ? ", time-domain" : ", from modes");
	if (m->flags & IRDM_META_FIR_TAIL_WINDOW)
		printf("tail          samples 0..%u exact, %u past them windowed (fir_tail = window:%u), "
		       "sum = static compliance\n",
		       m->fir_exact - 1, m->fir_length - m->fir_exact,
		       m->fir_length - m->fir_exact);
	if (m->representation != IRDM_REPR_FIR)
		printf("responses     modal, %u of %u modes%s, %s\n", m->n_modes, m->n_modes_total,
		       m->flags & IRDM_META_STATIC_CORR ? " + static correction" : "",
		       elem_name(m->precision));
	if (img.corr_start)
		printf("static corr   %u of %llu blocks kept, far field rank %u\n",
		       img.corr_start[m->n_cols], (unsigned long long)m->n_cols * m->n_cols,
		       img.corr_rank);
	if (img.corr_clusters)
		print_clusters(&img);
	if (img.exact_head)
		printf("exact head    the %u dropped modes' response at the kept blocks: samples "
		       "0..%u exact, %u..%u tapered, sum = static correction (hybrid)%s\n",
		       m->n_modes_total - m->n_modes, m->head_samples / 2 - 1, m->head_samples / 2,
		       m->head_samples - 1,
		       img.head_index ? "; each symmetric pair of blocks stored once" : "");
	if (img.col_scale)
		print_scales(&img);
	printf("dt            %g s (%g Hz)\n", m->dt_s, 1.0 / m->dt_s);
	printf("material      E %g Pa, nu %g, rho %g kg/m^3, %s mass\n", m->young_pa, m->poisson,
	       m->density_kg_m3, m->flags & IRDM_META_CONSISTENT_MASS ? "consistent" : "lumped");
	printf("damping       C = %.6g M + %.6g K", m->rayleigh_a_per_s, m->rayleigh_b_s);
	if (m->damping_ratio[0] > 0 || m->damping_ratio[1] > 0)
		printf(" (%.3g at %.4g Hz, %.3g at %.4g Hz)", m->damping_ratio[0], m->damping_freq_hz[0],
		       m->damping_ratio[1], m->damping_freq_hz[1]);
	printf("\nobject        %s, first elastic mode %.4f Hz\n",
	       m->flags & IRDM_META_FLOATING ? "floating" : "grounded", m->first_elastic_hz);
	if (img.rigid)
		printf("rigid body    mass %.6g kg, COM (%.4g, %.4g, %.4g) m\n", img.rigid->mass_kg,
		       img.rigid->com_m[0], img.rigid->com_m[1], img.rigid->com_m[2]);
	printf("nodes         %u rows, %u touchable columns, %u surface triangles\n", m->n_nodes,
	       m->n_cols, m->n_tris);
	size_t unstable = 0;
	for (uint32_t c = 0; c < m->n_cols; c++)
		unstable += !(img.stability[c].flags & IRDM_STAB_STABLE);
	printf("stability     max spectral radius %.6f; %zu of %u columns unstable\n",
	       m->max_spectral_radius, unstable, m->n_cols);
	if (m->flags & IRDM_META_ERROR_MEASURED)
		printf("force error   %.3g against the exact model (relative RMS, measured by the precompute)\n",
		       (double)m->measured_error);
	else
		printf("force error   not measured\n");
	if (img.two_contacts_error >= 0)
		printf("two contacts  %.3g against the exact model (relative RMS, two grabbed at once, measured by the precompute)\n",
		       img.two_contacts_error);
	printf("sections\n");
	const struct irdm_image_section *s = (const void *)(img.base + h->section_table_offset);
	for (uint32_t i = 0; i < h->section_count; i++)
		printf("  %-20s %-5s offset %10llu  size %12llu  crc32c %08x\n", irdm_image_kind_name(s[i].kind),
		       elem_name(s[i].elem), (unsigned long long)s[i].offset,
		       (unsigned long long)s[i].size, s[i].crc32c);
	printf("columns (mesh nodes):");
	for (uint32_t c = 0; c < m->n_cols && c < 16; c++)
		printf(" %u", img.nodes[img.columns[c]].mesh_node);
	printf(m->n_cols > 16 ? " ...\n" : "\n");
	printf("provenance\n");
	const char *p = img.provenance, *end = p + img.provenance_len;
	while (p < end) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		int len = (int)((nl ? nl : end) - p);
		printf("  %.*s\n", len, p);
		p += len + 1;
	}
	irdm_image_unmap(&img);
	return 0;
}

/* Tolerance for comparing stored values, by precision. */
static double prec_tol(uint32_t p)
{
	return p == IRDM_ELEM_F64 ? 1e-9 : p == IRDM_ELEM_F32 ? 1e-5 :
								5e-3;
}

static int check_r0(const struct irdm_image *img, uint32_t c, const double *r0)
{
	double scale = 0, asym = 0;

	for (int e = 0; e < 9; e++)
		scale = fmax(scale, fabs(r0[e]));
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			asym = fmax(asym, fabs(r0[3 * i + j] - r0[3 * j + i]));
	if (asym > prec_tol(img->meta->precision) * scale * 10) {
		fprintf(stderr, "irdm image verify: column %u: R[0] is not symmetric (%.3g relative)\n",
			c, asym / scale);
		return -1;
	}
	/* positive definite: leading minors of the symmetric part */
	double a = r0[0], b = 0.5 * (r0[1] + r0[3]), d = r0[4];
	double m2 = a * d - b * b;
	double det = r0[0] * (r0[4] * r0[8] - r0[5] * r0[7]) - r0[1] * (r0[3] * r0[8] - r0[5] * r0[6]) + r0[2] * (r0[3] * r0[7] - r0[4] * r0[6]);
	if (!(a > 0 && m2 > 0 && det > 0)) {
		fprintf(stderr, "irdm image verify: column %u: R[0] is not positive definite\n", c);
		return -1;
	}
	return 0;
}

/* R_{c1 -> row c2}[s] = R_{c2 -> row c1}[s]^T (reciprocity). */
static int check_reciprocity(const struct irdm_image *img, uint32_t c1, uint32_t c2, size_t n,
			     double *a, double *b)
{
	double scale = 0, diff = 0;

	if (irdm_image_response(img, c1, img->columns[c2], n, a) ||
	    irdm_image_response(img, c2, img->columns[c1], n, b))
		return -1;
	for (size_t s = 0; s < n; s++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				scale = fmax(scale, fabs(a[9 * s + 3 * (size_t)i + (size_t)j]));
				diff = fmax(diff, fabs(a[9 * s + 3 * (size_t)i + (size_t)j] - b[9 * s + 3 * (size_t)j + (size_t)i]));
			}
	if (diff > prec_tol(img->meta->precision) * 10 * scale + 1e-300) {
		fprintf(stderr, "irdm image verify: columns %u and %u violate reciprocity (%.3g relative)\n",
			c1, c2, diff / scale);
		return -1;
	}
	return 0;
}

static int cmd_verify(int argc, char **argv)
{
	const char *path = NULL;
	int require_stable = 0, bad = 0;
	struct irdm_image img;

	for (int i = 0; i < argc; i++) {
		if (!strcmp(argv[i], "--require-stable"))
			require_stable = 1;
		else if (!path && argv[i][0] != '-')
			path = argv[i];
		else {
			fprintf(stderr, "irdm image verify: unexpected argument '%s'\n", argv[i]);
			return 2;
		}
	}
	if (!path) {
		fputs(usage, stderr);
		return 2;
	}
	if (open_image(path, &img))
		return 1;
	const struct irdm_meta *m = img.meta;
	size_t n = m->representation == IRDM_REPR_FIR ? m->fir_length : 256;
	double *a = malloc(n * 9 * sizeof(double)), *b = malloc(n * 9 * sizeof(double));
	size_t unstable = 0;
	double max_rho = 0;

	if (!a || !b) {
		irdm_cli_fail("image verify", IRDM_ENOMEM, "out of memory");
		bad = 1;
		goto out_unmap;
	}
	for (uint32_t c = 0; c < m->n_cols && !bad; c++) {
		if (irdm_image_response(&img, c, img.columns[c], 1, a) || check_r0(&img, c, a))
			bad = 1;
		float rho = img.stability[c].spectral_radius;
		max_rho = fmax(max_rho, rho);
		if (((img.stability[c].flags & IRDM_STAB_STABLE) != 0) != (rho < 1.0f)) {
			fprintf(stderr, "irdm image verify: column %u: stability flag disagrees with radius %g\n", c, rho);
			bad = 1;
		}
		unstable += rho >= 1.0f;
	}
	if (!bad && fabs(max_rho - m->max_spectral_radius) > 1e-6 * fmax(1.0, max_rho)) {
		fprintf(stderr, "irdm image verify: header max spectral radius %g, columns say %g\n",
			m->max_spectral_radius, max_rho);
		bad = 1;
	}
	/* reciprocity on a spread of column pairs */
	for (uint32_t k = 0; k < 16 && m->n_cols > 1 && !bad; k++) {
		uint32_t c1 = (uint32_t)((k * 7919u) % m->n_cols), c2 = (uint32_t)((k * 104729u + 1) % m->n_cols);
		if (c1 != c2 && check_reciprocity(&img, c1, c2, n, a, b))
			bad = 1;
	}
	if (!bad && unstable && require_stable) {
		fprintf(stderr, "irdm image verify: %zu of %u columns have an unstable force recursion (max radius %.6f)\n",
			unstable, m->n_cols, m->max_spectral_radius);
		bad = 1;
	}
	if (!bad)
		printf("%s: OK (%u columns, R[0] symmetric positive definite, reciprocity holds, %zu unstable columns, max spectral radius %.6f)\n",
		       path, m->n_cols, unstable, m->max_spectral_radius);
out_unmap:
	free(a);
	free(b);
	irdm_image_unmap(&img);
	return bad;
}

/* A --rows entry: strtoul's syntax (" 7" and "+7" pass, as they always have). */
static int parse_u32(const char *s, uint32_t *out)
{
	char *end;

	errno = 0;
	unsigned long v = strtoul(s, &end, 10);
	if (end == s || *end || errno || v > UINT32_MAX || *s == '-')
		return -1;
	*out = (uint32_t)v;
	return 0;
}

#define MAX_EXPORT_ROWS 1024

static int write_csv(FILE *f, const struct irdm_image *img, uint32_t col, const uint32_t *rows,
		     size_t n_rows, size_t n_samples)
{
	static const char ax[] = "xyz";
	double *blk = malloc(n_rows * n_samples * 9 * sizeof(double));

	if (!blk)
		return IRDM_ENOMEM;
	for (size_t r = 0; r < n_rows; r++)
		if (irdm_image_response(img, col, rows[r], n_samples, &blk[r * n_samples * 9])) {
			free(blk);
			return IRDM_ENOMEM;
		}
	fprintf(f, "s,t_s");
	for (size_t r = 0; r < n_rows; r++)
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				fprintf(f, ",n%u_u%c_f%c", img->nodes[rows[r]].mesh_node, ax[i], ax[j]);
	fputc('\n', f);
	for (size_t s = 0; s < n_samples; s++) {
		fprintf(f, "%zu,%.9g", s, (double)(s + 1) * img->meta->dt_s);
		for (size_t r = 0; r < n_rows; r++)
			for (int e = 0; e < 9; e++)
				fprintf(f, ",%.9g", blk[(r * n_samples + s) * 9 + (size_t)e]);
		fputc('\n', f);
	}
	free(blk);
	return ferror(f) ? IRDM_EIO : IRDM_OK;
}

/* What export was asked for. */
struct export_args {
	const char *path;
	const char *out;
	const char *rows;
	uint64_t column;  /* UINT64_MAX: not given */
	uint32_t samples; /* 0: the FIR length, or one second */
};

#define EA(member) IRDM_OPT_FIELD(struct export_args, member)
#define EA_REF(member) IRDM_OPT_TEXT_REF(struct export_args, member)

static const struct irdm_opt export_opts[] = {
	{ .name = "column", .type = IRDM_OPT_UNSIGNED, EA(column), .metavar = "NODE", .range = IRDM_OPT_LE, .max = UINT32_MAX, .help = "the touchable mesh node whose responses are written (required)" },
	{ .name = "rows", .type = IRDM_OPT_STRING, EA_REF(rows), .metavar = "NODE,...", .help = "the mesh nodes whose displacement is written (default: NODE)" },
	{ .name = "samples", .type = IRDM_OPT_UNSIGNED, EA(samples), .metavar = "N", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 10000000, .help = "samples written (default: the FIR length, or one second)" },
	{ .name = "output", .short_name = 'o', .type = IRDM_OPT_STRING, EA_REF(out), .metavar = "FILE.csv", .help = "write here, atomically (default: standard output)" },
};

static const struct irdm_opt_table export_options = {
	.what = "option",
	.see = "irdm image export --help",
	.opts = export_opts,
	.n_opts = sizeof(export_opts) / sizeof(export_opts[0]),
};

static int export_image_arg(void *ctx, const char *arg, char *err, size_t errlen)
{
	struct export_args *a = ctx;

	if (a->path) {
		snprintf(err, errlen, "unexpected argument '%s'", arg);
		return IRDM_EINVAL;
	}
	a->path = arg;
	return IRDM_OK;
}

static int cmd_export(int argc, char **argv)
{
	struct export_args args = { .column = UINT64_MAX };
	const struct irdm_opt_set set = { &export_options, &args };
	const char *path, *out, *rows_arg;
	uint32_t col_node, n_samples;
	int ret = 1;
	uint32_t rows[MAX_EXPORT_ROWS];
	size_t n_rows = 0;
	struct irdm_image img;
	char err[512];
	int rc = irdm_opt_parse_args(&set, 1, argc, argv, export_image_arg, &args, err, sizeof(err));

	if (rc) {
		irdm_cli_fail("image export", rc, err);
		return 2;
	}
	if (!args.path || args.column == UINT64_MAX) {
		fputs(usage, stderr);
		return 2;
	}
	path = args.path;
	out = args.out;
	rows_arg = args.rows;
	col_node = (uint32_t)args.column;
	n_samples = args.samples;
	if (open_image(path, &img))
		return 1;
	int64_t cr = irdm_image_node_of(&img, col_node), c = cr < 0 ? -1 : irdm_image_col_of(&img, (uint32_t)cr);
	if (c < 0) {
		fprintf(stderr, "irdm image export: mesh node %u is not a touchable column of %s\n", col_node, path);
		goto out_unmap;
	}
	if (rows_arg) {
		char buf[8192], *save = NULL;
		if (strlen(rows_arg) >= sizeof(buf)) {
			fprintf(stderr, "irdm image export: --rows list too long\n");
			goto out_unmap;
		}
		strcpy(buf, rows_arg);
		for (char *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
			uint32_t node;
			int64_t r;
			if (parse_u32(t, &node) || (r = irdm_image_node_of(&img, node)) < 0) {
				fprintf(stderr, "irdm image export: --rows: '%s' is not a node of this image\n", t);
				goto out_unmap;
			}
			if (n_rows == MAX_EXPORT_ROWS) {
				fprintf(stderr, "irdm image export: at most %d rows\n", MAX_EXPORT_ROWS);
				goto out_unmap;
			}
			rows[n_rows++] = (uint32_t)r;
		}
	} else {
		rows[n_rows++] = (uint32_t)cr;
	}
	if (!n_samples)
		n_samples = img.meta->representation == IRDM_REPR_FIR ? img.meta->fir_length : (uint32_t)ceil(1.0 / img.meta->dt_s);
	FILE *f = stdout;
	char tmp[4096];
	if (out) {
		snprintf(tmp, sizeof(tmp), "%s.tmp", out);
		f = fopen(tmp, "w");
		if (!f) {
			fprintf(stderr, "irdm image export: EIO: cannot create %s: %s\n", tmp, strerror(errno));
			goto out_unmap;
		}
	}
	int wr = write_csv(f, &img, (uint32_t)c, rows, n_rows, n_samples);
	if (wr == IRDM_ENOMEM) {
		irdm_cli_fail("image export", wr, "out of memory");
		if (out) {
			fclose(f);
			remove(tmp);
		}
		goto out_unmap;
	}
	if (out) {
		if (fclose(f) || wr || rename(tmp, out)) {
			fprintf(stderr, "irdm image export: EIO: cannot write %s\n", out);
			remove(tmp);
			goto out_unmap;
		}
	} else if (wr || fflush(stdout)) {
		fprintf(stderr, "irdm image export: EIO: write error\n");
		goto out_unmap;
	}
	ret = 0;
out_unmap:
	irdm_image_unmap(&img);
	return ret;
}

int irdm_cmd_image(int argc, char **argv)
{
	if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
		fputs(usage, argc < 2 ? stderr : stdout);
		return argc < 2 ? 2 : 0;
	}
	if (argc >= 3 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))) {
		fputs(usage, stdout);
		if (!strcmp(argv[1], "export")) {
			fputs("\nexport options:\n", stdout);
			irdm_opt_print_help(stdout, &export_options, IRDM_OPT_STYLE_ARG);
		}
		return 0;
	}
	if (!strcmp(argv[1], "info")) {
		if (argc != 3) {
			fputs(usage, stderr);
			return 2;
		}
		return cmd_info(argv[2]);
	}
	if (!strcmp(argv[1], "verify"))
		return cmd_verify(argc - 2, argv + 2);
	if (!strcmp(argv[1], "export"))
		return cmd_export(argc - 2, argv + 2);
	if (!strcmp(argv[1], "config"))
		return irdm_cmd_image_config(argc - 2, argv + 2);
	fprintf(stderr, "irdm image: unknown subcommand '%s' (info, verify, export, config)\n",
		argv[1]);
	return 2;
}
