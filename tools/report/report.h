/* SPDX-License-Identifier: MIT */
/*
 * irdm report: accuracy against an exact reference, tick time and image
 * size, for each representation of one model on each scenario.
 *
 * A representation and a model are strings of scene keys ("key=value"
 * separated by spaces: docs/scene-format.md), so a representation added
 * to the precompute library later is one more line of a table.  A
 * scenario is a prescribed contact trajectory (accuracy/scenario.h).
 *
 * The reference of a model is its exact full model: every elastic mode,
 * no static correction, double precision (representation = modal:all),
 * its responses R[s] read back for every sample of the run (no
 * truncation) and the contact forces solved by direct convolution in
 * double (accuracy/reference.c), not by the engine.  A floating object's
 * reference is that exact model run by the force engine with its rigid
 * body (the convolution has no rigid motion): report.c, engine_reference().
 * The representation under test runs in the force engine, as the firmware
 * runs it.
 */
#ifndef IRDM_TOOLS_REPORT_H
#define IRDM_TOOLS_REPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "modal/modal.h" /* irdm_progress_fn */
#include "accuracy/scenario.h"

struct irdm_report_repr {
	const char *name; /* short label for tables and plots */
	const char *keys; /* scene keys on top of the model's */
};

struct irdm_report_model {
	const char *name;
	const char *keys; /* mesh, material, fixed, touch, display */
};

/* One configuration: a model, its representations and scenarios. */
struct irdm_report_config {
	const char *name;
	const struct irdm_report_model *model;
	const struct irdm_report_repr *reprs;
	size_t n_reprs;
	const struct irdm_report_scenario *const *scenarios;
	size_t n_scenarios;
	const double *dts_s; /* sample periods; each representation at each */
	size_t n_dts;
	/* the paper's setting, marked in tables and plots: a repr name and dt */
	const char *paper_repr;
	double paper_dt_s;
	double check_s; /* the reference check's length (report_check.h) */
};

/* The shipped configurations by name ("sweep", "paper", "floating", "tiny",
 * "tiny-floating"), or NULL. */
const struct irdm_report_config *irdm_report_config_find(const char *name);
/* Their names, comma-separated (for help texts). */
const char *irdm_report_config_names(void);
/* The index of the step scenario in cfg (the raw FIR recursion, the
 * reference check and the settled-force verdicts use it), or -1. */
int irdm_report_step_index(const struct irdm_report_config *cfg);

/* One row of the report: a representation at one dt on one scenario. */
struct irdm_report_row {
	char config[32], repr[48], scenario[24];
	double dt_s;
	char keys[256];
	/* force error relative to the reference: |F - Fref|_2 / |Fref|_2 over
	 * the whole run, its first 10 ticks and the ticks from 100 on */
	double force_err, force_err_first10, force_err_after100;
	double disp_err; /* displayed nodes, every DISP_EVERY-th tick */
	double tick_median_us, tick_p99_us;
	size_t image_bytes;
	double spectral_radius; /* largest recorded radius of the columns used */
	bool cert_stable;       /* every column used certified stable */
	bool run_bounded;       /* finite, no fault, not growing (report.c) */
	/* FIR: the recorded recursion run without the engine's tail damping
	 * (the step node, RAW_SECONDS): max |F| of its last second over the
	 * reference's; NAN for modal images */
	double raw_growth;
	size_t ticks;
	bool paper; /* the configuration's paper setting */
};

#define IRDM_REPORT_DISP_EVERY 10
#define IRDM_REPORT_RAW_SECONDS 20.0

struct irdm_report_opts {
	const struct irdm_report_config *cfg;
	const char *tmp_dir;   /* images are built here and removed */
	const char *only_repr; /* NULL: all; else only this name */
	bool keep_images;
	irdm_progress_fn progress;
	void *ctx;
	/* each row as it is done (the CSV writer), may be NULL */
	void (*row_done)(void *ctx, const struct irdm_report_row *row);
	void *row_ctx;
};

/* The reference checked against a second, independent method: the
 * time-domain (Newmark) responses of the step node over the step's first
 * second (report_check.c). */
struct irdm_report_check {
	double dt_s;
	unsigned substeps;
	double resp_rel_diff;  /* max |R_td - R_ref| / max |R_ref| */
	double force_rel_diff; /* step forces from each, relative RMS */
};

struct irdm_report_result {
	struct irdm_report_row *rows;
	size_t n_rows;
	struct irdm_report_check *checks; /* one per dt */
	size_t n_checks;
	/* the reference was the exact model run by the engine (a floating
	 * object), not the convolution */
	bool engine_reference;
	double seconds;
};

/*
 * Build every image, run every scenario, fill res (free with
 * irdm_report_result_free()).
 * Return: IRDM_OK; IRDM_EINVAL if a key string or scenario does not fit
 * the model; IRDM_ENOMEM; IRDM_EIO; any error of irdm_precompute() or of
 * the engine's set-up.  A one-line reason goes to err.
 */
int irdm_report_run(const struct irdm_report_opts *o, struct irdm_report_result *res,
		    char *err, size_t errlen);
void irdm_report_result_free(struct irdm_report_result *res);

/* CSV: a header line, then one line per row. */
void irdm_report_csv_header(FILE *f);
void irdm_report_csv_row(FILE *f, const struct irdm_report_row *r);

/* Markdown: the tables, the verdicts and the recommended setting. */
void irdm_report_markdown(FILE *f, const struct irdm_report_config *cfg,
			  const struct irdm_report_result *res, const char *plots_prefix);

#endif
