/* SPDX-License-Identifier: MIT */
/* An image's force error at every touchable column (scan.h). */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy/col_resp.h"
#include "accuracy/measure.h"
#include "accuracy/run.h"
#include "accuracy/scan.h"
#include "accuracy/split.h"
#include "util/clock.h"

struct work {
	struct irdm_col_resp cr;
	double *rt, *R, *Fref, *F;
	double *errs; /* per column */
	struct irdm_report_cmd *cmds;
	struct irdm_report_runner *run;
};

static void work_free(struct work *w)
{
	irdm_col_resp_free(&w->cr);
	free(w->rt);
	free(w->R);
	free(w->Fref);
	free(w->F);
	free(w->errs);
	free(w->cmds);
	irdm_report_runner_close(w->run);
}

/* Column c's two runs (R: its exact response): the larger error. */
static int scan_column(const struct irdm_image *img, struct work *w, size_t c, size_t N,
		       struct irdm_scan *res, uint32_t mesh_node, char *err, size_t errlen)
{
	double worst = 0;

	for (int release = 0; release < 2; release++) {
		bool faulted;
		double e;
		int ret;

		if (!irdm_split_forces(w->R, N, release, w->Fref)) {
			snprintf(err, errlen, "scan: the exact first response sample of mesh node %u is singular", mesh_node);
			return IRDM_EINVAL;
		}
		irdm_measure_cmds(release, img->columns[c], N, w->cmds);
		ret = irdm_report_runner_run(w->run, w->cmds, N, w->F, &faulted, err, errlen);
		if (ret)
			return ret;
		e = faulted ? INFINITY : irdm_measure_rel_rms(w->F, w->Fref, 3 * N);
		if (!(e <= worst))
			worst = e;
		if (!(e <= res->worst)) {
			res->worst = e;
			res->worst_node = mesh_node;
			res->worst_run = release ? "release" : "step";
		}
	}
	w->errs[c] = worst;
	return IRDM_OK;
}

static int by_value(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return (x > y) - (x < y);
}

/* The median and p90 of the columns' errors. */
static void summarise(double *errs, size_t n, struct irdm_scan *res)
{
	qsort(errs, n, sizeof(*errs), by_value);
	res->median = errs[n / 2];
	res->p90 = errs[(9 * n) / 10 < n ? (9 * n) / 10 : n - 1];
}

int irdm_scan_every_column(const struct irdm_image *img, const struct irdm_modes *m,
			   const struct irdm_mode *zoh, const int64_t *col_dofs,
			   const uint32_t *mesh_nodes, size_t n_cols,
			   irdm_progress_fn fn, void *ctx, struct irdm_scan *res, char *err,
			   size_t errlen)
{
	size_t N = irdm_measure_ticks(img->meta->dt_s), nm = m->n_modes;
	struct work w = { 0 };
	double t0 = irdm_now_s();
	int ret = IRDM_EINVAL;

	memset(res, 0, sizeof(*res));
	res->ticks = N;
	if (img->rigid || n_cols != img->meta->n_cols || !n_cols) {
		snprintf(err, errlen, "scan: %s", img->rigid ? "a floating object's exact model has rigid motion: not scanned" : "the model's columns are not the image's");
		return ret;
	}
	for (size_t c = 0; c < n_cols; c++)
		if (img->nodes[img->columns[c]].mesh_node != mesh_nodes[c]) {
			snprintf(err, errlen, "scan: column %zu is mesh node %u in the image, %u in the model",
				 c, img->nodes[img->columns[c]].mesh_node, mesh_nodes[c]);
			return ret;
		}
	ret = irdm_col_resp_init(&w.cr, m, N, 1);
	if (ret) {
		snprintf(err, errlen, "scan: out of memory");
		return ret;
	}
	ret = IRDM_ENOMEM;
	w.rt = malloc(w.cr.batch * 9 * N * sizeof(double));
	w.R = malloc(N * 9 * sizeof(double));
	w.Fref = malloc(N * 3 * sizeof(double));
	w.F = malloc(N * 3 * sizeof(double));
	w.errs = malloc(n_cols * sizeof(double));
	w.cmds = malloc(N * sizeof(*w.cmds));
	if (!w.rt || !w.R || !w.Fref || !w.F || !w.errs || !w.cmds) {
		snprintf(err, errlen, "scan: out of memory");
		goto out;
	}
	ret = irdm_report_runner_open(&w.run, img, 1, err, errlen);
	if (ret)
		goto out;
	for (size_t d = 0; d < nm; d++)
		irdm_zoh_response(&zoh[d], N, &w.cr.x[0][d * N]);
	ret = irdm_col_resp_ready(&w.cr);
	if (ret)
		snprintf(err, errlen, "scan: out of memory");
	for (size_t c0 = 0; c0 < n_cols && !ret; c0 += w.cr.batch) {
		size_t nb = n_cols - c0 < w.cr.batch ? n_cols - c0 : w.cr.batch;

		irdm_col_resp_run(&w.cr, col_dofs, c0, nb, (double *const[]){ w.rt });
		for (size_t c = 0; c < nb && !ret; c++) {
			irdm_col_resp_column(w.rt, c, N, w.R);
			ret = scan_column(img, &w, c0 + c, N, res, mesh_nodes[c0 + c], err, errlen);
		}
		if (fn)
			fn(ctx, "error at every column", (double)(c0 + nb) / (double)n_cols);
	}
	if (!ret) {
		res->n_cols = n_cols;
		summarise(w.errs, n_cols, res);
	}
out:
	work_free(&w);
	res->seconds = irdm_now_s() - t0;
	return ret;
}
