/* SPDX-License-Identifier: MIT */
/* Scene keys: parsing, defaults, checks and the canonical text. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/options.h"
#include "irdm/posix/textfile.h"
#include "modal/static_clusters.h"
#include "modal/static_lowrank.h"
#include "modal/static_sparse.h"
#include "scene/scene.h"

void irdm_scene_defaults(struct irdm_scene *sc)
{
	memset(sc, 0, sizeof(*sc));
	snprintf(sc->name, sizeof(sc->name), "cuboid");
	snprintf(sc->mesh, sizeof(sc->mesh), "cuboid");
	sc->tets_per_hex = 5;
	sc->mesh_scale = 1.0;
	snprintf(sc->tetgen, sizeof(sc->tetgen), "pq1.414");
	sc->mat.young_pa = 2000;
	sc->mat.poisson = 0.49;
	sc->mat.density_kg_m3 = 110;
	sc->mass = IRDM_MASS_LUMPED;
	sc->damping = IRDM_DAMP_RATIOS;
	sc->damp_ratio[0] = sc->damp_ratio[1] = 0.05;
	sc->damp_hz[0] = 0;
	sc->damp_hz[1] = 100;
	sc->dt_s = 0.001;
	sc->representation = IRDM_REPR_MODAL;
	sc->repr_auto = true;
	sc->modes = 300;
	sc->fir_tail_auto = true;
	sc->static_correction = true;
	sc->static_corr_tol = IRDM_STATIC_CORR_TOL_DEFAULT;
	sc->static_corr_rank = IRDM_STATIC_CORR_RANK_DEFAULT;
	sc->precision = IRDM_ELEM_F32;
	sc->fixed.kind = IRDM_REGION_PLANE;
	sc->fixed.axis = 2;
	sc->fixed.below = true;
	snprintf(sc->fixed.text, sizeof(sc->fixed.text), "z<=0");
	sc->touch.kind = IRDM_REGION_SURFACE;
	snprintf(sc->touch.text, sizeof(sc->touch.text), "surface");
	sc->display.kind = IRDM_REGION_SURFACE;
	snprintf(sc->display.text, sizeof(sc->display.text), "surface");
	sc->method = IRDM_METHOD_MODAL;
	sc->substeps = 8;
	sc->eigensolver = IRDM_EIG_AUTO;
	sc->symmetry = true;
	sc->max_error = IRDM_MAX_ERROR_DEFAULT;
	sc->max_head_mib = IRDM_MAX_HEAD_MIB_DEFAULT;
	sc->contacts = 1;
}

/* Strict number parsing: the whole token, finite. */
static int parse_double(const char *s, double *out)
{
	char *end;

	errno = 0;
	*out = strtod(s, &end);
	while (*end && isspace((unsigned char)*end))
		end++;
	return (end == s || *end || errno == ERANGE || !isfinite(*out)) ? -1 : 0;
}

static int parse_uint(const char *s, unsigned long max, unsigned *out)
{
	char *end;
	unsigned long v;

	if (!isdigit((unsigned char)*s))
		return -1;
	errno = 0;
	v = strtoul(s, &end, 10);
	if (*end || errno || v > max)
		return -1;
	*out = (unsigned)v;
	return 0;
}

/* Split "a,b,c" into at most n doubles; returns the count or -1. */
static int parse_list(const char *s, double *v, int n)
{
	char buf[256], *save = NULL, *tok;
	int k = 0;

	if (strlen(s) >= sizeof(buf))
		return -1;
	strcpy(buf, s);
	for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		if (k == n || parse_double(tok, &v[k]))
			return -1;
		k++;
	}
	return k;
}

static int parse_nodes(const char *s, struct irdm_region *r)
{
	const char *p = s;

	r->n_nodes = 0;
	while (*p) {
		char *end;
		errno = 0;
		unsigned long v = strtoul(p, &end, 10);
		if (end == p || errno || v > UINT32_MAX || r->n_nodes == IRDM_REGION_MAX_NODES)
			return -1;
		r->nodes[r->n_nodes++] = (uint32_t)v;
		p = end;
		if (*p == ',')
			p++;
		else if (*p)
			return -1;
	}
	return r->n_nodes ? 0 : -1;
}

static int parse_region(const char *s, struct irdm_region *r, bool allow_touch)
{
	double v[6];

	memset(r, 0, sizeof(*r));
	if (strlen(s) >= sizeof(r->text))
		return -1;
	snprintf(r->text, sizeof(r->text), "%s", s);
	if (!strcmp(s, "none")) {
		r->kind = IRDM_REGION_NONE;
	} else if (!strcmp(s, "surface")) {
		r->kind = IRDM_REGION_SURFACE;
	} else if (allow_touch && !strcmp(s, "touch")) {
		r->kind = IRDM_REGION_NONE; /* rows = touch only */
	} else if (!strncmp(s, "box:", 4)) {
		if (parse_list(s + 4, v, 6) != 6)
			return -1;
		r->kind = IRDM_REGION_BOX;
		memcpy(r->box_m, v, sizeof(v));
		for (int a = 0; a < 3; a++)
			if (r->box_m[a] > r->box_m[a + 3])
				return -1;
	} else if (!strncmp(s, "nodes:", 6)) {
		r->kind = IRDM_REGION_NODES;
		return parse_nodes(s + 6, r);
	} else if (strchr("xyz", s[0]) && s[0] && (s[1] == '<' || s[1] == '>') && s[2] == '=') {
		r->kind = IRDM_REGION_PLANE;
		r->axis = s[0] - 'x';
		r->below = s[1] == '<';
		return parse_double(s + 3, &r->value_m);
	} else {
		return -1;
	}
	return 0;
}

static int parse_damping(struct irdm_scene *sc, const char *s)
{
	double v[2];

	if (!strncmp(s, "rayleigh:", 9)) {
		if (parse_list(s + 9, v, 2) != 2 || v[0] < 0 || v[1] < 0)
			return -1;
		sc->damping = IRDM_DAMP_RAYLEIGH;
		sc->rayleigh.a_per_s = v[0];
		sc->rayleigh.b_s = v[1];
		return 0;
	}
	char buf[128], *comma, *at1, *at2;
	if (strlen(s) >= sizeof(buf))
		return -1;
	strcpy(buf, s);
	comma = strchr(buf, ',');
	if (!comma)
		return -1;
	*comma = 0;
	at1 = strchr(buf, '@');
	at2 = strchr(comma + 1, '@');
	if (!at1 || !at2)
		return -1;
	*at1++ = 0;
	*at2++ = 0;
	if (parse_double(buf, &sc->damp_ratio[0]) || parse_double(comma + 1, &sc->damp_ratio[1]))
		return -1;
	if (!strcmp(at1, "mode1"))
		sc->damp_hz[0] = 0;
	else if (parse_double(at1, &sc->damp_hz[0]) || sc->damp_hz[0] <= 0)
		return -1;
	if (parse_double(at2, &sc->damp_hz[1]) || sc->damp_hz[1] <= 0)
		return -1;
	if (sc->damp_ratio[0] < 0 || sc->damp_ratio[1] < 0)
		return -1;
	sc->damping = IRDM_DAMP_RATIOS;
	return 0;
}

static int parse_representation(struct irdm_scene *sc, const char *s)
{
	sc->repr_auto = !strcmp(s, "auto");
	if (sc->repr_auto) {
		/* what it resolves to without max_error: modal:300 + correction */
		sc->representation = IRDM_REPR_MODAL;
		sc->modes = 300;
		return 0;
	}
	if (!strcmp(s, "modal:all")) {
		sc->representation = IRDM_REPR_MODAL;
		sc->modes = 0;
		return 0;
	}
	if (!strncmp(s, "modal:", 6)) {
		sc->representation = IRDM_REPR_MODAL;
		return parse_uint(s + 6, 1000000, &sc->modes) || sc->modes == 0 ? -1 : 0;
	}
	if (!strncmp(s, "fir:", 4)) {
		sc->representation = IRDM_REPR_FIR;
		return parse_uint(s + 4, 1000000, &sc->fir_length) || sc->fir_length == 0 ? -1 : 0;
	}
	return -1;
}

static int parse_resolution(struct irdm_scene *sc, const char *s)
{
	double v[3];

	if (parse_list(s, v, 3) != 3)
		return -1;
	for (int a = 0; a < 3; a++) {
		if (v[a] < 1 || v[a] > 400 || v[a] != floor(v[a]))
			return -1;
		sc->res[a] = (unsigned)v[a];
	}
	return 0;
}

/*
 * Keys with a composite syntax parse with the functions above; the table
 * below gives every key its type, range, unit and help, so that parsing,
 * `irdm precompute --help` and docs/scene-format.md come from one place.
 */
static int set_resolution(const struct irdm_opt *o, void *obj, const char *v, char *why,
			  size_t len)
{
	(void)o;
	(void)why;
	(void)len;
	return parse_resolution(obj, v) ? IRDM_EFORMAT : IRDM_OK;
}

static int set_tetgen(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	struct irdm_scene *sc = obj;

	(void)o;
	for (const char *p = v; *p; p++)
		if (!isalnum((unsigned char)*p) && *p != '.' && *p != '/') {
			snprintf(why, len, "'%c': switches are letters, digits, '.' and '/'", *p);
			return IRDM_EFORMAT;
		}
	if (strlen(v) >= sizeof(sc->tetgen)) {
		snprintf(why, len, "longer than %zu characters", sizeof(sc->tetgen) - 1);
		return IRDM_EFORMAT;
	}
	snprintf(sc->tetgen, sizeof(sc->tetgen), "%s", v);
	sc->tetgen_given = true;
	return IRDM_OK;
}

static int set_damping(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	(void)o;
	(void)why;
	(void)len;
	return parse_damping(obj, v) ? IRDM_EFORMAT : IRDM_OK;
}

/* yes/no like any bool, and "yes" drops the default constraint. */
static int set_floating(const struct irdm_opt *o, void *obj, const char *v, char *why,
			size_t len)
{
	static const struct irdm_opt yes_no = { .name = "floating", .type = IRDM_OPT_BOOL, .size = sizeof(bool) };
	struct irdm_scene *sc = obj;
	bool b;
	int ret = irdm_opt_parse_value(&yes_no, &b, v, why, len);

	(void)o;
	if (ret)
		return ret;
	sc->floating = b;
	if (b && sc->fixed.kind == IRDM_REGION_PLANE && !strcmp(sc->fixed.text, "z<=0"))
		parse_region("none", &sc->fixed, false); /* default constraint off */
	return IRDM_OK;
}

/* fixed and touch: the region at the entry's offset. */
static int set_region(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	(void)why;
	(void)len;
	return parse_region(v, (struct irdm_region *)((char *)obj + o->offset), false) ?
		       IRDM_EFORMAT :
		       IRDM_OK;
}

/* display: a region, or "touch" (the touchable nodes only). */
static int set_display(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	(void)why;
	(void)len;
	return parse_region(v, (struct irdm_region *)((char *)obj + o->offset), true) ?
		       IRDM_EFORMAT :
		       IRDM_OK;
}

static int set_representation(const struct irdm_opt *o, void *obj, const char *v, char *why,
			      size_t len)
{
	(void)o;
	(void)why;
	(void)len;
	return parse_representation(obj, v) ? IRDM_EFORMAT : IRDM_OK;
}

/* "window" (L chosen by the precompute), "window:L": L samples past T,
 * tapered (precompute/fir_tail.c), or "none". */
static int set_fir_tail(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	static const struct irdm_opt count = { .name = "fir_tail", .type = IRDM_OPT_UNSIGNED, .size = sizeof(unsigned), .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 1000000 };
	struct irdm_scene *sc = obj;

	(void)o;
	sc->fir_tail = 0;
	sc->fir_tail_auto = !strcmp(v, "window");
	if (sc->fir_tail_auto || !strcmp(v, "none"))
		return IRDM_OK;
	if (strncmp(v, "window:", 7)) {
		snprintf(why, len, "expected window, window:L or none");
		return IRDM_EFORMAT;
	}
	return irdm_opt_parse_value(&count, &sc->fir_tail, v + 7, why, len);
}

/* "none" (0: not measured, not checked) or a relative error in (0, 1]. */
static int set_max_error(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	static const struct irdm_opt err = { .name = "max_error", .type = IRDM_OPT_DOUBLE, .size = sizeof(double), .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 1 };
	struct irdm_scene *sc = obj;

	(void)o;
	if (!strcmp(v, "none")) {
		sc->max_error = 0;
		return IRDM_OK;
	}
	return irdm_opt_parse_value(&err, &sc->max_error, v, why, len);
}

/* "all" or "0": every mode; otherwise 1 to 1000000. */
static int set_modes(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	static const struct irdm_opt count = { .name = "modes", .type = IRDM_OPT_UNSIGNED, .size = sizeof(unsigned), .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 1000000 };
	struct irdm_scene *sc = obj;

	(void)o;
	if (!strcmp(v, "all") || !strcmp(v, "0")) {
		sc->modes = 0;
		return IRDM_OK;
	}
	return irdm_opt_parse_value(&count, &sc->modes, v, why, len);
}

static const struct irdm_opt_name mass_names[] = {
	{ "lumped", IRDM_MASS_LUMPED },
	{ "consistent", IRDM_MASS_CONSISTENT },
	{ NULL, 0 },
};
static const struct irdm_opt_name precision_names[] = {
	{ "f16", IRDM_ELEM_F16 },
	{ "f32", IRDM_ELEM_F32 },
	{ "f64", IRDM_ELEM_F64 },
	{ NULL, 0 },
};
static const struct irdm_opt_name error_columns_names[] = {
	{ "auto", IRDM_ERROR_COLUMNS_AUTO },
	{ "sample", IRDM_ERROR_COLUMNS_SAMPLE },
	{ "every", IRDM_ERROR_COLUMNS_EVERY },
	{ NULL, 0 },
};
static const struct irdm_opt_name method_names[] = {
	{ "modal", IRDM_METHOD_MODAL },
	{ "time-domain", IRDM_METHOD_TIME_DOMAIN },
	{ NULL, 0 },
};
static const struct irdm_opt_name eig_names[] = {
	{ "auto", IRDM_EIG_AUTO },
	{ "dense", IRDM_EIG_DENSE },
	{ "lanczos", IRDM_EIG_LANCZOS },
	{ "slepc", IRDM_EIG_SLEPC },
	{ NULL, 0 },
};

#define SC(member) IRDM_OPT_FIELD(struct irdm_scene, member)
#define REGION "none | x|y|z<=V | x|y|z>=V | box:X0,Y0,Z0,X1,Y1,Z1 | nodes:I,J,..."

static const struct irdm_opt scene_opts[] = {
	{ .name = "name", .type = IRDM_OPT_STRING, SC(name), .metavar = "TEXT", .help = "scene name (provenance)" },
	{ .name = "mesh", .type = IRDM_OPT_STRING, SC(mesh), .metavar = "cuboid | cube | box:LX,LY,LZ | FILE", .help = "builtin mesh, or a file (.node/.ele .msh .obj .off .stl)" },
	{ .name = "resolution", .type = IRDM_OPT_CUSTOM, .parse = set_resolution, .metavar = "NX,NY,NZ", .help = "hexes per axis for builtin meshes, each 1 to 400 (cuboid 11,11,22; cube 10,10,10)" },
	{ .name = "tets_per_hex", .type = IRDM_OPT_UNSIGNED, SC(tets_per_hex), .metavar = "5 | 6", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 5, .max = 6, .help = "builtin split (5: the paper's cuboid, 13310 tets)" },
	{ .name = "mesh_scale", .type = IRDM_OPT_DOUBLE, SC(mesh_scale), .metavar = "S", .range = IRDM_OPT_GT, .min = 0, .help = "multiply file coordinates by S (0.001 for mm)" },
	{ .name = "tetgen", .type = IRDM_OPT_CUSTOM, .parse = set_tetgen, .metavar = "SWITCHES", .help = "tetgen switches for surface meshes; when given they override target_nodes "
													 "and max_tet_volume (default: sized by target_nodes)" },
	{ .name = "target_nodes", .type = IRDM_OPT_UNSIGNED, SC(target_nodes), .metavar = "N", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 100, .max = 10000000, .help = "surface meshes: about N nodes (within a factor 2; tetgen re-run up to 6 "
																					"times; default 3000 unless max_tet_volume or tetgen is given)" },
	{ .name = "max_tet_volume", .type = IRDM_OPT_DOUBLE, SC(max_tet_volume_m3), .metavar = "M3", .unit = "m^3", .range = IRDM_OPT_GT, .min = 0, .help = "surface meshes: largest tetrahedron (tetgen -a, after mesh_scale)" },
	{ .name = "young", .type = IRDM_OPT_DOUBLE, SC(mat.young_pa), .metavar = "PA", .unit = "Pa", .range = IRDM_OPT_GT, .min = 0, .help = "Young's modulus (default 2000: the paper)" },
	{ .name = "poisson", .type = IRDM_OPT_DOUBLE, SC(mat.poisson), .metavar = "NU", .range = IRDM_OPT_GT | IRDM_OPT_LT, .min = -1, .max = 0.5, .help = "Poisson's ratio (default 0.49: the paper; 0.5 is incompressible)" },
	{ .name = "density", .type = IRDM_OPT_DOUBLE, SC(mat.density_kg_m3), .metavar = "KG_M3", .unit = "kg/m^3", .range = IRDM_OPT_GT, .min = 0, .help = "density (default 110: the paper)" },
	{ .name = "mass", .type = IRDM_OPT_ENUM, SC(mass), .names = mass_names, .help = "mass matrix (default lumped)" },
	{ .name = "damping", .type = IRDM_OPT_CUSTOM, .parse = set_damping, .metavar = "Z1@F1,Z2@F2 | rayleigh:A,B", .help = "ratios Z at two frequencies F in Hz, F1 may be 'mode1'; or C = A M + B K "
															     "(default 0.05@mode1,0.05@100)" },
	{ .name = "floating", .type = IRDM_OPT_CUSTOM, .parse = set_floating, .metavar = "yes | no", .help = "non-grounded object (rigid motion separated); yes turns the default fixed = z<=0 off" },
	{ .name = "fixed", .type = IRDM_OPT_CUSTOM, .parse = set_region, SC(fixed), .metavar = REGION, .help = "fixed nodes, called REGION below (default z<=0)" },
	{ .name = "dt", .type = IRDM_OPT_DOUBLE, SC(dt_s), .metavar = "SECONDS", .unit = "s", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1e-6, .max = 1, .help = "sample period (default 0.001)" },
	{ .name = "representation", .type = IRDM_OPT_CUSTOM, .parse = set_representation, .metavar = "auto | modal:K | modal:all | fir:T", .help = "K modes (1 to 1000000) or all, or an FIR of T samples (1 to 1000000); auto: "
																		   "every mode solved (a dense eigensolve), the cheapest estimated to tick of "
																		   "modal:all (up to 300 modes), modal:300 + static correction, hybrids with "
																		   "heads of 1 to 256 samples, each keeping the fewest modes ringing longest "
																		   "past it whose predicted error is within half of max_error, and "
																		   "modal:all, whose measured error meets max_error; when every mode does not "
																		   "fit in memory (max_memory_mib), the lowest modes of a Lanczos solve whose "
																		   "envelope after a 128-sample head is over 200 max_error, the head from "
																		   "Chebyshev series, measured, and kept up to three times with more modes "
																		   "until it meets max_error; with max_error = none, "
																		   "modal:300 + static correction (default auto)" },
	{ .name = "modes", .type = IRDM_OPT_CUSTOM, .parse = set_modes, .metavar = "K | all", .help = "modes that synthesise a modal-method FIR, 1 to 1000000 (default 300)" },
	{ .name = "fir_tail", .type = IRDM_OPT_CUSTOM, .parse = set_fir_tail, .metavar = "window | window:L | none", .help = "FIR stabilisation: window:L appends L samples past T tapered to zero (Hann), "
															     "the taps' sum restored to the static compliance; the first T stay exact; "
															     "window chooses L: 2T, doubled until every touchable node's force recursion is "
															     "certified stable, up to 16T (refused if none is); none: no window, the engine "
															     "damps an unstable FIR's tail by r^s, which distorts it from the first sample "
															     "(default window)" },
	{ .name = "static_correction", .type = IRDM_OPT_BOOL, SC(static_correction), .help = "residual compliance of dropped modes (modal; default yes)" },
	{ .name = "static_correction_tol", .type = IRDM_OPT_DOUBLE, SC(static_corr_tol), .metavar = "TOL", .range = IRDM_OPT_GE | IRDM_OPT_LT, .min = 0, .max = 1, .help = "modal: drop the static correction's block between touchable nodes a and b when its norm is below TOL sqrt(|S_aa| |S_bb|), the diagonal blocks' norms: the force error at a contact is of about that order (default 0.02; 0 keeps every block)" },
	{ .name = "static_correction_rank", .type = IRDM_OPT_UNSIGNED, SC(static_corr_rank), .metavar = "R", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 0, .max = IRDM_CORR_LOWRANK_MAX, .help = "modal: the far field of the dropped static-correction blocks as a symmetric term of rank R over the touchable nodes, added to every block (image section STATIC_CORR_LOWRANK, R (1 + 3 n_cols) values); 0 leaves it out; not used with exact_head, where two contacts grabbed at once through it can diverge (default 96)" },
	{ .name = "static_correction_cluster", .type = IRDM_OPT_UNSIGNED, SC(static_corr_cluster), .metavar = "N", .range = IRDM_OPT_LE, .max = IRDM_STATIC_CORR_CLUSTER_MAX, .help = "modal: keep the static correction between every pair of touchable nodes, block low-rank over clusters of at most N nearby nodes (image section STATIC_CORR_CLUSTERS): static_correction_tol then bounds every block's error, not the dropped ones', and static_correction_rank is not used; 0 drops blocks instead (default 0)" },
	{ .name = "exact_head", .type = IRDM_OPT_UNSIGNED, SC(exact_head), .metavar = "H", .range = IRDM_OPT_LE, .max = IRDM_HEAD_SAMPLES_MAX / 2, .help = "modal: the hybrid representation: the dropped modes' exact response over the "
																			   "first H samples between touchable nodes, on top of the kept modes, tapered off "
																			   "over H more with the static compliance kept exactly; from every mode of a dense "
																			   "eigensolve, or with eigensolver = lanczos from the K kept modes and Chebyshev series in "
																			   "the stiffness, one per touchable DoF (a grounded object with lumped mass) "
																			   "(default 0: the static correction alone)" },
	{ .name = "max_error", .type = IRDM_OPT_CUSTOM, .parse = set_max_error, .metavar = "E | none", .help = "largest force error an image may have: after the build, its relative RMS "
													       "force error against the exact linear model (every mode, in double) is "
													       "measured for a step and a release at a few touchable nodes, stored in the "
													       "image and printed; above E the image is refused.  none neither measures "
													       "nor checks (the measurement needs every mode, a dense eigensolve, or the "
													       "Chebyshev series of exact_head with eigensolver = lanczos) "
													       "(default 1e-3)" },
	{ .name = "error_columns", .type = IRDM_OPT_ENUM, SC(error_columns), .names = error_columns_names, .help = "where max_error is measured: every touchable node (a grounded object whose "
														   "every mode is solved: representation = auto or exact_head; about a minute "
														   "on 2,000 of them), a sample (spread over the surface, the ones screened as "
														   "worst for the modes dropped, the worst-conditioned), or auto: every one when "
														   "that costs no more than the sample, up to 324 (default auto)" },
	{ .name = "max_head_mib", .type = IRDM_OPT_DOUBLE, SC(max_head_mib), .metavar = "MIB", .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 65536, .help = "representation = auto: the largest exact head it builds, in MiB as stored; a hybrid "
																				   "whose head would be larger is tried again with twice the modes (fewer "
																				   "dropped, fewer kept blocks) while that still ticks cheaper than every "
																				   "mode, else left for the next candidate (default 128)" },
	{ .name = "max_memory_mib", .type = IRDM_OPT_DOUBLE, SC(max_memory_mib), .metavar = "MIB", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 0, .max = 1 << 30, .help = "the memory the precompute plans for, in MiB: a step that needs more (the dense "
																					 "eigensolve of every mode) is refused before it starts, and representation = auto "
																					 "then chooses from the lowest modes of a Lanczos solve (0: the machine's physical "
																					 "memory, or ulimit -v or -d when lower; default 0)" },
	{ .name = "contacts", .type = IRDM_OPT_UNSIGNED, SC(contacts), .metavar = "N", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = IRDM_SCENE_CONTACTS_MAX, .help = "contacts at once that max_error holds: 1, a contact alone; 2, also two grabbed at "
																					     "once at up to 28 pairs of touchable nodes spread over the surface (a grounded "
																					     "object whose every mode is solved: representation = auto or exact_head), "
																					     "auto halving static_correction_tol until they meet it (more blocks "
																					     "between touchable nodes: a larger image) (default 1)" },
	{ .name = "uncertified", .type = IRDM_OPT_BOOL, SC(uncertified), .help = "write an image although some touchable node's force recursion is not "
										 "certified stable (spectral radius >= 1; the engine then damps an FIR's tail "
										 "by r^s); default no: such an image is refused, as `irdm image verify "
										 "--require-stable` would reject it" },
	{ .name = "precision", .type = IRDM_OPT_ENUM, SC(precision), .names = precision_names, .help = "storage of the responses (default f32)" },
	{ .name = "touch", .type = IRDM_OPT_CUSTOM, .parse = set_region, SC(touch), .metavar = "surface | REGION", .help = "touchable surface nodes: columns (default surface)" },
	{ .name = "display", .type = IRDM_OPT_CUSTOM, .parse = set_display, SC(display), .metavar = "surface | touch | REGION", .help = "displayed surface nodes: rows (default surface)" },
	{ .name = "method", .type = IRDM_OPT_ENUM, SC(method), .names = method_names, .help = "how FIR responses are computed (default modal)" },
	{ .name = "substeps", .type = IRDM_OPT_UNSIGNED, SC(substeps), .metavar = "N", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 100000, .help = "time-domain integration steps per sample (default 8)" },
	{ .name = "symmetry", .type = IRDM_OPT_BOOL, SC(symmetry), .help = "split every-mode dense eigensolves by the model's mirror and half-turn symmetries, when it has exact ones (the same eigenpairs, about 4^g times faster for g symmetries; lumped mass; default yes)" },
	{ .name = "eigensolver", .type = IRDM_OPT_ENUM, SC(eigensolver), .names = eig_names, .help = "eigenvalue solver (default auto: by size); slepc: SLEPc over MPI ranks "
												     "(run under mpirun -np N; docs/mpi.md)" },
	{ .name = "threads", .type = IRDM_OPT_UNSIGNED, SC(threads), .metavar = "N", .range = IRDM_OPT_LE, .max = 256, .help = "worker threads (0: all cores)" },
};

const struct irdm_opt_table irdm_scene_options = {
	.what = "scene key",
	.see = "irdm precompute --help",
	.opts = scene_opts,
	.n_opts = sizeof(scene_opts) / sizeof(scene_opts[0]),
};

int irdm_scene_set(struct irdm_scene *sc, const char *key, const char *value,
		   const char *where, char *err, size_t errlen)
{
	return irdm_opt_set(&irdm_scene_options, sc, where, key, value, err, errlen);
}

int irdm_scene_load(struct irdm_scene *sc, const char *path, char *err, size_t errlen)
{
	/* a key set twice is a mistake, not an override: say so */
	struct irdm_opt_file file = { .table = &irdm_scene_options, .obj = sc, .name = path, .reject_duplicates = true };
	struct irdm_text_file t;
	char line[1024];
	int ret;

	ret = irdm_text_open(&t, path, IRDM_TEXT_MAX_BYTES, err, errlen);
	if (ret)
		return ret;
	while ((ret = irdm_text_line(&t, line, sizeof(line), err, errlen)) > 0) {
		file.line_no++;
		ret = irdm_opt_parse_line(&file, line, err, errlen);
		if (ret)
			break;
	}
	irdm_text_close(&t);
	return ret;
}

int irdm_scene_check(const struct irdm_scene *sc, char *err, size_t errlen)
{
	int ret = irdm_material_check(&sc->mat, err, errlen);

	if (ret)
		return ret;
	if (!sc->floating && sc->fixed.kind == IRDM_REGION_NONE) {
		snprintf(err, errlen, "scene: a grounded object needs fixed nodes (set 'fixed' or 'floating = yes')");
		return IRDM_EINVAL;
	}
	if (sc->floating && sc->fixed.kind != IRDM_REGION_NONE) {
		snprintf(err, errlen, "scene: a floating object cannot have fixed nodes ('fixed = %s')",
			 sc->fixed.text);
		return IRDM_EINVAL;
	}
	if (sc->touch.kind == IRDM_REGION_NONE) {
		snprintf(err, errlen, "scene: nothing is touchable ('touch = none')");
		return IRDM_EINVAL;
	}
	if (sc->method == IRDM_METHOD_TIME_DOMAIN && sc->representation != IRDM_REPR_FIR) {
		snprintf(err, errlen, "scene: method = time-domain makes FIR responses: use representation = fir:T");
		return IRDM_EINVAL;
	}
	if (sc->fir_tail && sc->representation != IRDM_REPR_FIR) {
		snprintf(err, errlen, "scene: fir_tail = window:%u windows an FIR's tail: use representation = fir:T",
			 sc->fir_tail);
		return IRDM_EINVAL;
	}
	if (sc->fir_tail && (uint64_t)sc->fir_tail + sc->fir_length > 1000000) {
		snprintf(err, errlen, "scene: fir:%u with fir_tail = window:%u makes more than 1000000 samples",
			 sc->fir_length, sc->fir_tail);
		return IRDM_EINVAL;
	}
	if (sc->exact_head && (sc->representation != IRDM_REPR_MODAL || !sc->modes ||
			       !sc->static_correction)) {
		snprintf(err, errlen, "scene: exact_head = %u adds the dropped modes' head to a truncated modal image: use representation = modal:K with static_correction = yes",
			 sc->exact_head);
		return IRDM_EINVAL;
	}
	if (sc->static_corr_cluster && (sc->representation != IRDM_REPR_MODAL ||
					!sc->static_correction)) {
		snprintf(err, errlen, "scene: static_correction_cluster = %u clusters a modal image's static correction: use representation = modal:K with static_correction = yes",
			 sc->static_corr_cluster);
		return IRDM_EINVAL;
	}
	if (sc->static_corr_cluster && sc->static_corr_cluster < IRDM_STATIC_CORR_CLUSTER_MIN) {
		snprintf(err, errlen, "scene: static_correction_cluster = %u is below %d nodes per cluster (0 turns it off)",
			 sc->static_corr_cluster, IRDM_STATIC_CORR_CLUSTER_MIN);
		return IRDM_EINVAL;
	}
	if (sc->exact_head && sc->eigensolver == IRDM_EIG_SLEPC) {
		snprintf(err, errlen, "scene: exact_head = %u with eigensolver = slepc: the head is built on one process (eigensolver = lanczos or dense)",
			 sc->exact_head);
		return IRDM_EINVAL;
	}
	if (sc->exact_head && sc->eigensolver == IRDM_EIG_LANCZOS &&
	    (sc->floating || sc->mass != IRDM_MASS_LUMPED)) {
		snprintf(err, errlen, "scene: exact_head = %u with eigensolver = lanczos builds the head from Chebyshev series in the stiffness, on a grounded object with lumped mass only: %s",
			 sc->exact_head, sc->floating ? "floating = yes" : "mass = consistent");
		return IRDM_EINVAL;
	}
	if (sc->static_corr_cluster && sc->exact_head) {
		snprintf(err, errlen, "scene: exact_head = %u with static_correction_cluster = %u: the hybrid's head needs the dropped-block correction (static_correction_cluster = 0)",
			 sc->exact_head, sc->static_corr_cluster);
		return IRDM_EINVAL;
	}
	if (sc->contacts > 1 && !(sc->max_error > 0)) {
		snprintf(err, errlen, "scene: contacts = %u holds two contacts at once against max_error: set max_error (not none)",
			 sc->contacts);
		return IRDM_EINVAL;
	}
	if (sc->contacts > 1 && sc->floating) {
		snprintf(err, errlen, "scene: contacts = %u: two contacts at once are measured on a grounded object only (floating = yes)",
			 sc->contacts);
		return IRDM_EINVAL;
	}
	if (sc->damping == IRDM_DAMP_RATIOS && sc->damp_hz[0] > 0 &&
	    fabs(sc->damp_hz[0] - sc->damp_hz[1]) < 1e-9) {
		snprintf(err, errlen, "scene: damping needs two different frequencies");
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

static const char *region_text(const struct irdm_region *r)
{
	return r->text[0] ? r->text : "none";
}

int irdm_scene_format(const struct irdm_scene *sc, char *buf, size_t len)
{
	char damp[96], repr[32];
	static const char *const prec[] = { "?", "f16", "f32", "f64" };
	static const char *const eig[] = { "auto", "dense", "lanczos", "slepc" };

	if (sc->damping == IRDM_DAMP_RAYLEIGH)
		snprintf(damp, sizeof(damp), "rayleigh:%.17g,%.17g", sc->rayleigh.a_per_s,
			 sc->rayleigh.b_s);
	else if (sc->damp_hz[0] == 0)
		snprintf(damp, sizeof(damp), "%.17g@mode1,%.17g@%.17g", sc->damp_ratio[0],
			 sc->damp_ratio[1], sc->damp_hz[1]);
	else
		snprintf(damp, sizeof(damp), "%.17g@%.17g,%.17g@%.17g", sc->damp_ratio[0],
			 sc->damp_hz[0], sc->damp_ratio[1], sc->damp_hz[1]);
	if (sc->repr_auto)
		snprintf(repr, sizeof(repr), "auto");
	else if (sc->representation == IRDM_REPR_FIR)
		snprintf(repr, sizeof(repr), "fir:%u", sc->fir_length);
	else if (sc->modes)
		snprintf(repr, sizeof(repr), "modal:%u", sc->modes);
	else
		snprintf(repr, sizeof(repr), "modal:all");
	int n = snprintf(buf, len,
			 "name=%s\nmesh=%s\nresolution=%u,%u,%u\ntets_per_hex=%u\nmesh_scale=%.17g\n"
			 "tetgen=%s\nyoung=%.17g\npoisson=%.17g\ndensity=%.17g\nmass=%s\ndamping=%s\n"
			 "floating=%s\nfixed=%s\ndt=%.17g\nrepresentation=%s\nstatic_correction=%s\n"
			 "static_correction_tol=%.17g\nstatic_correction_rank=%u\n"
			 "precision=%s\ntouch=%s\ndisplay=%s\nmethod=%s\nsubsteps=%u\neigensolver=%s\nmodes=%u\n",
			 sc->name, sc->mesh, sc->res[0], sc->res[1], sc->res[2], sc->tets_per_hex,
			 sc->mesh_scale, sc->tetgen, sc->mat.young_pa, sc->mat.poisson,
			 sc->mat.density_kg_m3, sc->mass == IRDM_MASS_LUMPED ? "lumped" : "consistent",
			 damp, sc->floating ? "yes" : "no", region_text(&sc->fixed), sc->dt_s, repr,
			 sc->static_correction ? "yes" : "no", sc->static_corr_tol, sc->static_corr_rank,
			 prec[sc->precision & 3],
			 region_text(&sc->touch), region_text(&sc->display),
			 sc->method == IRDM_METHOD_MODAL ? "modal" : "time-domain", sc->substeps,
			 eig[sc->eigensolver], sc->modes);
	if (n < 0 || (size_t)n >= len)
		return -1;
	if (sc->representation == IRDM_REPR_FIR) { /* only for an FIR: older scenes keep their text */
		char tail[32];
		if (sc->fir_tail)
			snprintf(tail, sizeof(tail), "window:%u", sc->fir_tail);
		else
			snprintf(tail, sizeof(tail), "%s", sc->fir_tail_auto ? "window" : "none");
		int t = snprintf(buf + n, len - (size_t)n, "fir_tail=%s\n", tail);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->static_corr_cluster) { /* only when set, as fir_tail */
		int t = snprintf(buf + n, len - (size_t)n, "static_correction_cluster=%u\n",
				 sc->static_corr_cluster);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->exact_head) { /* only when set, as fir_tail */
		int t = snprintf(buf + n, len - (size_t)n, "exact_head=%u\n", sc->exact_head);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (!sc->symmetry) { /* only when set: the same eigenpairs either way */
		int t = snprintf(buf + n, len - (size_t)n, "symmetry=no\n");
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->max_memory_mib > 0) { /* only when set */
		int t = snprintf(buf + n, len - (size_t)n, "max_memory_mib=%.17g\n", sc->max_memory_mib);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->max_head_mib != IRDM_MAX_HEAD_MIB_DEFAULT) { /* only when set */
		int t = snprintf(buf + n, len - (size_t)n, "max_head_mib=%.17g\n", sc->max_head_mib);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->contacts != 1) { /* only when set */
		int t = snprintf(buf + n, len - (size_t)n, "contacts=%u\n", sc->contacts);
		if (t < 0 || (size_t)t >= len - (size_t)n)
			return -1;
		n += t;
	}
	if (sc->tetgen_given || irdm_scene_builtin_mesh(sc))
		return 0; /* as before sizing existed: the same images */
	int k = snprintf(buf + n, len - (size_t)n, "target_nodes=%u\nmax_tet_volume=%.17g\n",
			 irdm_scene_target_nodes(sc), sc->max_tet_volume_m3);
	return (k < 0 || (size_t)k >= len - (size_t)n) ? -1 : 0;
}

bool irdm_scene_builtin_mesh(const struct irdm_scene *sc)
{
	return !strcmp(sc->mesh, "cuboid") || !strcmp(sc->mesh, "cube") ||
	       !strncmp(sc->mesh, "box:", 4);
}

unsigned irdm_scene_target_nodes(const struct irdm_scene *sc)
{
	if (sc->target_nodes || sc->max_tet_volume_m3 > 0)
		return sc->target_nodes;
	return IRDM_SCENE_TARGET_NODES;
}

bool irdm_region_contains(const struct irdm_region *r, uint32_t node, const double p[3],
			  bool on_surface)
{
	/* A relative tolerance so that "z<=0" catches nodes at -1e-17. */
	const double tol = 1e-9;

	switch (r->kind) {
	case IRDM_REGION_NONE:
		return false;
	case IRDM_REGION_SURFACE:
		return on_surface;
	case IRDM_REGION_PLANE:
		return r->below ? p[r->axis] <= r->value_m + tol : p[r->axis] >= r->value_m - tol;
	case IRDM_REGION_BOX:
		for (int a = 0; a < 3; a++)
			if (p[a] < r->box_m[a] - tol || p[a] > r->box_m[a + 3] + tol)
				return false;
		return true;
	case IRDM_REGION_NODES:
		for (size_t i = 0; i < r->n_nodes; i++)
			if (r->nodes[i] == node)
				return true;
		return false;
	}
	return false;
}
