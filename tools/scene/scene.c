/* SPDX-License-Identifier: MIT */
/* Scene keys: parsing, defaults, checks and the canonical text. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

const char *const irdm_scene_help =
	"  name = TEXT            scene name (provenance)\n"
	"  mesh = cuboid | cube | box:LX,LY,LZ | FILE   (.node/.ele .msh .obj .off .stl)\n"
	"  resolution = NX,NY,NZ  hexes per axis for builtin meshes (cuboid 11,11,22; cube 10,10,10)\n"
	"  tets_per_hex = 5 | 6   builtin split (5: the paper's cuboid, 13310 tets)\n"
	"  mesh_scale = S         multiply file coordinates by S (0.001 for mm)\n"
	"  tetgen = SWITCHES      tetgen quality switches for surface meshes (default pq1.414)\n"
	"  young = PA  poisson = NU  density = KG_M3   (default 2000, 0.49, 110: the paper)\n"
	"  mass = lumped | consistent\n"
	"  damping = Z1@F1,Z2@F2  ratios at two frequencies in Hz; F1 may be 'mode1'\n"
	"            | rayleigh:A,B   C = A M + B K      (default 0.05@mode1,0.05@100)\n"
	"  floating = yes | no    non-grounded object (rigid motion separated)\n"
	"  fixed = none | x|y|z<=V | x|y|z>=V | box:X0,Y0,Z0,X1,Y1,Z1 | nodes:I,J,...\n"
	"  dt = SECONDS           sample period (default 0.001)\n"
	"  representation = modal:K | modal:all | fir:T\n"
	"  modes = K | all        modes that synthesise a modal-method FIR (default 300)\n"
	"  static_correction = yes | no   residual compliance of dropped modes (modal)\n"
	"  precision = f16 | f32 | f64\n"
	"  touch = surface | REGION      touchable surface nodes (columns)\n"
	"  display = surface | touch | REGION   displayed surface nodes (rows)\n"
	"  method = modal | time-domain  how FIR responses are computed\n"
	"  substeps = N           time-domain integration steps per sample (default 8)\n"
	"  eigensolver = auto | dense | lanczos\n"
	"  threads = N            worker threads (0: all cores)\n";

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
	sc->modes = 300;
	sc->static_correction = true;
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

static int parse_bool(const char *s, bool *out)
{
	if (!strcmp(s, "yes") || !strcmp(s, "true") || !strcmp(s, "1") || !strcmp(s, "on"))
		*out = true;
	else if (!strcmp(s, "no") || !strcmp(s, "false") || !strcmp(s, "0") || !strcmp(s, "off"))
		*out = false;
	else
		return -1;
	return 0;
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
		r->kind = IRDM_REGION_NONE;   /* rows = touch only */
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

static int set_key(struct irdm_scene *sc, const char *k, const char *v)
{
	bool b;

	if (!strcmp(k, "name"))
		return snprintf(sc->name, sizeof(sc->name), "%s", v) >= (int)sizeof(sc->name);
	if (!strcmp(k, "mesh"))
		return snprintf(sc->mesh, sizeof(sc->mesh), "%s", v) >= (int)sizeof(sc->mesh);
	if (!strcmp(k, "resolution"))
		return parse_resolution(sc, v);
	if (!strcmp(k, "tets_per_hex"))
		return parse_uint(v, 6, &sc->tets_per_hex) ||
		       (sc->tets_per_hex != 5 && sc->tets_per_hex != 6);
	if (!strcmp(k, "mesh_scale"))
		return parse_double(v, &sc->mesh_scale) || sc->mesh_scale <= 0;
	if (!strcmp(k, "tetgen")) {
		for (const char *p = v; *p; p++)
			if (!isalnum((unsigned char)*p) && *p != '.' && *p != '/')
				return -1;
		return snprintf(sc->tetgen, sizeof(sc->tetgen), "%s", v) >= (int)sizeof(sc->tetgen);
	}
	if (!strcmp(k, "young"))
		return parse_double(v, &sc->mat.young_pa);
	if (!strcmp(k, "poisson"))
		return parse_double(v, &sc->mat.poisson);
	if (!strcmp(k, "density"))
		return parse_double(v, &sc->mat.density_kg_m3);
	if (!strcmp(k, "mass")) {
		if (!strcmp(v, "lumped"))
			sc->mass = IRDM_MASS_LUMPED;
		else if (!strcmp(v, "consistent"))
			sc->mass = IRDM_MASS_CONSISTENT;
		else
			return -1;
		return 0;
	}
	if (!strcmp(k, "damping"))
		return parse_damping(sc, v);
	if (!strcmp(k, "floating")) {
		if (parse_bool(v, &b))
			return -1;
		sc->floating = b;
		if (b && sc->fixed.kind == IRDM_REGION_PLANE && !strcmp(sc->fixed.text, "z<=0"))
			parse_region("none", &sc->fixed, false);   /* default constraint off */
		return 0;
	}
	if (!strcmp(k, "fixed"))
		return parse_region(v, &sc->fixed, false);
	if (!strcmp(k, "dt"))
		return parse_double(v, &sc->dt_s) || sc->dt_s <= 0 || sc->dt_s > 1;
	if (!strcmp(k, "representation"))
		return parse_representation(sc, v);
	if (!strcmp(k, "modes")) {
		if (!strcmp(v, "all") || !strcmp(v, "0")) {
			sc->modes = 0;
			return 0;
		}
		return parse_uint(v, 1000000, &sc->modes) || sc->modes == 0;
	}
	if (!strcmp(k, "static_correction"))
		return parse_bool(v, &sc->static_correction);
	if (!strcmp(k, "precision")) {
		if (!strcmp(v, "f16"))
			sc->precision = IRDM_ELEM_F16;
		else if (!strcmp(v, "f32"))
			sc->precision = IRDM_ELEM_F32;
		else if (!strcmp(v, "f64"))
			sc->precision = IRDM_ELEM_F64;
		else
			return -1;
		return 0;
	}
	if (!strcmp(k, "touch"))
		return parse_region(v, &sc->touch, false);
	if (!strcmp(k, "display"))
		return parse_region(v, &sc->display, true);
	if (!strcmp(k, "method")) {
		if (!strcmp(v, "modal"))
			sc->method = IRDM_METHOD_MODAL;
		else if (!strcmp(v, "time-domain"))
			sc->method = IRDM_METHOD_TIME_DOMAIN;
		else
			return -1;
		return 0;
	}
	if (!strcmp(k, "substeps"))
		return parse_uint(v, 100000, &sc->substeps) || sc->substeps == 0;
	if (!strcmp(k, "eigensolver")) {
		if (!strcmp(v, "auto"))
			sc->eigensolver = IRDM_EIG_AUTO;
		else if (!strcmp(v, "dense"))
			sc->eigensolver = IRDM_EIG_DENSE;
		else if (!strcmp(v, "lanczos"))
			sc->eigensolver = IRDM_EIG_LANCZOS;
		else
			return -1;
		return 0;
	}
	if (!strcmp(k, "threads"))
		return parse_uint(v, 256, &sc->threads);
	return -2;
}

int irdm_scene_set(struct irdm_scene *sc, const char *key, const char *value,
		   const char *where, char *err, size_t errlen)
{
	int r = set_key(sc, key, value);

	if (r == -2) {
		snprintf(err, errlen, "%s: unknown scene key '%s' (see irdm precompute --help)",
			 where, key);
		return IRDM_EINVAL;
	}
	if (r) {
		snprintf(err, errlen, "%s: invalid value '%s' for '%s' (see irdm precompute --help)",
			 where, value, key);
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

static char *trim(char *s)
{
	char *e;

	while (isspace((unsigned char)*s))
		s++;
	e = s + strlen(s);
	while (e > s && isspace((unsigned char)e[-1]))
		*--e = 0;
	return s;
}

int irdm_scene_load(struct irdm_scene *sc, const char *path, char *err, size_t errlen)
{
	FILE *f = fopen(path, "r");
	char line[1024], where[600];
	int lineno = 0, ret = IRDM_EFORMAT;

	if (!f) {
		snprintf(err, errlen, "%s: cannot open scene: %s", path, strerror(errno));
		return IRDM_EIO;
	}
	while (fgets(line, sizeof(line), f)) {
		lineno++;
		snprintf(where, sizeof(where), "%s:%d", path, lineno);
		if (!strchr(line, '\n') && !feof(f)) {
			snprintf(err, errlen, "%s: line too long", where);
			goto out_close;
		}
		char *hash = strchr(line, '#');
		if (hash)
			*hash = 0;
		char *s = trim(line);
		if (!*s)
			continue;
		char *eq = strchr(s, '=');
		if (!eq) {
			snprintf(err, errlen, "%s: expected 'key = value'", where);
			goto out_close;
		}
		*eq = 0;
		ret = irdm_scene_set(sc, trim(s), trim(eq + 1), where, err, errlen);
		if (ret)
			goto out_close;
		ret = IRDM_EFORMAT;
	}
	if (ferror(f)) {
		snprintf(err, errlen, "%s: read failed: %s", path, strerror(errno));
		ret = IRDM_EIO;
		goto out_close;
	}
	ret = IRDM_OK;
out_close:
	fclose(f);
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
	static const char *const eig[] = { "auto", "dense", "lanczos" };

	if (sc->damping == IRDM_DAMP_RAYLEIGH)
		snprintf(damp, sizeof(damp), "rayleigh:%.17g,%.17g", sc->rayleigh.a_per_s,
			 sc->rayleigh.b_s);
	else if (sc->damp_hz[0] == 0)
		snprintf(damp, sizeof(damp), "%.17g@mode1,%.17g@%.17g", sc->damp_ratio[0],
			 sc->damp_ratio[1], sc->damp_hz[1]);
	else
		snprintf(damp, sizeof(damp), "%.17g@%.17g,%.17g@%.17g", sc->damp_ratio[0],
			 sc->damp_hz[0], sc->damp_ratio[1], sc->damp_hz[1]);
	if (sc->representation == IRDM_REPR_FIR)
		snprintf(repr, sizeof(repr), "fir:%u", sc->fir_length);
	else if (sc->modes)
		snprintf(repr, sizeof(repr), "modal:%u", sc->modes);
	else
		snprintf(repr, sizeof(repr), "modal:all");
	int n = snprintf(buf, len,
		"name=%s\nmesh=%s\nresolution=%u,%u,%u\ntets_per_hex=%u\nmesh_scale=%.17g\n"
		"tetgen=%s\nyoung=%.17g\npoisson=%.17g\ndensity=%.17g\nmass=%s\ndamping=%s\n"
		"floating=%s\nfixed=%s\ndt=%.17g\nrepresentation=%s\nstatic_correction=%s\n"
		"precision=%s\ntouch=%s\ndisplay=%s\nmethod=%s\nsubsteps=%u\neigensolver=%s\nmodes=%u\n",
		sc->name, sc->mesh, sc->res[0], sc->res[1], sc->res[2], sc->tets_per_hex,
		sc->mesh_scale, sc->tetgen, sc->mat.young_pa, sc->mat.poisson,
		sc->mat.density_kg_m3, sc->mass == IRDM_MASS_LUMPED ? "lumped" : "consistent",
		damp, sc->floating ? "yes" : "no", region_text(&sc->fixed), sc->dt_s, repr,
		sc->static_correction ? "yes" : "no", prec[sc->precision & 3],
		region_text(&sc->touch), region_text(&sc->display),
		sc->method == IRDM_METHOD_MODAL ? "modal" : "time-domain", sc->substeps,
		eig[sc->eigensolver], sc->modes);
	return (n < 0 || (size_t)n >= len) ? -1 : 0;
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
