/* SPDX-License-Identifier: MIT */
/* The reference against time-domain responses of the step node. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image_response.h"
#include "irdm/error.h"
#include "report/report_check.h"
#include "report/report_image.h"
#include "accuracy/reference.h"

static void check_progress(void *ctx, const char *stage, double fraction)
{
	const struct irdm_report_opts *o = ctx;
	char s[160];

	if (!o->progress || fraction < 0)
		return;
	snprintf(s, sizeof(s), "reference check (time domain): %s", stage);
	o->progress(o->ctx, s, fraction);
}

/* max |a - b| / max |b| over n values. */
static double rel_max(const double *a, const double *b, size_t n)
{
	double d = 0, m = 0;

	for (size_t i = 0; i < n; i++) {
		d = fmax(d, fabs(a[i] - b[i]));
		m = fmax(m, fabs(b[i]));
	}
	return d / m;
}

static int compare(const struct irdm_image *ref, const struct irdm_image *td,
		   const struct irdm_report_scenario *step, double dt_s, size_t N,
		   const double *Fref, struct irdm_report_check *ck, char *err, size_t errlen)
{
	struct irdm_report_conv c = { .img = td, .m = 1, .N = N, .n_resp = N };
	struct irdm_report_cmd *cmds = malloc(N * sizeof(*cmds));
	double *Rr = malloc(N * 9 * sizeof(double)), *Rt = malloc(N * 9 * sizeof(double));
	struct irdm_report_conv_out out;
	uint32_t row = td->columns[0];
	int64_t rr = irdm_image_node_of(ref, td->nodes[row].mesh_node);
	int ret = IRDM_ENOMEM;

	if (!cmds || !Rr || !Rt)
		goto out;
	ret = IRDM_EINVAL;
	if (rr < 0 || irdm_image_col_of(ref, (uint32_t)rr) < 0) {
		snprintf(err, errlen, "reference check: the step node is not a column of the reference");
		goto out;
	}
	ret = irdm_image_response(ref, (uint32_t)irdm_image_col_of(ref, (uint32_t)rr), (uint32_t)rr, N, Rr);
	if (!ret)
		ret = irdm_image_response(td, 0, row, N, Rt);
	if (ret)
		goto out;
	ck->resp_rel_diff = rel_max(Rt, Rr, 9 * N);
	for (size_t t = 0; t < N; t++)
		irdm_report_scenario_cmds(step, td, dt_s, t, &cmds[t]);
	c.cmds = cmds;
	ret = irdm_report_convolve(&c, &out, err, errlen);
	if (ret)
		goto out;
	{
		double d = 0, r = 0;
		for (size_t i = 0; i < 3 * N; i++) {
			d += (out.F[i] - Fref[i]) * (out.F[i] - Fref[i]);
			r += Fref[i] * Fref[i];
		}
		ck->force_rel_diff = sqrt(d / r);
	}
	irdm_report_conv_free(&out);
out:
	free(cmds);
	free(Rr);
	free(Rt);
	return ret;
}

int irdm_report_check_reference(const struct irdm_report_opts *o, const struct irdm_image *ref,
				double dt_s, const struct irdm_report_scenario *step,
				const double *Fref, struct irdm_report_result *res,
				char *err, size_t errlen)
{
	/* the first check_s: Newmark's cost grows with the samples */
	size_t N = (size_t)llround(o->cfg->check_s / dt_s);
	struct irdm_report_cmd cmd;
	struct irdm_report_check ck = { .dt_s = dt_s, .substeps = IRDM_REPORT_CHECK_SUBSTEPS };
	struct irdm_report_image td;
	struct irdm_report_check *grown;
	char keys[256], name[96];
	const char *kl[] = { o->cfg->model->keys, keys, NULL };
	int ret;

	/* the step node of the reference, as the only column of the check */
	irdm_report_scenario_cmds(step, ref, dt_s, 0, &cmd);
	snprintf(keys, sizeof(keys),
		 "dt=%.17g method=time-domain representation=fir:%zu fir_tail=none substeps=%d precision=f64 touch=nodes:%u display=touch",
		 dt_s, N, IRDM_REPORT_CHECK_SUBSTEPS, ref->nodes[cmd.row].mesh_node);
	snprintf(name, sizeof(name), "%s-check-%gms", o->cfg->name, dt_s * 1e3);
	ret = irdm_report_image_build(&td, o->tmp_dir, name, kl, check_progress, (void *)o, err, errlen);
	if (ret)
		return ret;
	ret = compare(ref, &td.img, step, dt_s, N, Fref, &ck, err, errlen);
	irdm_report_image_drop(&td, o->keep_images);
	if (ret)
		return ret;
	grown = realloc(res->checks, (res->n_checks + 1) * sizeof(*grown));
	if (!grown)
		return IRDM_ENOMEM;
	res->checks = grown;
	res->checks[res->n_checks++] = ck;
	return IRDM_OK;
}
