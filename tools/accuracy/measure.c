/* SPDX-License-Identifier: MIT */
/* An image's force error against the exact model, on a few columns. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/image_response.h"
#include "irdm/error.h"
#include "irdm/posix/image_map.h"
#include "accuracy/measure.h"
#include "accuracy/reference.h"
#include "accuracy/run.h"
#include "util/clock.h"

const double irdm_measure_push_m[3] = { 0.3e-3, 0.2e-3, -0.9327379e-3 };

size_t irdm_measure_ticks(double dt_s)
{
	size_t n = (size_t)llround(1.0 / dt_s);

	return n < 300 ? 300 : (n > 3000 ? 3000 : n);
}

static double dist2(const double *a, const double *b)
{
	double d = 0;

	for (int k = 0; k < 3; k++)
		d += (a[k] - b[k]) * (a[k] - b[k]);
	return d;
}

static bool have(const uint32_t *cols, size_t n, uint32_t c)
{
	for (size_t i = 0; i < n; i++)
		if (cols[i] == c)
			return true;
	return false;
}

size_t irdm_measure_spread(const double *pos, size_t n_pos, size_t k, uint32_t *cols)
{
	size_t n = 0;

	if (!n_pos || !k)
		return 0;
	cols[n++] = 0;
	while (n < k && n < n_pos) {
		double best = -1;
		uint32_t bc = 0;

		for (uint32_t c = 0; c < n_pos; c++) {
			double dmin = INFINITY;
			for (size_t i = 0; i < n; i++)
				dmin = fmin(dmin, dist2(&pos[3 * (size_t)c], &pos[3 * (size_t)cols[i]]));
			if (dmin > best) {
				best = dmin;
				bc = c;
			}
		}
		if (have(cols, n, bc))
			break;
		cols[n++] = bc;
	}
	return n;
}

/* The spread of the columns, the screened ones, then the largest radii. */
static size_t pick_columns(const struct irdm_image *img, const uint32_t *screened,
			   size_t n_screened, uint32_t *cols)
{
	uint32_t nc = img->meta->n_cols;
	double *pos = nc ? malloc(3 * (size_t)nc * sizeof(double)) : NULL;
	size_t n;

	if (!pos)
		return 0;
	for (uint32_t c = 0; c < nc; c++)
		for (int a = 0; a < 3; a++)
			pos[3 * (size_t)c + (size_t)a] = img->nodes[img->columns[c]].pos_m[a];
	n = irdm_measure_spread(pos, nc, IRDM_MEASURE_SPREAD, cols);
	free(pos);
	for (size_t i = 0; i < n_screened && i < IRDM_MEASURE_SCREENED; i++)
		if (screened[i] < nc && !have(cols, n, screened[i]))
			cols[n++] = screened[i];
	for (int k = 0; k < IRDM_MEASURE_WORST && n < nc; k++) {
		float best = -1;
		uint32_t bc = UINT32_MAX;

		for (uint32_t c = 0; c < nc; c++)
			if (!have(cols, n, c) && img->stability[c].spectral_radius > best) {
				best = img->stability[c].spectral_radius;
				bc = c;
			}
		if (bc == UINT32_MAX)
			break;
		cols[n++] = bc;
	}
	return n;
}

/* The image row of a mesh node, or -1. */
static int64_t row_of_mesh_node(const struct irdm_image *img, uint32_t mesh_node)
{
	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		if (img->nodes[r].mesh_node == mesh_node)
			return r;
	return -1;
}

void irdm_measure_cmds(bool release, uint32_t row, size_t N, struct irdm_report_cmd *cmds)
{
	for (size_t t = 0; t < N; t++) {
		struct irdm_report_cmd *c = &cmds[t];
		bool held = irdm_measure_held(release, t, N);

		memset(c, 0, sizeof(*c));
		c->on_node = true;
		c->row = row;
		c->active = irdm_measure_active(release, t, N);
		for (int a = 0; a < 3; a++)
			c->target_m[a] = held ? irdm_measure_push_m[a] : 0;
	}
}

double irdm_measure_rel_rms(const double *F, const double *Fref, size_t n)
{
	double num = 0, den = 0;

	for (size_t i = 0; i < n; i++) {
		num += (F[i] - Fref[i]) * (F[i] - Fref[i]);
		den += Fref[i] * Fref[i];
	}
	return den > 0 ? sqrt(num / den) : (num > 0 ? INFINITY : 0);
}

/* The engines the runs share: the image's, and a floating reference's. */
struct runners {
	struct irdm_report_runner *img, *ref;
	double *F; /* N x 3 */
};

/* The exact model's forces for one run. */
static int reference(const struct irdm_image *ref, struct runners *rn,
		     const struct irdm_report_cmd *cmds, size_t N, double **F, char *err,
		     size_t errlen)
{
	struct irdm_report_conv c = { .img = ref, .cmds = cmds, .m = 1, .N = N, .n_resp = N };
	struct irdm_report_conv_out co;
	bool faulted;
	int ret;

	if (!ref->rigid) {
		ret = irdm_report_convolve(&c, &co, err, errlen);
		if (ret)
			return ret;
		*F = co.F;
		free(co.disp);
		return IRDM_OK;
	}
	*F = malloc(N * 3 * sizeof(double));
	if (!*F) {
		snprintf(err, errlen, "error measurement: out of memory");
		return IRDM_ENOMEM;
	}
	ret = irdm_report_runner_run(rn->ref, cmds, N, *F, &faulted, err, errlen);
	if (!ret && faulted) {
		snprintf(err, errlen, "error measurement: the exact model's engine run faulted");
		ret = IRDM_ECONTACT;
	}
	if (ret) {
		free(*F);
		*F = NULL;
	}
	return ret;
}

/* One column, both runs: the larger error into res. */
static int measure_column(const struct irdm_image *img, const struct irdm_image *ref,
			  struct runners *rn, uint32_t col, size_t N, struct irdm_report_cmd *cmds,
			  struct irdm_measure *res, char *err, size_t errlen)
{
	uint32_t mesh_node = img->nodes[img->columns[col]].mesh_node;
	int64_t ref_row = row_of_mesh_node(ref, mesh_node);

	if (ref_row < 0) {
		snprintf(err, errlen, "error measurement: mesh node %u is not in the exact model", mesh_node);
		return IRDM_EINVAL;
	}
	for (int release = 0; release < 2; release++) {
		double *Fref = NULL, e;
		bool faulted;
		int ret;

		irdm_measure_cmds(release, (uint32_t)ref_row, N, cmds);
		ret = reference(ref, rn, cmds, N, &Fref, err, errlen);
		if (ret)
			return ret;
		irdm_measure_cmds(release, img->columns[col], N, cmds);
		ret = irdm_report_runner_run(rn->img, cmds, N, rn->F, &faulted, err, errlen);
		if (ret) {
			free(Fref);
			return ret;
		}
		e = faulted ? INFINITY : irdm_measure_rel_rms(rn->F, Fref, 3 * N);
		if (!(e <= res->error)) {
			res->error = e;
			res->worst_node = mesh_node;
			res->worst_run = release ? "release" : "step";
		}
		free(Fref);
	}
	return IRDM_OK;
}

static int build_reference(const struct irdm_scene *sc, const struct irdm_measure *res,
			   const char *ref_path, irdm_measure_ref_fn build_ref, void *ref_ctx,
			   char *err, size_t errlen)
{
	struct irdm_scene *ref = malloc(sizeof(*ref));
	char nodes[16 * IRDM_MEASURE_MAX_COLS + 8];
	size_t len = (size_t)snprintf(nodes, sizeof(nodes), "nodes:");
	int ret;

	if (!ref) {
		snprintf(err, errlen, "error measurement: out of memory");
		return IRDM_ENOMEM;
	}
	*ref = *sc;
	for (size_t i = 0; i < res->n_cols; i++)
		len += (size_t)snprintf(nodes + len, sizeof(nodes) - len, "%s%u", i ? "," : "",
					res->nodes[i]);
	ref->method = IRDM_METHOD_MODAL;
	ref->fir_tail = 0;
	ref->exact_head = 0;
	ref->static_corr_cluster = 0;
	ref->uncertified = true;
	ref->max_error = 0; /* not measured itself */
	ref->contacts = 1;
	ref->eigensolver = IRDM_EIG_DENSE;
	ret = irdm_scene_set(ref, "representation", "modal:all", "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(ref, "static_correction", "no", "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(ref, "precision", "f64", "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(ref, "touch", nodes, "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(ref, "display", "touch", "error measurement", err, errlen);
	if (!ret)
		ret = build_ref(ref_ctx, ref, ref_path, err, errlen);
	free(ref);
	return ret;
}

int irdm_measure_error(const struct irdm_scene *sc, const struct irdm_image *img,
		       const char *ref_path, irdm_measure_ref_fn build_ref, void *ref_ctx,
		       irdm_progress_fn fn, void *ctx, struct irdm_measure *res,
		       char *err, size_t errlen)
{
	return irdm_measure_error_at(sc, img, NULL, 0, ref_path, build_ref, ref_ctx, fn, ctx, res,
				     err, errlen);
}

int irdm_measure_error_at(const struct irdm_scene *sc, const struct irdm_image *img,
			  const uint32_t *screened, size_t n_screened, const char *ref_path,
			  irdm_measure_ref_fn build_ref, void *ref_ctx, irdm_progress_fn fn,
			  void *ctx, struct irdm_measure *res, char *err, size_t errlen)
{
	uint32_t cols[IRDM_MEASURE_MAX_COLS];
	struct irdm_image ref;
	struct irdm_report_cmd *cmds = NULL;
	struct runners rn = { NULL, NULL, NULL };
	double t0 = irdm_now_s();
	int ret;

	memset(res, 0, sizeof(*res));
	res->error = -1;
	res->n_cols = pick_columns(img, screened, n_screened, cols);
	if (!res->n_cols) {
		snprintf(err, errlen, "error measurement: no column to measure (none touchable, or out of memory)");
		return IRDM_ENOMEM;
	}
	for (size_t i = 0; i < res->n_cols; i++)
		res->nodes[i] = img->nodes[img->columns[cols[i]]].mesh_node;
	res->ticks = irdm_measure_ticks(img->meta->dt_s);
	if (fn)
		fn(ctx, "error measurement", 0.0);
	ret = build_reference(sc, res, ref_path, build_ref, ref_ctx, err, errlen);
	if (ret)
		goto out_unlink;
	ret = irdm_image_map(ref_path, 0, &ref, err, errlen);
	if (ret)
		goto out_unlink;
	ret = IRDM_EINVAL;
	if (ref.meta->mesh_hash != img->meta->mesh_hash) {
		snprintf(err, errlen, "error measurement: the exact model's mesh differs from the image's (hash %016llx, %016llx)",
			 (unsigned long long)ref.meta->mesh_hash,
			 (unsigned long long)img->meta->mesh_hash);
		goto out_unmap;
	}
	ret = IRDM_ENOMEM;
	cmds = malloc(res->ticks * sizeof(*cmds));
	rn.F = malloc(res->ticks * 3 * sizeof(double));
	if (!cmds || !rn.F) {
		snprintf(err, errlen, "error measurement: out of memory");
		goto out_free;
	}
	ret = irdm_report_runner_open(&rn.img, img, 1, err, errlen);
	if (!ret && ref.rigid)
		ret = irdm_report_runner_open(&rn.ref, &ref, 1, err, errlen);
	for (size_t i = 0; i < res->n_cols && !ret; i++) {
		ret = measure_column(img, &ref, &rn, cols[i], res->ticks, cmds, res, err, errlen);
		if (fn)
			fn(ctx, "error measurement", (double)(i + 1) / (double)res->n_cols);
	}
	irdm_report_runner_close(rn.img);
	irdm_report_runner_close(rn.ref);
out_free:
	free(cmds);
	free(rn.F);
out_unmap:
	irdm_image_unmap(&ref);
out_unlink:
	unlink(ref_path);
	res->seconds = irdm_now_s() - t0;
	return ret;
}
