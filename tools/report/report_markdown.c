/* SPDX-License-Identifier: MIT */
/* The report as Markdown: one line per representation, the verdicts. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "report/report.h"

/* One representation at one period, over its scenarios. */
struct summary {
	const char *repr;
	double dt_s;
	double force_worst, step_first10, step_after100, disp_worst;
	double tick_median_us, tick_p99_us; /* worst scenario */
	size_t bytes;
	double radius, raw_growth;
	int cert_stable, bounded;
	double per_scen[8];
};

static void summarise(const struct irdm_report_config *cfg, const struct irdm_report_result *res,
		      const char *repr, double dt_s, struct summary *s)
{
	memset(s, 0, sizeof(*s));
	s->repr = repr;
	s->dt_s = dt_s;
	s->step_first10 = s->step_after100 = NAN;
	s->cert_stable = s->bounded = 1;
	for (size_t i = 0; i < res->n_rows; i++) {
		const struct irdm_report_row *r = &res->rows[i];
		if (strcmp(r->repr, repr) || fabs(r->dt_s - dt_s) > 1e-12)
			continue;
		for (size_t k = 0; k < cfg->n_scenarios && k < 8; k++)
			if (!strcmp(cfg->scenarios[k]->name, r->scenario))
				s->per_scen[k] = r->force_err;
		s->force_worst = fmax(s->force_worst, r->force_err);
		s->disp_worst = fmax(s->disp_worst, r->disp_err);
		s->tick_median_us = fmax(s->tick_median_us, r->tick_median_us);
		s->tick_p99_us = fmax(s->tick_p99_us, r->tick_p99_us);
		if (!strcmp(r->scenario, "step")) {
			s->step_first10 = r->force_err_first10;
			s->step_after100 = r->force_err_after100;
		}
		s->bytes = r->image_bytes;
		s->radius = r->spectral_radius;
		s->raw_growth = r->raw_growth;
		s->cert_stable &= r->cert_stable;
		s->bounded &= r->run_bounded;
	}
}

static void pct(FILE *f, double x)
{
	if (isnan(x))
		fputs(" - |", f);
	else
		fprintf(f, " %.3g %% |", 100 * x);
}

static const char *growth_text(double g, char *buf, size_t n)
{
	if (isnan(g))
		return "-";
	if (isinf(g))
		return "overflow";
	snprintf(buf, n, "%.3g", g);
	return buf;
}

static int is_paper(const struct irdm_report_config *cfg, const struct summary *s)
{
	return cfg->paper_repr && !strcmp(cfg->paper_repr, s->repr) &&
	       fabs(cfg->paper_dt_s - s->dt_s) < 1e-12;
}

static void table(FILE *f, const struct irdm_report_config *cfg, const struct summary *S, size_t n)
{
	int step = irdm_report_step_index(cfg) >= 0;

	fputs("| representation | dt | stable (radius) | raw FIR growth | bytes | tick median / p99 |", f);
	for (size_t k = 0; k < cfg->n_scenarios; k++)
		fprintf(f, " %s |", cfg->scenarios[k]->name);
	fputs(step ? " step, first 10 ticks | step, from tick 100 | surface, worst |\n" :
		     " surface, worst |\n",
	      f);
	fputs("|---|---|---|---|---|---|", f);
	for (size_t k = 0; k < cfg->n_scenarios; k++)
		fputs("---|", f);
	fputs(step ? "---|---|---|\n" : "---|\n", f);
	for (size_t i = 0; i < n; i++) {
		const struct summary *s = &S[i];
		char g[32];

		fprintf(f, "| %s%s%s | %g ms | %s (%.6f) | %s | %zu | %.2f / %.2f us |",
			is_paper(cfg, s) ? "**" : "", s->repr, is_paper(cfg, s) ? " (paper)**" : "",
			s->dt_s * 1e3, s->cert_stable && s->bounded ? "yes" : "**no**", s->radius,
			growth_text(s->raw_growth, g, sizeof(g)), s->bytes, s->tick_median_us,
			s->tick_p99_us);
		for (size_t k = 0; k < cfg->n_scenarios; k++)
			pct(f, s->per_scen[k]);
		if (step) {
			pct(f, s->step_first10);
			pct(f, s->step_after100);
		}
		pct(f, s->disp_worst);
		fputc('\n', f);
	}
}

/* The error a verdict judges: the worst scenario's whole run, or the
 * step from tick 100 on (the settled force, as truncation is usually shown). */
static double judged(const struct summary *s, int settled)
{
	return settled ? s->step_after100 : s->force_worst;
}

/* The fastest and the smallest of the stable ones within tol. */
static void best(const struct summary *S, size_t n, double tol, int settled,
		 const struct summary **fast, const struct summary **small)
{
	*fast = *small = NULL;
	for (size_t i = 0; i < n; i++) {
		const struct summary *s = &S[i];
		if (!s->cert_stable || !s->bounded || !(judged(s, settled) <= tol))
			continue;
		if (!*fast || s->tick_median_us < (*fast)->tick_median_us)
			*fast = s;
		if (!*small || s->bytes < (*small)->bytes)
			*small = s;
	}
}

/* Recommended: of the stable ones within tol whose tick is within 10 % of
 * the fastest (tick times this close are the host's noise), the smallest. */
static const struct summary *recommended(const struct summary *S, size_t n, double tol)
{
	const struct summary *fast, *small, *r = NULL;

	best(S, n, tol, 0, &fast, &small);
	for (size_t i = 0; fast && i < n; i++) {
		const struct summary *s = &S[i];
		if (!s->cert_stable || !s->bounded || !(s->force_worst <= tol) ||
		    s->tick_median_us > 1.1 * fast->tick_median_us)
			continue;
		if (!r || s->bytes < r->bytes)
			r = s;
	}
	return r;
}

static void name_best(FILE *f, const struct summary *S, size_t n, double tol, int settled,
		      const char *what)
{
	const struct summary *fast, *small;

	best(S, n, tol, settled, &fast, &small);
	if (!fast) {
		fprintf(f, "- **No representation is stable and within %g %%** (%s).\n", 100 * tol, what);
		return;
	}
	fprintf(f, "- **Stable and within %g %%** (%s): lowest tick time **%s at %g ms** (%.2f us median, p99 %.2f us, %zu bytes, error %.3g %%); smallest image **%s at %g ms** (%zu bytes, %.2f us, %.3g %%).\n",
		100 * tol, what, fast->repr, fast->dt_s * 1e3, fast->tick_median_us,
		fast->tick_p99_us, fast->bytes, 100 * judged(fast, settled), small->repr,
		small->dt_s * 1e3, small->bytes, small->tick_median_us, 100 * judged(small, settled));
}

static void verdicts(FILE *f, const struct irdm_report_config *cfg, const struct summary *S,
		     size_t n)
{
	const struct summary *rec;
	char g[32];

	for (size_t i = 0; i < n; i++)
		if (is_paper(cfg, &S[i]))
			fprintf(f, "- **The paper's setting** (%s at %g ms): recorded force recursion's spectral radius %.6f (%s); run without the engine's tail damping for %.0f s on the step, its force ends at %s times the exact held force%s.\n",
				S[i].repr, S[i].dt_s * 1e3, S[i].radius,
				S[i].cert_stable ? "stable" : "**unstable**", IRDM_REPORT_RAW_SECONDS,
				growth_text(S[i].raw_growth, g, sizeof(g)),
				S[i].raw_growth > 10 ? " (it diverges)" : "");
	name_best(f, S, n, 0.01, 0, "force error, worst scenario, whole run, first ticks included");
	name_best(f, S, n, 0.001, 0, "the same");
	if (irdm_report_step_index(cfg) >= 0) {
		name_best(f, S, n, 0.01, 1, "the step's force from tick 100 on, the first ticks left out");
		name_best(f, S, n, 0.001, 1, "the same");
	}
	rec = recommended(S, n, 0.01);
	if (rec)
		fprintf(f, "- **Recommended** for this model: **%s at %g ms** (%.2f us, %zu bytes, worst error %.3g %%): of the stable ones within 1 %% over every whole run, the smallest whose tick is within 10 %% of the fastest.\n",
			rec->repr, rec->dt_s * 1e3, rec->tick_median_us, rec->bytes, 100 * rec->force_worst);
}

static void reference_check(FILE *f, const struct irdm_report_config *cfg,
			    const struct irdm_report_result *res)
{
	fprintf(f, "\nReference check: the exact model's responses of the step node against time-domain (Newmark) ones, and the step's forces from each, over its first %g s:\n\n| dt | Newmark substeps | max abs dR / max abs R | step forces, relative RMS difference |\n|---|---|---|---|\n", cfg->check_s);
	for (size_t i = 0; i < res->n_checks; i++)
		fprintf(f, "| %g ms | %u | %.2e | %.2e |\n", res->checks[i].dt_s * 1e3,
			res->checks[i].substeps, res->checks[i].resp_rel_diff, res->checks[i].force_rel_diff);
}

/* The figures quoted are test_floating's output (its own 3x3x3 cube). */
static void floating_reference(FILE *f)
{
	fputs("\n**Reference for this configuration.** The object floats, so the direct\n"
	      "convolution of the other configurations' reference does not apply: it has\n"
	      "no rigid motion.  The reference here is the same exact full model\n"
	      "(`representation=modal:all static_correction=no precision=f64`) run through\n"
	      "the force engine, whose floating path adds the rigid body (its pose, its\n"
	      "compliance in the contact solve, the midpoint rule).  That path is itself\n"
	      "checked in `tests/test_floating.c` against a reference that shares none of it\n"
	      "(the image's responses convolved in double, classical RK4 with 64 sub-steps\n"
	      "for the rigid body, a finite-difference Newton solve of the end-of-tick\n"
	      "position) on the 12 cm cube at 3x3x3 hexes: relative RMS force error 1.2e-7\n"
	      "on a 3 cm, 1 Hz swing and 8.2e-12 on a 2 mm tap (limit 1e-4).  So the\n"
	      "errors below measure each representation's truncation, correction and\n"
	      "storage precision, and the reference's own error is at most that of the\n"
	      "engine's floating path.\n",
	      f);
}

void irdm_report_markdown(FILE *f, const struct irdm_report_config *cfg,
			  const struct irdm_report_result *res, const char *plots_prefix)
{
	struct summary *S = calloc(cfg->n_reprs * cfg->n_dts, sizeof(*S));
	size_t n = 0;

	if (!S)
		return;
	for (size_t d = 0; d < cfg->n_dts; d++)
		for (size_t i = 0; i < cfg->n_reprs; i++) {
			summarise(cfg, res, cfg->reprs[i].name, cfg->dts_s[d], &S[n]);
			if (S[n].bytes)
				n++;
		}
	fprintf(f, "### %s: %s\n\n", cfg->name, cfg->model->name);
	fprintf(f, "Model keys: `%s`.  Scenarios:\n\n", cfg->model->keys);
	for (size_t k = 0; k < cfg->n_scenarios; k++)
		fprintf(f, "- `%s`: %s\n", cfg->scenarios[k]->name, cfg->scenarios[k]->what);
	if (res->engine_reference)
		floating_reference(f);
	else
		reference_check(f, cfg, res);
	fprintf(f, "\nRelative RMS force error against the exact model per scenario (whole run)%s, and the worst scenario's displayed-node error%s:\n\n",
		irdm_report_step_index(cfg) >= 0 ? ", then the step's first 10 ticks and its ticks from 100 on" : "",
		res->engine_reference ? " (world positions, the rigid motion included, less the rest positions)" : "");
	table(f, cfg, S, n);
	fputc('\n', f);
	verdicts(f, cfg, S, n);
	if (plots_prefix)
		fprintf(f, "\n![error vs tick time](%s-%s-tick.png)\n![error vs image bytes](%s-%s-bytes.png)\n",
			plots_prefix, cfg->name, plots_prefix, cfg->name);
	if (plots_prefix && irdm_report_step_index(cfg) >= 0)
		fprintf(f, "![settled error vs tick time](%s-%s-settled.png)\n", plots_prefix, cfg->name);
	fprintf(f, "\n%zu rows in %.0f s.\n\n", res->n_rows, res->seconds);
	free(S);
}
