/* SPDX-License-Identifier: MIT */
/* irdm report: every representation of a model against its exact reference. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "irdm/error.h"
#include "report/report.h"
#include "report/report_check.h"
#include "report/report_image.h"
#include "accuracy/reference.h"
#include "accuracy/run.h"

/* Progress of a nested stage, prefixed with what the report is doing. */
struct prefixed {
	const struct irdm_report_opts *o;
	char prefix[96];
};

static void prefixed_progress(void *ctx, const char *stage, double fraction)
{
	struct prefixed *p = ctx;
	char s[192];

	if (!p->o->progress)
		return;
	if (fraction < 0 && strncmp(stage, "warning:", 8))
		return; /* the precompute's notes: not the report's */
	snprintf(s, sizeof(s), "%s: %s", p->prefix, stage);
	p->o->progress(p->o->ctx, s, fraction);
}

/* The reference of one scenario at one dt. */
struct scen_ref {
	const struct irdm_report_scenario *sc;
	size_t N;
	struct irdm_report_cmd *cmds;
	struct irdm_report_conv_out out;
};

static double now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return (x > y) - (x < y);
}

/* Median and 99th percentile of n samples (sorted in place). */
static void percentiles(double *x, size_t n, double *median, double *p99)
{
	qsort(x, n, sizeof(double), cmp_double);
	*median = x[n / 2];
	*p99 = x[(size_t)floor(0.99 * (double)(n - 1))];
}

/* |a - b|_2 / |b|_2 over ticks [t0, t1) of rows of w values. */
static double rel_rms(const double *a, const double *b, size_t w, size_t t0, size_t t1)
{
	double d = 0, r = 0;

	for (size_t i = t0 * w; i < t1 * w; i++) {
		d += (a[i] - b[i]) * (a[i] - b[i]);
		r += b[i] * b[i];
	}
	return r > 0 ? sqrt(d / r) : (d > 0 ? INFINITY : 0);
}

/* max |x|; INFINITY if a value is not finite (a diverged run). */
static double max_abs(const double *x, size_t n)
{
	double m = 0;

	for (size_t i = 0; i < n; i++) {
		if (!isfinite(x[i]))
			return INFINITY;
		m = fmax(m, fabs(x[i]));
	}
	return m;
}

/* No fault, finite, and not growing: the last tenth's largest force at most
 * 10 x that of ticks 40-60 % (every scenario holds or is free by then). */
static bool bounded(const struct irdm_report_engine_out *eo, size_t N, size_t w)
{
	size_t a = 4 * N / 10, b = 6 * N / 10, c = 9 * N / 10;
	double mid = max_abs(&eo->F[a * w], (b - a) * w), end = max_abs(&eo->F[c * w], (N - c) * w);

	return !eo->faulted && isfinite(max_abs(eo->F, N * w)) && end <= 10 * mid + 1e-12;
}

static int resolve_cmds(const struct irdm_report_scenario *sc, const struct irdm_image *img,
			double dt_s, size_t N, struct irdm_report_cmd **cmds, char *err, size_t errlen)
{
	*cmds = malloc(N * sc->n_contacts * sizeof(**cmds));
	if (!*cmds) {
		snprintf(err, errlen, "report: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t t = 0; t < N; t++)
		if (irdm_report_scenario_cmds(sc, img, dt_s, t, &(*cmds)[t * sc->n_contacts])) {
			snprintf(err, errlen, "report: scenario %s: no touchable surface under a contact point at tick %zu",
				 sc->name, t);
			return IRDM_ECONTACT;
		}
	return IRDM_OK;
}

/*
 * A floating object's reference: the exact model through the force engine,
 * whose floating path adds the rigid body (its pose, the rigid compliance
 * in the contact solve, the midpoint step) that the convolution lacks.
 * That path is checked against an RK4 rigid body and a finite-difference
 * Newton solve in tests/test_floating.c.  Displayed nodes: world positions
 * (pose included) less their rest positions.
 */
static int engine_reference(const struct irdm_image *ref, struct scen_ref *sr, char *err,
			    size_t errlen)
{
	struct irdm_report_engine_out eo;
	int ret = irdm_report_engine_run(ref, sr->cmds, sr->sc->n_contacts, sr->N,
					 IRDM_REPORT_DISP_EVERY, &eo, err, errlen);

	if (ret)
		return ret;
	if (eo.faulted) {
		snprintf(err, errlen, "reference: scenario %s: the exact model's engine run faulted",
			 sr->sc->name);
		irdm_report_engine_free(&eo);
		return IRDM_ECONTACT;
	}
	sr->out.F = eo.F;
	sr->out.disp = eo.disp;
	sr->out.n_eval = eo.n_eval;
	free(eo.tick_us);
	return IRDM_OK;
}

/* The exact full model's forces and displayed nodes for every scenario. */
static int references(const struct irdm_report_opts *o, const struct irdm_image *ref, double dt_s,
		      struct scen_ref *sr, char *err, size_t errlen)
{
	const struct irdm_report_config *cfg = o->cfg;
	struct prefixed pp = { .o = o };

	for (size_t k = 0; k < cfg->n_scenarios; k++) {
		struct irdm_report_conv c = { .img = ref, .m = cfg->scenarios[k]->n_contacts, .disp_every = IRDM_REPORT_DISP_EVERY };
		int ret;

		sr[k].sc = cfg->scenarios[k];
		sr[k].N = c.N = c.n_resp = irdm_report_scenario_ticks(sr[k].sc, dt_s);
		ret = resolve_cmds(sr[k].sc, ref, dt_s, c.N, &sr[k].cmds, err, errlen);
		if (ret)
			return ret;
		c.cmds = sr[k].cmds;
		snprintf(pp.prefix, sizeof(pp.prefix), "reference dt %g ms", dt_s * 1e3);
		prefixed_progress(&pp, sr[k].sc->name, (double)(k + 1) / (double)cfg->n_scenarios);
		ret = ref->rigid ? engine_reference(ref, &sr[k], err, errlen) :
				   irdm_report_convolve(&c, &sr[k].out, err, errlen);
		if (ret)
			return ret;
	}
	return IRDM_OK;
}

/* FIR: the recorded recursion without tail damping, step node, RAW_SECONDS. */
static int raw_growth(const struct irdm_image *img, const struct scen_ref *step, double dt_s,
		      double *growth, char *err, size_t errlen)
{
	size_t N = (size_t)llround(IRDM_REPORT_RAW_SECONDS / dt_s), last = (size_t)llround(1.0 / dt_s);
	struct irdm_report_conv c = { .img = img, .m = 1, .N = N, .n_resp = img->meta->fir_length };
	struct irdm_report_conv_out out;
	const double *Fr = &step->out.F[3 * (step->N - 1)];
	int ret;

	*growth = NAN;
	if (img->meta->representation != IRDM_REPR_FIR)
		return IRDM_OK;
	ret = resolve_cmds(step->sc, img, dt_s, N, (struct irdm_report_cmd **)&c.cmds, err, errlen);
	if (!ret)
		ret = irdm_report_convolve(&c, &out, err, errlen);
	free((void *)c.cmds);
	if (ret)
		return ret;
	*growth = max_abs(&out.F[3 * (N - last)], 3 * last) / sqrt(Fr[0] * Fr[0] + Fr[1] * Fr[1] + Fr[2] * Fr[2]);
	irdm_report_conv_free(&out);
	return IRDM_OK;
}

/* Radius and verdict over the image's columns. */
static void stability_of(const struct irdm_image *img, struct irdm_report_row *row)
{
	row->spectral_radius = 0;
	row->cert_stable = true;
	for (uint32_t c = 0; c < img->meta->n_cols; c++) {
		row->spectral_radius = fmax(row->spectral_radius, img->stability[c].spectral_radius);
		if (!(img->stability[c].flags & IRDM_STAB_STABLE))
			row->cert_stable = false;
	}
}

static int same_nodes(const struct irdm_image *a, const struct irdm_image *b)
{
	if (a->meta->n_nodes != b->meta->n_nodes || a->meta->n_cols != b->meta->n_cols)
		return 0;
	for (uint32_t r = 0; r < a->meta->n_nodes; r++)
		if (a->nodes[r].mesh_node != b->nodes[r].mesh_node)
			return 0;
	return 1;
}

/* One scenario on one representation's image: the row's figures. */
static int measure(const struct irdm_image *img, const struct scen_ref *sr,
		   struct irdm_report_row *row, char *err, size_t errlen)
{
	struct irdm_report_engine_out eo;
	size_t w = 3 * sr->sc->n_contacts, n_nodes = img->meta->n_nodes;
	int ret = irdm_report_engine_run(img, sr->cmds, sr->sc->n_contacts, sr->N,
					 IRDM_REPORT_DISP_EVERY, &eo, err, errlen);

	if (ret)
		return ret;
	row->ticks = sr->N;
	row->force_err = rel_rms(eo.F, sr->out.F, w, 0, sr->N);
	row->force_err_first10 = rel_rms(eo.F, sr->out.F, w, 0, sr->N < 10 ? sr->N : 10);
	row->force_err_after100 = sr->N > 100 ? rel_rms(eo.F, sr->out.F, w, 100, sr->N) : NAN;
	row->disp_err = rel_rms(eo.disp, sr->out.disp, n_nodes * 3, 0, sr->out.n_eval);
	row->run_bounded = bounded(&eo, sr->N, w);
	percentiles(eo.tick_us, sr->N, &row->tick_median_us, &row->tick_p99_us);
	irdm_report_engine_free(&eo);
	return IRDM_OK;
}

static int add_row(struct irdm_report_result *res, const struct irdm_report_row *row)
{
	struct irdm_report_row *r = realloc(res->rows, (res->n_rows + 1) * sizeof(*r));

	if (!r)
		return IRDM_ENOMEM;
	res->rows = r;
	res->rows[res->n_rows++] = *row;
	return IRDM_OK;
}

int irdm_report_step_index(const struct irdm_report_config *cfg)
{
	for (size_t k = 0; k < cfg->n_scenarios; k++)
		if (cfg->scenarios[k] == &irdm_report_step)
			return (int)k;
	return -1;
}

/* A representation that names its own dt runs at that dt only. */
static int runs_at(const struct irdm_report_repr *rp, double dt_s)
{
	const char *d = strstr(rp->keys, "dt=");

	return !d || fabs(strtod(d + 3, NULL) - dt_s) < 1e-12;
}

static int one_repr(const struct irdm_report_opts *o, const struct irdm_report_repr *rp,
		    double dt_s, const struct irdm_image *ref, const struct scen_ref *sr,
		    struct irdm_report_result *res, const char *prefix, char *err, size_t errlen)
{
	const struct irdm_report_config *cfg = o->cfg;
	char dtkey[48], name[96];
	const char *keys[] = { cfg->model->keys, dtkey, rp->keys, NULL };
	struct irdm_report_image ri;
	struct irdm_report_row row;
	struct prefixed pp = { .o = o };
	int step = irdm_report_step_index(cfg);
	double growth;
	int ret;

	snprintf(dtkey, sizeof(dtkey), "dt=%.17g", dt_s);
	snprintf(name, sizeof(name), "%s-%s-%gms", cfg->name, rp->name, dt_s * 1e3);
	for (char *c = name; *c; c++)
		if (*c == ':' || *c == '/' || *c == ' ')
			*c = '_';
	snprintf(pp.prefix, sizeof(pp.prefix), "%s %s dt %g ms", prefix, rp->name, dt_s * 1e3);
	ret = irdm_report_image_build(&ri, o->tmp_dir, name, keys, prefixed_progress, &pp, err, errlen);
	if (ret)
		return ret;
	if (!same_nodes(&ri.img, ref)) {
		snprintf(err, errlen, "report: %s: its image holds other nodes than the reference's", rp->name);
		ret = IRDM_EINVAL;
		goto out_image;
	}
	prefixed_progress(&pp, "raw recursion", 0.0);
	growth = NAN;
	ret = step >= 0 ? raw_growth(&ri.img, &sr[step], dt_s, &growth, err, errlen) : 0;
	for (size_t k = 0; !ret && k < cfg->n_scenarios; k++) {
		prefixed_progress(&pp, "scenarios", (double)k / (double)cfg->n_scenarios);
		memset(&row, 0, sizeof(row));
		snprintf(row.config, sizeof(row.config), "%s", cfg->name);
		snprintf(row.repr, sizeof(row.repr), "%s", rp->name);
		snprintf(row.scenario, sizeof(row.scenario), "%s", sr[k].sc->name);
		snprintf(row.keys, sizeof(row.keys), "%s", rp->keys);
		row.dt_s = dt_s;
		row.image_bytes = ri.bytes;
		row.raw_growth = growth;
		row.paper = cfg->paper_repr && !strcmp(cfg->paper_repr, rp->name) &&
			    fabs(cfg->paper_dt_s - dt_s) < 1e-12;
		stability_of(&ri.img, &row);
		ret = measure(&ri.img, &sr[k], &row, err, errlen);
		if (!ret && add_row(res, &row)) {
			snprintf(err, errlen, "report: out of memory");
			ret = IRDM_ENOMEM;
		}
		if (!ret && o->row_done)
			o->row_done(o->row_ctx, &row);
	}
	prefixed_progress(&pp, "scenarios", 1.0);
out_image:
	irdm_report_image_drop(&ri, o->keep_images);
	return ret;
}

static void free_refs(struct scen_ref *sr, size_t n)
{
	for (size_t k = 0; k < n; k++) {
		free(sr[k].cmds);
		irdm_report_conv_free(&sr[k].out);
	}
	free(sr);
}

static int one_dt(const struct irdm_report_opts *o, double dt_s, struct irdm_report_result *res,
		  size_t *done, size_t total, char *err, size_t errlen)
{
	const struct irdm_report_config *cfg = o->cfg;
	char dtkey[48], name[96];
	const char *keys[] = { cfg->model->keys, dtkey,
			       "representation=modal:all static_correction=no precision=f64", NULL };
	struct scen_ref *sr = calloc(cfg->n_scenarios, sizeof(*sr));
	struct irdm_report_image ref;
	struct prefixed pp = { .o = o };
	int step = irdm_report_step_index(cfg);
	int ret;

	if (!sr)
		return IRDM_ENOMEM;
	snprintf(dtkey, sizeof(dtkey), "dt=%.17g", dt_s);
	snprintf(name, sizeof(name), "%s-reference-%gms", cfg->name, dt_s * 1e3);
	snprintf(pp.prefix, sizeof(pp.prefix), "reference dt %g ms", dt_s * 1e3);
	ret = irdm_report_image_build(&ref, o->tmp_dir, name, keys, prefixed_progress, &pp, err, errlen);
	if (ret)
		goto out_refs;
	res->engine_reference = ref.img.rigid != NULL;
	ret = references(o, &ref.img, dt_s, sr, err, errlen);
	if (!ret && step >= 0)
		ret = irdm_report_check_reference(o, &ref.img, dt_s, sr[step].sc, sr[step].out.F, res,
						  err, errlen);
	for (size_t i = 0; !ret && i < cfg->n_reprs; i++) {
		char prefix[32];

		if (!runs_at(&cfg->reprs[i], dt_s) ||
		    (o->only_repr && strcmp(o->only_repr, cfg->reprs[i].name)))
			continue;
		snprintf(prefix, sizeof(prefix), "[%zu/%zu]", ++*done, total);
		ret = one_repr(o, &cfg->reprs[i], dt_s, &ref.img, sr, res, prefix, err, errlen);
	}
	irdm_report_image_drop(&ref, o->keep_images);
out_refs:
	free_refs(sr, cfg->n_scenarios);
	return ret;
}

int irdm_report_run(const struct irdm_report_opts *o, struct irdm_report_result *res,
		    char *err, size_t errlen)
{
	const struct irdm_report_config *cfg = o->cfg;
	double t0 = now_s();
	size_t done = 0, total = 0;
	int ret = IRDM_OK;

	memset(res, 0, sizeof(*res));
	for (size_t d = 0; d < cfg->n_dts; d++)
		for (size_t i = 0; i < cfg->n_reprs; i++)
			total += runs_at(&cfg->reprs[i], cfg->dts_s[d]) &&
				 (!o->only_repr || !strcmp(o->only_repr, cfg->reprs[i].name));
	for (size_t d = 0; !ret && d < cfg->n_dts; d++)
		ret = one_dt(o, cfg->dts_s[d], res, &done, total, err, errlen);
	res->seconds = now_s() - t0;
	if (ret)
		irdm_report_result_free(res);
	return ret;
}

void irdm_report_result_free(struct irdm_report_result *res)
{
	free(res->rows);
	free(res->checks);
	memset(res, 0, sizeof(*res));
}
