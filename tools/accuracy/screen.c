/* SPDX-License-Identifier: MIT */
/* Where a modal image that drops modes is likely worst (screen.h). */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy/col_resp.h"
#include "accuracy/measure.h"
#include "accuracy/screen.h"
#include "accuracy/split.h"

#define SCREEN_MIN_TICKS 300 /* the runs' length, unless the head needs longer */

/* Every mode's response over n ticks, h (nm x n, row-major), and the
 * image's, g: h less what it misses of a dropped mode (split.h); x, e:
 * n of scratch each. */
static void responses(const struct irdm_modes *m, const struct irdm_mode *zoh, const bool *dropped,
		      unsigned H, size_t n, double *h, double *g, double *x, double *e)
{
	for (size_t d = 0; d < m->n_modes; d++) {
		double *hd = &h[d * n], *gd = &g[d * n];

		irdm_zoh_response(&zoh[d], n, hd);
		memcpy(gd, hd, n * sizeof(double));
		if (!dropped[d] || !(m->omega2[d] > 0))
			continue;
		irdm_split_miss(&zoh[d], m->omega2[d], H, n, x, e);
		for (size_t s = 0; s < n; s++)
			gd[s] -= e[s];
	}
}

/* The prediction at column c of a batch from its responses rt and gt
 * (col_resp.h): both runs, the larger; 0 at a column the grab cannot
 * hold (R[0] singular: a fixed DoF).  R, F: n x 9 and n x 3 of scratch,
 * twice. */
static double column_error(const double *rt, const double *gt, size_t c, size_t n, double *R,
			   double *Rh, double *F, double *Fh)
{
	double worst = 0;

	irdm_col_resp_column(rt, c, n, R);
	irdm_col_resp_column(gt, c, n, Rh);
	for (int run = 0; run < 2; run++) {
		if (!irdm_split_forces(R, n, run, F))
			return 0;
		if (!irdm_split_forces(Rh, n, run, Fh))
			return INFINITY;
		worst = fmax(worst, irdm_measure_rel_rms(Fh, F, 3 * n));
	}
	return worst;
}

/* Insert column c of estimate v into the k largest so far (n of them). */
static size_t keep_largest(uint32_t *cols, double *vals, size_t n, size_t k, uint32_t c, double v)
{
	size_t i;

	if (n == k && !(v > vals[k - 1]))
		return n;
	i = n < k ? n++ : k - 1;
	for (; i > 0 && !(vals[i - 1] >= v); i--) {
		vals[i] = vals[i - 1];
		cols[i] = cols[i - 1];
	}
	vals[i] = v;
	cols[i] = c;
	return n;
}

size_t irdm_screen_ticks(unsigned H, size_t N)
{
	size_t n = 4 * (size_t)H > SCREEN_MIN_TICKS ? 4 * (size_t)H : SCREEN_MIN_TICKS;

	return n < N ? n : N;
}

size_t irdm_screen_columns(const struct irdm_modes *m, const struct irdm_mode *zoh,
			   const bool *dropped, unsigned H, const int64_t *col_dofs, size_t n_cols,
			   size_t N, size_t k, uint32_t *cols, double *est)
{
	size_t n = irdm_screen_ticks(H, N), found = 0, n_dropped = 0;
	struct irdm_col_resp cr;
	double *rt = NULL, *gt = NULL, *R, *Rh, *F, *Fh, *x, *e, *vals;

	for (size_t d = 0; d < m->n_modes; d++)
		n_dropped += dropped[d] && m->omega2[d] > 0;
	if (!n_dropped || !k || !n || irdm_col_resp_init(&cr, m, n, 2))
		return 0;
	rt = malloc(cr.batch * 9 * n * sizeof(double));
	gt = malloc(cr.batch * 9 * n * sizeof(double));
	R = malloc(n * 9 * sizeof(double));
	Rh = malloc(n * 9 * sizeof(double));
	F = malloc(n * 3 * sizeof(double));
	Fh = malloc(n * 3 * sizeof(double));
	x = malloc(n * sizeof(double));
	e = malloc(n * sizeof(double));
	vals = malloc(k * sizeof(double));
	if (!rt || !gt || !R || !Rh || !F || !Fh || !x || !e || !vals)
		goto out_free;
	responses(m, zoh, dropped, H, n, cr.x[0], cr.x[1], x, e);
	if (irdm_col_resp_ready(&cr))
		goto out_free;
	for (size_t c0 = 0; c0 < n_cols; c0 += cr.batch) {
		size_t nb = n_cols - c0 < cr.batch ? n_cols - c0 : cr.batch;

		irdm_col_resp_run(&cr, col_dofs, c0, nb, (double *const[]){ rt, gt });
		for (size_t c = 0; c < nb; c++)
			found = keep_largest(cols, vals, found, k, (uint32_t)(c0 + c),
					     column_error(rt, gt, c, n, R, Rh, F, Fh));
	}
	for (size_t i = 0; est && i < found; i++)
		est[i] = vals[i];
out_free:
	irdm_col_resp_free(&cr);
	free(rt);
	free(gt);
	free(R);
	free(Rh);
	free(F);
	free(Fh);
	free(x);
	free(e);
	free(vals);
	return found;
}
