/* SPDX-License-Identifier: MIT */
/* Scene -> model -> responses -> stability -> image. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "dist/dist.h"
#include "fem/inertia.h"
#include "image/bvh_build.h"
#include "image/elem_store.h"
#include "image/image_writer.h"
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "modal/decay.h"
#include "modal/exact_head.h"
#include "modal/head_split.h"
#include "modal/krylov_head.h"
#include "accuracy/pairs.h"
#include "accuracy/scan.h"
#include "accuracy/screen.h"
#include "accuracy/split.h"
#include "modal/lapack.h"
#include "modal/response.h"
#include "modal/stability.h"
#include "modal/static_lowrank.h"
#include "modal/static_clusters.h"
#include "modal/static_sparse.h"
#include "precompute/candidates.h"
#include "precompute/col_scale.h"
#include "precompute/fir_tail.h"
#include "precompute/head_pairs.h"
#include "precompute/lowest.h"
#include "precompute/precompute.h"
#include "precompute/td_part.h"
#include "accuracy/measure.h"
#include "timedomain/timedomain.h"
#include "util/clock.h"
#include "util/fnv1a.h"

struct build {
	const struct irdm_scene *sc;
	const struct irdm_precompute_opts *o;
	struct irdm_model m;
	struct irdm_mode *zoh;              /* modal */
	size_t n_modes;                     /* modes in the image (modal) */
	double *fir;                        /* FIR, double, section layout */
	double *shapes;                     /* modal: [row][3][mode] */
	double *corr;                       /* FIR: static correction [c][r][3][3] or NULL */
	struct irdm_corr_sparse sparse;     /* modal: the kept blocks (start NULL if none) */
	double *head;                       /* modal exact_head: [k][s][3][3] (exact_head.h) */
	struct irdm_corr_lowrank far;       /* modal: their far field (rank 0 if none) */
	struct irdm_corr_clusters clusters; /* modal: every block, clustered (0 clusters if not) */
	void *stored[6];                    /* converted to the scene's precision */
	size_t stored_bytes[6];
	float *col_scale;     /* f16: COLUMN_SCALE (col_scale.h), else NULL */
	uint32_t *head_index; /* the head by pairs: EXACT_HEAD_INDEX (head_pairs.h), else NULL */
	struct irdm_stability *stab;
	struct irdm_meta meta;
	struct irdm_rigid rigid;
	struct irdm_node *nodes;
	char *prov;
	uint64_t scene_hash;
	size_t n_solved;      /* modes the eigensolve gave (all: the exact model's) */
	bool reference;       /* the error measurement's reference */
	bool kept_not_lowest; /* auto's hybrid keeps modes above a dropped one */
	bool auto_try;        /* building one of auto's candidates */
	size_t head_capped;   /* and its head was over max_head_mib: its blocks (0: not) */
	size_t try_bytes;     /* the measured image's size (0: none written) */
	unsigned cluster;     /* the scene's static_correction_cluster, for auto's tries */
};

/* The provenance text's room: the scene (at most 4096 bytes) and what the
 * build adds to it. */
#define PROV_BYTES 8192

/* Modes the scene needs solved (0: all). */
static size_t modes_needed(const struct irdm_scene *sc)
{
	if (sc->repr_auto && sc->max_error > 0)
		return 0; /* every candidate is measured: the reference needs all */
	if (sc->representation == IRDM_REPR_MODAL)
		/* the head from every mode, or from Chebyshev series (krylov_head.h) */
		return sc->exact_head && sc->eigensolver != IRDM_EIG_LANCZOS ? 0 : sc->modes;
	if (sc->method == IRDM_METHOD_TIME_DOMAIN)
		return 1; /* only the first mode, for the default damping */
	return sc->modes; /* FIR synthesised from modes */
}

/* FIR samples the image holds: T, plus a windowed tail (fir_tail.h). */
static size_t fir_taps(const struct build *b)
{
	return (size_t)b->sc->fir_length + b->sc->fir_tail;
}

static bool truncated(const struct build *b)
{
	return b->m.modes.n_modes < b->m.modes.n_elastic_total;
}

/* Is the head stored by pairs (head_pairs.h)?  Not in f16, whose column
 * scales (col_scale.h) keep the two blocks of a pair apart. */
static bool head_by_pairs(const struct build *b)
{
	return b->sc->precision != IRDM_ELEM_F16;
}

/* The head's stored bytes: n_blocks 3x3 blocks over 2H samples, by pairs
 * the diagonal blocks and half the rest. */
static size_t head_bytes(const struct build *b, size_t n_blocks, size_t H)
{
	size_t runs = head_by_pairs(b) ? (n_blocks + b->m.n_cols) / 2 : n_blocks;

	return runs * 2 * H * 9 * irdm_elem_size(b->sc->precision);
}

/* The head without every mode: a Chebyshev series from each touchable
 * DoF.  A measurement's reference reads its head over the whole run
 * (irdm_measure_ticks() samples): only those are computed, the run never
 * reads the rest. */
static int krylov_head(struct build *b, const double *target, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	struct irdm_krylov_head_stats st;
	char line[240];
	struct irdm_krylov_head_opts ko = { IRDM_KRYLOV_HEAD_TOL, IRDM_KRYLOV_HEAD_MAX_TERMS,
					    b->sc->threads, 0 };
	int ret;

	if (b->reference)
		ko.samples = irdm_measure_ticks(b->sc->dt_s);
	ret = irdm_krylov_head(&m->fem, &m->modes, &m->damping, b->sc->dt_s, m->col_dofs,
			       &b->sparse, target, b->sc->exact_head, &ko, b->o->progress, b->o->ctx,
			       b->head, &st, err, errlen);
	if (ret || !b->o->progress)
		return ret;
	snprintf(line, sizeof(line), "krylov head: %zu Chebyshev runs of %zu terms over %zu samples, the spectrum bounded by w = %.4g rad/s; the terms cut leave %.2g of the largest dropped response at most",
		 st.runs, st.terms, st.samples, sqrt(st.lam_up), st.tail);
	b->o->progress(b->o->ctx, line, -1.0);
	return IRDM_OK;
}

/*
 * The hybrid representation (scene key exact_head): every mode was solved
 * (zoh_all: each discretised; NULL: the head from Chebyshev series instead);
 * the image keeps the scene's K, and the dropped ones' exact response over
 * the head's samples at the static correction's kept blocks.  Called once
 * the static correction of the K kept modes is known.
 */
static int exact_head(struct build *b, const struct irdm_mode *zoh_all, size_t n_all, char *err,
		      size_t errlen)
{
	struct irdm_model *m = &b->m;
	struct irdm_corr_sparse *sp = &b->sparse;
	struct irdm_modes all = m->modes;
	size_t H = b->sc->exact_head;
	double *target = malloc(sp->n_blocks * 9 * sizeof(double));
	int ret = IRDM_ENOMEM;

	all.n_modes = n_all;
	/* on a large touchable surface the kept blocks times the head's
	 * samples grow past what an image should hold (max_head_mib), and
	 * building them takes as long */
	if (b->auto_try && (double)head_bytes(b, sp->n_blocks, H) > b->sc->max_head_mib * (1 << 20)) {
		b->head_capped = sp->n_blocks;
		free(target);
		snprintf(err, errlen, "precompute: auto: the head would take %.3g MiB (%zu blocks x %zu samples), more than max_head_mib = %g",
			 (double)head_bytes(b, sp->n_blocks, H) / (1 << 20), sp->n_blocks, 2 * H,
			 b->sc->max_head_mib);
		return IRDM_ENUMERIC;
	}
	b->head = malloc(sp->n_blocks * 2 * H * 9 * sizeof(double));
	if (!b->head || !target) {
		snprintf(err, errlen, "precompute: the exact head (%zu blocks x %zu samples) does not fit in memory",
			 sp->n_blocks, 2 * H);
		goto out_free;
	}
	/* what each kept block's head sums to: its whole correction, the
	 * far field's value there included (the blocks are stored without) */
	for (size_t c = 0; c < sp->n_cols; c++)
		for (uint32_t k = sp->start[c]; k < sp->start[c + 1]; k++) {
			double far[9] = { 0 };
			if (b->far.rank)
				irdm_corr_lowrank_block(&b->far, c, sp->rows[k], far);
			for (int e = 0; e < 9; e++)
				target[9 * (size_t)k + (size_t)e] = sp->blocks[9 * (size_t)k + (size_t)e] + far[e];
		}
	if (zoh_all) {
		ret = irdm_exact_head(&all, zoh_all, m->modes.n_modes, m->col_dofs, sp, target, H,
				      b->o->progress, b->o->ctx, b->head);
		if (ret)
			snprintf(err, errlen, "precompute: out of memory for the exact head");
	} else {
		ret = krylov_head(b, target, err, errlen);
	}
out_free:
	free(target);
	return ret;
}

/* exact_head: discretise every mode, then keep the scene's K. */
static int split_modes(struct build *b, struct irdm_mode **zoh_all, size_t *n_all, char *err,
		       size_t errlen)
{
	struct irdm_modes *md = &b->m.modes;

	*n_all = md->n_modes;
	if (b->sc->modes >= md->n_modes) {
		snprintf(err, errlen, "scene: exact_head needs dropped modes, but modal:%u keeps all %zu",
			 b->sc->modes, md->n_modes);
		return IRDM_EINVAL;
	}
	*zoh_all = malloc(md->n_modes * sizeof(**zoh_all));
	if (!*zoh_all) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	irdm_modes_discretise(md, &b->m.damping, b->sc->dt_s, *zoh_all);
	md->n_modes = b->sc->modes; /* phi is column-major: the first K columns */
	return IRDM_OK;
}

/* The static correction clustered: the columns' rest positions set the
 * clusters. */
static int clustered(struct build *b, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	double *pos = malloc(3 * (m->n_cols ? m->n_cols : 1) * sizeof(double));
	int ret;

	if (!pos) {
		snprintf(err, errlen, "precompute: out of memory for the column positions");
		return IRDM_ENOMEM;
	}
	for (size_t c = 0; c < m->n_cols; c++)
		memcpy(&pos[3 * c], &m->mesh.pos_m[3 * (size_t)m->rows[m->cols[c]]],
		       3 * sizeof(double));
	ret = irdm_static_correction_clusters(&m->fem, &m->modes, b->sc->floating, m->col_dofs, pos,
					      m->n_cols, b->sc->static_corr_cluster,
					      b->sc->static_corr_tol, b->o->progress, b->o->ctx,
					      &b->sparse, &b->clusters, err, errlen);
	free(pos);
	return ret;
}
static int modal_data(struct build *b, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	struct irdm_mode *zoh_all = NULL;
	size_t n_all = 0, K, n = m->modes.n;
	bool hybrid = b->sc->exact_head && b->sc->representation == IRDM_REPR_MODAL;
	int ret;

	if (hybrid && b->sc->modes >= b->m.modes.n_elastic_total) {
		snprintf(err, errlen, "scene: exact_head needs dropped modes, but modal:%u keeps all %zu",
			 b->sc->modes, b->m.modes.n_elastic_total);
		return IRDM_EINVAL;
	}
	if (hybrid && b->m.modes.n_modes > b->sc->modes) {
		ret = split_modes(b, &zoh_all, &n_all, err, errlen);
		if (ret)
			return ret;
	}
	K = m->modes.n_modes;
	/* the shapes at the rows: whole vectors of the modes kept only */
	ret = irdm_modes_complete(&m->modes, 0, K, m->row_dofs, 3 * m->n_rows, err, errlen);
	if (ret) {
		free(zoh_all);
		return ret;
	}

	b->n_modes = K;
	b->zoh = malloc(K * sizeof(*b->zoh));
	b->shapes = malloc(m->n_rows * 3 * K * sizeof(double));
	if (!b->zoh || !b->shapes)
		goto out_nomem;
	irdm_modes_discretise(&m->modes, &m->damping, b->sc->dt_s, b->zoh);
	for (size_t r = 0; r < 3 * m->n_rows; r++)
		for (size_t k = 0; k < K; k++) {
			int64_t d = m->row_dofs[r];
			b->shapes[r * K + k] = d < 0 ? 0.0 : m->modes.phi[k * n + (size_t)d];
		}
	if (!b->sc->static_correction || !truncated(b)) {
		free(zoh_all);
		return IRDM_OK;
	}
	if (b->sc->representation == IRDM_REPR_MODAL && b->sc->static_corr_cluster) {
		/* every block, block low-rank over clusters (static_clusters.h) */
		ret = clustered(b, err, errlen);
		free(zoh_all);
		return ret;
	}
	if (b->sc->representation == IRDM_REPR_MODAL) {
		/* between columns only, the blocks that matter (static_sparse.h),
		 * and what the dropped ones share far apart (static_lowrank.h) */
		ret = irdm_static_correction_sparse(&m->fem, &m->modes, b->sc->floating,
						    m->col_dofs, m->n_cols, b->sc->static_corr_tol,
						    b->o->progress, b->o->ctx, &b->sparse,
						    err, errlen);
		/* not with a head: a dropped block's far field is a constant at
		 * R[0] between two columns whose own blocks move with their
		 * heads, and two contacts grabbed at once through it can
		 * diverge (accuracy/pairs.h) */
		if (!ret && b->sc->static_corr_rank && !hybrid &&
		    b->sparse.n_blocks < m->n_cols * m->n_cols)
			ret = irdm_static_correction_lowrank(&m->fem, &m->modes, b->sc->floating,
							     m->col_dofs, &b->sparse,
							     b->sc->static_corr_rank < 3 * m->n_cols ?
								     b->sc->static_corr_rank :
								     3 * m->n_cols,
							     b->o->progress, b->o->ctx, &b->far, err,
							     errlen);
		/* the hybrid's head, after the far field: it sums to the whole
		 * correction of each kept block */
		if (!ret && hybrid)
			ret = exact_head(b, zoh_all, n_all, err, errlen);
		free(zoh_all);
		return ret;
	}
	/* an FIR adds it to R[0] of every row: as dense as the FIR itself */
	b->corr = malloc(m->n_cols * m->n_rows * 9 * sizeof(double));
	if (!b->corr)
		goto out_nomem;
	if (b->o->progress)
		b->o->progress(b->o->ctx, "static correction", 0.0);
	ret = irdm_static_correction(&m->fem, &m->modes, b->sc->floating, m->col_dofs,
				     m->n_cols, m->row_dofs, m->n_rows, b->corr, err, errlen);
	if (!ret && b->o->progress)
		b->o->progress(b->o->ctx, "static correction", 1.0);
	return ret;
out_nomem:
	free(zoh_all);
	snprintf(err, errlen, "precompute: out of memory for the modal data");
	return IRDM_ENOMEM;
}

static int fir_from_modes(struct build *b, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	size_t T = fir_taps(b);
	int ret;

	ret = modal_data(b, err, errlen);
	if (ret)
		return ret;
	b->fir = malloc(m->n_cols * m->n_rows * T * 9 * sizeof(double));
	if (!b->fir) {
		snprintf(err, errlen, "precompute: FIR of %zu x %zu nodes x %zu samples does not fit in memory (%.1f GiB); use a modal image or a smaller touch/display region",
			 m->n_cols, m->n_rows, T, (double)m->n_cols * m->n_rows * T * 72 / (1 << 30));
		return IRDM_ENOMEM;
	}
	ret = irdm_fir_from_modes(&m->modes, b->zoh, m->col_dofs, m->n_cols, m->row_dofs,
				  m->n_rows, T, b->corr, b->fir, b->o->progress, b->o->ctx);
	if (ret)
		snprintf(err, errlen, "precompute: out of memory synthesising the FIR from modes");
	return ret;
}

/* The time-domain inputs are the free DoFs of the columns, in column order;
 * global[] gets their global DoF, slot[] their index in col_dofs. */
static size_t list_inputs(const struct irdm_model *m, int64_t *global, size_t *slot)
{
	size_t n = 0;

	for (size_t c = 0; c < 3 * m->n_cols; c++)
		if (m->col_dofs[c] >= 0) {
			if (global)
				global[n] = m->fem.map.global_of[m->col_dofs[c]];
			if (slot)
				slot[n] = c;
			n++;
		}
	return n;
}

struct td_progress {
	irdm_progress_fn fn;
	void *ctx;
};

static void td_progress(void *ctx, size_t done, size_t total)
{
	struct td_progress *p = ctx;

	if (p->fn)
		p->fn(p->ctx, "time-domain responses", (double)done / (double)total);
}

static int td_run(struct build *b, size_t begin, size_t end, double *R, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	size_t n_in = list_inputs(m, NULL, NULL);
	int64_t *global = malloc(n_in * sizeof(int64_t));
	struct td_progress tp = { b->o->progress, b->o->ctx };
	struct irdm_td_opts o = {
		.dt_s = b->sc->dt_s,
		.n_samples = fir_taps(b),
		.substeps = b->sc->substeps,
		.damping = m->damping,
		.floating = b->sc->floating,
		/* over MPI, the cores of a machine shared by its ranks */
		.threads = b->sc->threads ? b->sc->threads : irdm_dist_threads(),
		.progress = td_progress,
		.progress_ctx = &tp,
		/* rigid motion removed by a mass-weighted best fit (Kabsch):
		 * docs/architecture.md, "Frames and signs" */
		.rigid = IRDM_TD_RIGID_KABSCH,
	};
	int ret;

	if (!global) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	list_inputs(m, global, NULL);
	ret = irdm_td_responses(&m->mesh, &m->fem, &o, global + begin, end - begin, m->rows,
				m->n_rows, R, err, errlen);
	free(global);
	return ret;
}

/* Scatter time-domain input columns into the FIR layout.
 * Return: IRDM_OK; IRDM_ENOMEM if the input list does not fit (the FIR is
 * then incomplete: the caller must not write it). */
static int td_scatter(struct build *b, const double *R, size_t begin, size_t end,
		      char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	size_t T = fir_taps(b), n_out = 3 * m->n_rows;
	size_t *slot = malloc(3 * m->n_cols * sizeof(size_t));

	if (!slot) {
		snprintf(err, errlen, "precompute: out of memory scattering time-domain responses");
		return IRDM_ENOMEM;
	}
	list_inputs(m, NULL, slot);
	for (size_t i = begin; i < end; i++) {
		size_t c = slot[i] / 3, j = slot[i] % 3;
		for (size_t s = 0; s < T; s++)
			for (size_t r = 0; r < m->n_rows; r++)
				for (size_t a = 0; a < 3; a++)
					b->fir[(((c * m->n_rows + r) * T + s) * 3 + a) * 3 + j] =
						R[((i - begin) * T + s) * n_out + 3 * r + a];
	}
	free(slot);
	return IRDM_OK;
}

/* Time-domain responses of inputs [part_begin, part_end) into a part file. */
static int td_part(struct build *b, size_t n_in, char *err, size_t errlen)
{
	const struct irdm_precompute_opts *o = b->o;
	size_t T = fir_taps(b), n_out = 3 * b->m.n_rows;
	size_t e = o->part_end < n_in ? o->part_end : n_in;
	int ret;

	if (o->part_begin >= e) {
		snprintf(err, errlen, "precompute: part range %zu:%zu is empty (the scene has %zu inputs)",
			 o->part_begin, o->part_end, n_in);
		return IRDM_EINVAL;
	}
	struct irdm_td_part p = { b->scene_hash, n_in, o->part_begin, e, T, n_out, NULL };
	p.data = malloc((e - o->part_begin) * T * n_out * sizeof(double));
	if (!p.data) {
		snprintf(err, errlen, "precompute: out of memory for the part");
		return IRDM_ENOMEM;
	}
	ret = td_run(b, o->part_begin, e, p.data, err, errlen);
	if (!ret)
		ret = irdm_td_part_write(o->part_out, &p, err, errlen);
	free(p.data);
	return ret;
}

/* Merge: every input covered exactly once, by parts of the same scene. */
static int td_merge(struct build *b, size_t n_in, char *err, size_t errlen)
{
	const struct irdm_precompute_opts *o = b->o;
	size_t T = fir_taps(b), n_out = 3 * b->m.n_rows;
	unsigned char *seen = calloc(n_in ? n_in : 1, 1);
	int ret = IRDM_EINVAL;

	if (!seen) {
		snprintf(err, errlen, "merge: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t k = 0; k < o->n_merge; k++) {
		struct irdm_td_part p;
		ret = irdm_td_part_read(o->merge[k], &p, err, errlen);
		if (ret)
			goto out_seen;
		ret = IRDM_EINVAL;
		if (p.scene_hash != b->scene_hash || p.n_inputs != n_in || p.T != T || p.n_out != n_out) {
			snprintf(err, errlen, "%s: part was made from a different scene", o->merge[k]);
			free(p.data);
			goto out_seen;
		}
		for (size_t i = p.begin; i < p.end; i++) {
			if (seen[i]++) {
				snprintf(err, errlen, "%s: input %zu is also in an earlier part", o->merge[k], i);
				free(p.data);
				goto out_seen;
			}
		}
		ret = td_scatter(b, p.data, p.begin, p.end, err, errlen);
		free(p.data);
		if (ret)
			goto out_seen;
	}
	ret = IRDM_EINVAL;
	for (size_t i = 0; i < n_in; i++)
		if (!seen[i]) {
			snprintf(err, errlen, "merge: input %zu of %zu is in no part", i, n_in);
			goto out_seen;
		}
	ret = IRDM_OK;
out_seen:
	free(seen);
	return ret;
}

/*
 * Over MPI ranks: rank r computes inputs [n_in r / P, n_in (r + 1) / P) (the
 * --part logic, driven by the rank) and rank 0 gathers them in memory into
 * the FIR (R: rank 0's FIR is allocated, NULL elsewhere).  Every rank
 * calls it; a failing rank stops them all (irdm_dist_abort).
 */
static int td_distributed(struct build *b, size_t n_in, char *err, size_t errlen)
{
	size_t per_input = b->sc->fir_length * 3 * b->m.n_rows, begin, end;
	int P = irdm_dist_size(), me = irdm_dist_rank();
	size_t *counts = malloc((size_t)P * sizeof(size_t));
	double *mine = NULL, *all = NULL;
	int ret = IRDM_ENOMEM;

	begin = n_in * (size_t)me / (size_t)P;
	end = n_in * (size_t)(me + 1) / (size_t)P;
	if (counts)
		mine = malloc((end > begin ? end - begin : 1) * per_input * sizeof(double));
	if (counts && mine && me == 0)
		all = malloc((n_in ? n_in : 1) * per_input * sizeof(double));
	if (!counts || !mine || (me == 0 && !all)) {
		snprintf(err, errlen, "precompute: out of memory for this rank's time-domain inputs");
		goto out_free;
	}
	for (int q = 0; q < P; q++)
		counts[q] = (n_in * (size_t)(q + 1) / (size_t)P - n_in * (size_t)q / (size_t)P) *
			    per_input;
	ret = end > begin ? td_run(b, begin, end, mine, err, errlen) : IRDM_OK;
	if (!ret)
		ret = irdm_dist_gather(mine, counts, all, err, errlen);
	if (!ret && me == 0)
		ret = td_scatter(b, all, 0, n_in, err, errlen);
out_free:
	free(counts);
	free(mine);
	free(all);
	return ret;
}

static int fir_time_domain(struct build *b, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	size_t T = fir_taps(b), n_out = 3 * m->n_rows, n_in = list_inputs(m, NULL, NULL);
	size_t fir_n = m->n_cols * m->n_rows * T * 9;
	double *R;
	int ret;

	if (b->o->part_out)
		return td_part(b, n_in, err, errlen);
	b->fir = calloc(fir_n, sizeof(double));
	if (!b->fir) {
		snprintf(err, errlen, "precompute: FIR does not fit in memory");
		return IRDM_ENOMEM;
	}
	if (b->o->n_merge)
		return td_merge(b, n_in, err, errlen);
	if (irdm_dist_size() > 1)
		return td_distributed(b, n_in, err, errlen);
	R = malloc(n_in * T * n_out * sizeof(double));
	if (!R) {
		snprintf(err, errlen, "precompute: out of memory for time-domain responses");
		return IRDM_ENOMEM;
	}
	ret = td_run(b, 0, n_in, R, err, errlen);
	if (!ret)
		ret = td_scatter(b, R, 0, n_in, err, errlen);
	free(R);
	return ret;
}

/* Store as the scene's precision; replace the doubles by what was stored
 * so stability is judged on the data the firmware will use. */
static void *store(double *x, size_t n, uint32_t elem, size_t *bytes)
{
	size_t es = irdm_elem_size(elem);
	void *out = malloc(n * es > 0 ? n * es : 1);

	*bytes = n * es;
	if (!out)
		return NULL;
	for (size_t i = 0; i < n; i++)
		x[i] = irdm_elem_put(out, elem, i, x[i]);
	return out;
}

struct stab_job {
	struct build *b;
	size_t begin, end;
};

static void stab_one(struct build *b, size_t c)
{
	struct irdm_model *m = &b->m;
	size_t row = m->cols[c];
	double rho;

	if (b->sc->representation == IRDM_REPR_FIR) {
		size_t T = fir_taps(b);
		const double *R = &b->fir[(c * m->n_rows + row) * T * 9];
		/* exact eigenvalues while the companion matrix is cheap (3(T-1)
		 * <= 480), the argument-principle upper bound beyond */
		rho = T <= 161 ? irdm_stability_fir_companion(R, T) : irdm_stability_fir(R, T);
	} else {
		size_t K = b->n_modes, H = b->head ? b->meta.head_samples : 1;
		const double *D = NULL;
		double Df[9];
		/* the diagonal block, always kept: stored rows are sorted */
		for (uint32_t k = b->sparse.start ? b->sparse.start[c] : 0;
		     b->sparse.start && k < b->sparse.start[c + 1]; k++)
			if (b->sparse.rows[k] == c)
				D = b->head ? &b->head[9 * H * (size_t)k] : &b->sparse.blocks[9 * (size_t)k];
		/* stored without the far field: R[0] has it (a hybrid's head
		 * already sums to the whole block) */
		if (D && b->far.rank && !b->head) {
			irdm_corr_lowrank_block(&b->far, c, c, Df);
			for (int e = 0; e < 9; e++)
				Df[e] += D[e];
			D = Df;
		}
		/* clustered: the kept diagonal is zero, the value is the pair's */
		if (D && b->clusters.n_clusters) {
			irdm_corr_clusters_block(&b->clusters, c, c, Df);
			for (int e = 0; e < 9; e++)
				Df[e] += D[e];
			D = Df;
		}
		/* the argument-principle certificate: O(modes) per point of a
		 * circle where the dense eigenvalues are O(modes^3)
		 * (irdm_stability_modal stays as the tests' reference); a
		 * hybrid image's head is a polynomial in 1/z added to H(z) */
		rho = irdm_stability_modal_ap_head(b->zoh, K, &b->shapes[3 * row * K], D, D ? H : 0);
	}
	/* judge the stored float: a radius within 3e-8 below 1 rounds to 1.0f */
	b->stab[c].spectral_radius = (float)rho;
	b->stab[c].flags = (rho >= 0 && b->stab[c].spectral_radius < 1.0f) ? IRDM_STAB_STABLE : 0;
}

static void *stab_worker(void *arg)
{
	struct stab_job *j = arg;

	for (size_t c = j->begin; c < j->end; c++) {
		stab_one(j->b, c);
		if (j->begin == 0 && j->b->o->progress && (c % 8 == 0))
			j->b->o->progress(j->b->o->ctx, "stability", (double)(c + 1) / (double)j->end);
	}
	return NULL;
}

/*
 * A hybrid whose head is shorter than the dropped modes' ringing is
 * unstable (its force recursion has a zero outside the unit circle), and
 * nothing in the engine can damp a modal recursion: refuse it here, with
 * what to change, rather than write an image that faults at first touch.
 */
static int hybrid_stable(const struct build *b, char *err, size_t errlen)
{
	size_t unstable = 0, worst = 0;

	for (size_t c = 0; c < b->m.n_cols; c++)
		if (!(b->stab[c].flags & IRDM_STAB_STABLE)) {
			if (!unstable || b->stab[c].spectral_radius > b->stab[worst].spectral_radius)
				worst = c;
			unstable++;
		}
	if (!unstable)
		return IRDM_OK;
	snprintf(err, errlen, "precompute: exact_head = %u on modal:%zu is unstable at %zu of %zu columns (spectral radius up to %.6f at mesh node %u): the dropped modes ring longer than the head; raise exact_head or keep more modes",
		 b->sc->exact_head, b->n_modes, unstable, b->m.n_cols,
		 (double)b->stab[worst].spectral_radius, b->m.rows[b->m.cols[worst]]);
	return IRDM_ENUMERIC;
}

/* The representation as the scene says it, for messages. */
static void repr_text(const struct irdm_scene *sc, char *buf, size_t len)
{
	if (sc->representation == IRDM_REPR_FIR)
		snprintf(buf, len, sc->fir_tail ? "fir:%u with fir_tail = window:%u" : "fir:%u",
			 sc->fir_length, sc->fir_tail);
	else if (!sc->modes)
		snprintf(buf, len, "modal:all");
	else if (sc->exact_head)
		snprintf(buf, len, "modal:%u%s + exact_head %u", sc->modes,
			 sc->static_correction ? " + static correction" : "", sc->exact_head);
	else
		snprintf(buf, len, "modal:%u%s", sc->modes,
			 sc->static_correction ? " + static correction" : "");
}

/* What may make an uncertified image certified. */
static void certify_hint(const struct irdm_scene *sc, char *buf, size_t len)
{
	if (sc->precision == IRDM_ELEM_F16)
		snprintf(buf, len, "try precision = f32 (f16 rounds the responses the certificate judges)");
	else if (sc->representation == IRDM_REPR_FIR && !sc->fir_tail)
		snprintf(buf, len, "try fir_tail = window (the default), or a modal representation");
	else if (sc->representation == IRDM_REPR_FIR)
		snprintf(buf, len, "try a longer fir_tail than window:%u, or a modal representation",
			 sc->fir_tail);
	else
		snprintf(buf, len, "try more modes (representation = modal:K), static_correction = yes or precision = f64");
}

/*
 * An image that `irdm image verify --require-stable` rejects is not
 * written unless the scene asks for it by name (uncertified = yes): a
 * warning after the fact is too easy to miss, and an uncertified FIR runs
 * on the engine's tail damping, which distorts it from the first sample.
 */
static int certified(const struct build *b, char *err, size_t errlen)
{
	size_t unstable = 0, worst = 0;
	char repr[64], hint[128];

	for (size_t c = 0; c < b->m.n_cols; c++)
		if (!(b->stab[c].flags & IRDM_STAB_STABLE)) {
			if (!unstable || b->stab[c].spectral_radius > b->stab[worst].spectral_radius)
				worst = c;
			unstable++;
		}
	if (!unstable || b->sc->uncertified)
		return IRDM_OK;
	repr_text(b->sc, repr, sizeof(repr));
	certify_hint(b->sc, hint, sizeof(hint));
	snprintf(err, errlen, "precompute: scene %s: %s is not certified stable: spectral radius %.6f at mesh node %u (%zu of %zu columns >= 1); %s (uncertified = yes writes it anyway)",
		 b->sc->name, repr, (double)b->stab[worst].spectral_radius,
		 b->m.rows[b->m.cols[worst]], unstable, b->m.n_cols, hint);
	return IRDM_ENUMERIC;
}

static int stability(struct build *b, char *err, size_t errlen)
{
	size_t n = b->m.n_cols;
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);
	unsigned nt = b->sc->threads ? b->sc->threads : (unsigned)(cpus > 0 ? cpus : 1);
	pthread_t th[64];
	bool started[64];
	struct stab_job jobs[64];
	int blas_threads, ret;

	b->stab = calloc(n, sizeof(*b->stab));
	if (!b->stab) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	if (nt > 64)
		nt = 64;
	if (nt > n)
		nt = (unsigned)n;
	/* one LAPACK call per thread: OpenBLAS's own threads would oversubscribe */
	blas_threads = irdm_blas_serial_begin();
	for (unsigned t = 0; t < nt; t++) {
		jobs[t] = (struct stab_job){ b, n * t / nt, n * (t + 1) / nt };
		started[t] = !pthread_create(&th[t], NULL, stab_worker, &jobs[t]);
		if (!started[t])
			stab_worker(&jobs[t]);
	}
	for (unsigned t = 0; t < nt; t++)
		if (started[t])
			pthread_join(th[t], NULL);
	irdm_blas_serial_end(blas_threads);
	b->meta.max_spectral_radius = 0;
	for (size_t c = 0; c < n; c++) {
		if (b->stab[c].spectral_radius < 0) {
			snprintf(err, errlen, "stability: could not compute the force recursion at column %zu (mesh node %u): R[0] singular?",
				 c, b->m.rows[b->m.cols[c]]);
			return IRDM_ENUMERIC;
		}
		b->meta.max_spectral_radius = fmax(b->meta.max_spectral_radius, b->stab[c].spectral_radius);
	}
	ret = b->head ? hybrid_stable(b, err, errlen) : IRDM_OK;
	return ret ? ret : certified(b, err, errlen);
}

static void fill_meta(struct build *b)
{
	const struct irdm_scene *sc = b->sc;
	struct irdm_model *m = &b->m;
	struct irdm_meta *mt = &b->meta;

	mt->representation = sc->representation;
	mt->precision = sc->precision;
	mt->n_nodes = (uint32_t)m->n_rows;
	mt->n_cols = (uint32_t)m->n_cols;
	mt->n_tris = (uint32_t)m->n_tris;
	mt->fir_length = sc->representation == IRDM_REPR_FIR ? (uint32_t)fir_taps(b) : 0;
	mt->fir_exact = sc->representation == IRDM_REPR_FIR && sc->fir_tail ? sc->fir_length : 0;
	mt->n_modes = sc->representation == IRDM_REPR_MODAL ? (uint32_t)b->n_modes : 0;
	mt->flags = (sc->floating ? IRDM_META_FLOATING : 0) |
		    (b->sparse.start ? IRDM_META_STATIC_CORR : 0) |
		    (sc->mass == IRDM_MASS_CONSISTENT ? IRDM_META_CONSISTENT_MASS : 0) |
		    (sc->method == IRDM_METHOD_TIME_DOMAIN ? IRDM_META_TIME_DOMAIN : 0) |
		    (mt->fir_exact ? IRDM_META_FIR_TAIL_WINDOW : 0) |
		    (b->head ? IRDM_META_EXACT_HEAD : 0) |
		    (b->col_scale ? IRDM_META_COLUMN_SCALE : 0) |
		    (b->head_index ? IRDM_META_HEAD_PAIRS : 0);
	mt->head_samples = b->head ? 2 * sc->exact_head : 0;
	mt->dt_s = sc->dt_s;
	mt->young_pa = sc->mat.young_pa;
	mt->poisson = sc->mat.poisson;
	mt->density_kg_m3 = sc->mat.density_kg_m3;
	mt->rayleigh_a_per_s = m->damping.a_per_s;
	mt->rayleigh_b_s = m->damping.b_s;
	if (sc->damping == IRDM_DAMP_RATIOS) {
		mt->damping_ratio[0] = sc->damp_ratio[0];
		mt->damping_ratio[1] = sc->damp_ratio[1];
		mt->damping_freq_hz[0] = sc->damp_hz[0] > 0 ? sc->damp_hz[0] : sqrt(m->modes.omega2[0]) / (2 * M_PI);
		mt->damping_freq_hz[1] = sc->damp_hz[1];
	}
	mt->first_elastic_hz = sqrt(m->modes.omega2[0]) / (2 * M_PI);
	mt->mesh_nodes = (uint32_t)m->mesh.n_nodes;
	mt->mesh_tets = (uint32_t)m->mesh.n_tets;
	mt->n_modes_total = (uint32_t)m->modes.n_elastic_total;
	mt->mesh_hash = irdm_mesh_hash(&m->mesh);
	snprintf(mt->tool_version, sizeof(mt->tool_version), "%s", IRDM_TOOL_VERSION);
	snprintf(mt->mesh_name, sizeof(mt->mesh_name), "%s", m->mesh.name);
}

static int fill_nodes_rigid(struct build *b)
{
	struct irdm_model *m = &b->m;

	b->nodes = calloc(m->n_rows, sizeof(*b->nodes));
	if (!b->nodes)
		return IRDM_ENOMEM;
	for (size_t r = 0; r < m->n_rows; r++) {
		for (int a = 0; a < 3; a++)
			b->nodes[r].pos_m[a] = (float)m->mesh.pos_m[3 * (size_t)m->rows[r] + (size_t)a];
		b->nodes[r].mesh_node = m->rows[r];
	}
	/*
	 * A floating body's mass, centre and inertia from the mass matrix
	 * the modes were separated with (consistent or lumped): from the
	 * lumped masses under a consistent M, an off-centre push spun the
	 * cube 2 % too slowly (24 % on a flat 6x6x1 mesh).
	 */
	if (m->fem.map.n_free == 3 * m->mesh.n_nodes)
		irdm_mass_properties_of_matrix(&m->mesh, &m->fem, &b->rigid.mass_kg,
					       b->rigid.com_m, b->rigid.inertia_kg_m2);
	else
		irdm_mass_properties(&m->mesh, m->fem.lumped_mass_kg, &b->rigid.mass_kg,
				     b->rigid.com_m, b->rigid.inertia_kg_m2);
	return IRDM_OK;
}

static int provenance(struct build *b)
{
	char scene[4096];
	size_t len = PROV_BYTES;

	b->prov = malloc(len);
	if (!b->prov)
		return IRDM_ENOMEM;
	if (irdm_scene_format(b->sc, scene, sizeof(scene)))
		return IRDM_EINVAL;
	snprintf(b->prov, len,
		 "tool=%s\nmesh_name=%s\nmesh_nodes=%zu\nmesh_tets=%zu\nmesh_hash=%016llx\n"
		 "free_dofs=%zu\nrayleigh_a_per_s=%.17g\nrayleigh_b_s=%.17g\n"
		 "modes_solved=%zu\nmodes_total=%zu\nfirst_elastic_hz=%.9g\n%s",
		 IRDM_TOOL_VERSION, b->m.mesh.name, b->m.mesh.n_nodes, b->m.mesh.n_tets,
		 (unsigned long long)b->meta.mesh_hash, b->m.fem.map.n_free,
		 b->m.damping.a_per_s, b->m.damping.b_s, b->m.modes.n_modes,
		 b->m.modes.n_elastic_total, b->meta.first_elastic_hz, scene);
	/* the scene's modal:K would keep the lowest K: say that it did not */
	if (b->kept_not_lowest)
		snprintf(b->prov + strlen(b->prov), len - strlen(b->prov),
			 "modes_kept=the ones ringing past the head (not the lowest)\n");
	return IRDM_OK;
}

/* The image's sections, in file order.
 * Return: IRDM_OK; IRDM_EINVAL if the writer refuses one (table full, kind
 * repeated, no data): a bug here, but never an image with a section missing. */
static int add_sections(struct build *b, struct irdm_image_writer *w, const void *bvh,
			size_t bvh_bytes, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	uint32_t p = b->sc->precision;
	int ret = 0;

	irdm_iw_init(w);
	ret |= irdm_iw_add(w, IRDM_SEC_META, IRDM_ELEM_BYTES, &b->meta, sizeof(b->meta));
	ret |= irdm_iw_add(w, IRDM_SEC_PROVENANCE, IRDM_ELEM_BYTES, b->prov, strlen(b->prov));
	ret |= irdm_iw_add(w, IRDM_SEC_NODES, IRDM_ELEM_BYTES, b->nodes, m->n_rows * sizeof(*b->nodes));
	ret |= irdm_iw_add(w, IRDM_SEC_COLUMNS, IRDM_ELEM_U32, m->cols, m->n_cols * sizeof(uint32_t));
	ret |= irdm_iw_add(w, IRDM_SEC_SURFACE, IRDM_ELEM_U32, m->tris, m->n_tris * 3 * sizeof(uint32_t));
	if (b->sc->representation == IRDM_REPR_FIR) {
		ret |= irdm_iw_add(w, IRDM_SEC_FIR, p, b->stored[0], b->stored_bytes[0]);
	} else {
		ret |= irdm_iw_add(w, IRDM_SEC_MODES, IRDM_ELEM_BYTES, b->zoh, b->n_modes * sizeof(*b->zoh));
		ret |= irdm_iw_add(w, IRDM_SEC_MODE_SHAPES, p, b->stored[1], b->stored_bytes[1]);
		if (b->stored[2]) {
			struct irdm_corr_sparse *s = &b->sparse;
			ret |= irdm_iw_add(w, IRDM_SEC_STATIC_CORR, p, b->stored[2], b->stored_bytes[2]);
			ret |= irdm_iw_add(w, IRDM_SEC_STATIC_CORR_INDEX, IRDM_ELEM_U32, s->start,
					   (s->n_cols + 1 + s->n_blocks) * sizeof(uint32_t));
			if (b->stored[3])
				ret |= irdm_iw_add(w, IRDM_SEC_STATIC_CORR_LOWRANK, IRDM_ELEM_BYTES,
						   b->stored[3], b->stored_bytes[3]);
			if (b->stored[5])
				ret |= irdm_iw_add(w, IRDM_SEC_STATIC_CORR_CLUSTERS, IRDM_ELEM_BYTES,
						   b->stored[5], b->stored_bytes[5]);
		}
		if (b->stored[4])
			ret |= irdm_iw_add(w, IRDM_SEC_EXACT_HEAD, p, b->stored[4], b->stored_bytes[4]);
		if (b->head_index)
			ret |= irdm_iw_add(w, IRDM_SEC_EXACT_HEAD_INDEX, IRDM_ELEM_U32, b->head_index,
					   b->sparse.n_blocks * sizeof(uint32_t));
	}
	if (b->sc->floating)
		ret |= irdm_iw_add(w, IRDM_SEC_RIGID, IRDM_ELEM_BYTES, &b->rigid, sizeof(b->rigid));
	if (b->col_scale)
		ret |= irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, b->col_scale,
				   m->n_cols * sizeof(*b->col_scale));
	ret |= irdm_iw_add(w, IRDM_SEC_STABILITY, IRDM_ELEM_BYTES, b->stab, m->n_cols * sizeof(*b->stab));
	ret |= irdm_iw_add(w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_BYTES, bvh, bvh_bytes);
	if (ret) {
		snprintf(err, errlen, "precompute: the image writer refused a section");
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

static int write_image(struct build *b, const char *path, size_t *bytes, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	struct irdm_image_writer w;
	void *bvh;
	size_t bvh_bytes;
	FILE *f;
	int ret;

	ret = irdm_bvh_build(b->nodes, (uint32_t)m->n_rows, m->cols, (uint32_t)m->n_cols, m->tris,
			     (uint32_t)m->n_tris, &bvh, &bvh_bytes, err, errlen);
	if (ret)
		return ret;
	ret = add_sections(b, &w, bvh, bvh_bytes, err, errlen);
	if (!ret)
		ret = irdm_iw_write(&w, path, err, errlen);
	free(bvh);
	if (ret)
		return ret;
	f = fopen(path, "rb");
	if (f) {
		fseek(f, 0, SEEK_END);
		*bytes = (size_t)ftell(f);
		fclose(f);
	}
	return IRDM_OK;
}

/* STATIC_CORR_LOWRANK's payload: header, lambda, U in the precision. */
static void *store_far(const struct irdm_corr_lowrank *lr, uint32_t prec, size_t *bytes)
{
	struct irdm_corr_lowrank_header h = { .rank = (uint32_t)lr->rank };
	size_t es = irdm_elem_size(prec), hdr = sizeof(h);
	uint8_t *p;

	*bytes = hdr + es * lr->rank * (1 + lr->n_dofs);
	p = malloc(*bytes);
	if (!p)
		return NULL;
	memcpy(p, &h, hdr);
	for (size_t k = 0; k < lr->rank; k++)
		irdm_elem_put(p + hdr, prec, k, lr->lambda[k]);
	for (size_t i = 0; i < lr->rank * lr->n_dofs; i++)
		irdm_elem_put(p + hdr + es * lr->rank, prec, i, lr->u[i]);
	return p;
}

/* STATIC_CORR_CLUSTERS' payload (image_format.h): header, the three
 * tables, padding, the pair table, the values in the precision. */
static void *store_clusters(const struct irdm_corr_clusters *cl, uint32_t prec, size_t *bytes)
{
	struct irdm_corr_clusters_header h = { .n_clusters = (uint32_t)cl->n_clusters,
					       .max_rank = (uint32_t)cl->max_rank,
					       .n_values = cl->n_values };
	size_t es = irdm_elem_size(prec), nc = cl->n_cols, nC = cl->n_clusters;
	size_t tables = (sizeof(h) + 4 * (nC + 1 + 2 * nc) + 7) & ~(size_t)7;
	size_t pairs = sizeof(struct irdm_corr_pair) * cl->n_pairs;
	uint8_t *p;

	*bytes = tables + pairs + es * cl->n_values;
	p = calloc(1, *bytes);
	if (!p)
		return NULL;
	memcpy(p, &h, sizeof(h));
	memcpy(p + sizeof(h), cl->start, 4 * (nC + 1));
	memcpy(p + sizeof(h) + 4 * (nC + 1), cl->members, 4 * nc);
	memcpy(p + sizeof(h) + 4 * (nC + 1 + nc), cl->col_pos, 4 * nc);
	for (size_t q = 0; q < cl->n_pairs; q++) {
		struct irdm_corr_pair e = { .offset = cl->offset[q], .rank = cl->rank[q] };
		memcpy(p + tables + q * sizeof(e), &e, sizeof(e));
	}
	for (size_t i = 0; i < cl->n_values; i++)
		irdm_elem_put(p + tables + pairs, prec, i, cl->values[i]);
	return p;
}

/*
 * f16: a power of two per force column over the values it divides (the
 * FIR, or the kept correction blocks and their head: col_scale.h), and
 * those stored scaled, so that stiff objects do not underflow.  The
 * certificate and the error measurement then see the values as stored.
 */
static int store_f16_scaled(struct build *b)
{
	size_t nc = b->m.n_cols, fir_per = b->m.n_rows * fir_taps(b) * 9;
	size_t head_per = 2 * (size_t)b->sc->exact_head * 9;
	uint32_t p = b->sc->precision;
	double *mx = calloc(nc ? nc : 1, sizeof(*mx));

	b->col_scale = malloc((nc ? nc : 1) * sizeof(*b->col_scale));
	if (!mx || !b->col_scale) {
		free(mx);
		return IRDM_ENOMEM;
	}
	if (b->fir)
		irdm_col_absmax(b->fir, nc, NULL, fir_per, mx);
	if (b->sparse.start)
		irdm_col_absmax(b->sparse.blocks, nc, b->sparse.start, 9, mx);
	if (b->head)
		irdm_col_absmax(b->head, nc, b->sparse.start, head_per, mx);
	for (size_t c = 0; c < nc; c++)
		b->col_scale[c] = irdm_col_scale_for(mx[c]);
	free(mx);
	if (b->fir)
		b->stored[0] = irdm_store_scaled(b->fir, nc, NULL, fir_per, b->col_scale, p,
						 &b->stored_bytes[0]);
	if (b->sparse.start)
		b->stored[2] = irdm_store_scaled(b->sparse.blocks, nc, b->sparse.start, 9,
						 b->col_scale, p, &b->stored_bytes[2]);
	if (b->head)
		b->stored[4] = irdm_store_scaled(b->head, nc, b->sparse.start, head_per,
						 b->col_scale, p, &b->stored_bytes[4]);
	return IRDM_OK;
}

static int responses(struct build *b, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	int ret;

	if (b->sc->representation == IRDM_REPR_MODAL)
		ret = modal_data(b, err, errlen);
	else if (b->sc->method == IRDM_METHOD_TIME_DOMAIN)
		ret = fir_time_domain(b, err, errlen);
	else
		ret = fir_from_modes(b, err, errlen);
	if (ret || b->o->part_out)
		return ret;
	if (b->fir && b->sc->fir_tail) {
		ret = irdm_fir_tail_window(m, b->sc->floating, b->sc->fir_length, b->sc->fir_tail,
					   b->fir, err, errlen);
		if (ret)
			return ret;
	}
	if (b->sc->precision == IRDM_ELEM_F16 && store_f16_scaled(b)) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	if (b->fir && !b->col_scale)
		b->stored[0] = store(b->fir, m->n_cols * m->n_rows * fir_taps(b) * 9,
				     b->sc->precision, &b->stored_bytes[0]);
	if (b->shapes && b->sc->representation == IRDM_REPR_MODAL)
		b->stored[1] = store(b->shapes, m->n_rows * 3 * b->n_modes, b->sc->precision,
				     &b->stored_bytes[1]);
	if (b->sparse.start && !b->col_scale)
		b->stored[2] = store(b->sparse.blocks, b->sparse.n_blocks * 9, b->sc->precision,
				     &b->stored_bytes[2]);
	if (b->far.rank)
		b->stored[3] = store_far(&b->far, b->sc->precision, &b->stored_bytes[3]);
	if (b->head && head_by_pairs(b)) {
		struct irdm_head_pairs hp;
		ret = irdm_head_pairs_store(&b->sparse, 2 * (size_t)b->sc->exact_head,
					    b->sc->precision, b->head, &hp);
		if (ret == IRDM_EINVAL) {
			snprintf(err, errlen, "precompute: the static correction kept a block without its mirror");
			return ret;
		}
		b->stored[4] = hp.runs;
		b->stored_bytes[4] = hp.bytes;
		b->head_index = hp.index;
	}
	if (b->clusters.n_clusters)
		b->stored[5] = store_clusters(&b->clusters, b->sc->precision, &b->stored_bytes[5]);
	if ((b->fir && !b->stored[0]) ||
	    (b->shapes && b->sc->representation == IRDM_REPR_MODAL && !b->stored[1]) ||
	    (b->sparse.start && !b->stored[2]) || (b->far.rank && !b->stored[3]) ||
	    (b->head && !b->stored[4]) || (b->clusters.n_clusters && !b->stored[5])) {
		snprintf(err, errlen, "precompute: out of memory converting to the storage precision");
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

static void build_free(struct build *b)
{
	irdm_model_free(&b->m);
	free(b->zoh);
	free(b->fir);
	free(b->shapes);
	free(b->corr);
	irdm_corr_sparse_free(&b->sparse);
	free(b->head);
	irdm_corr_lowrank_free(&b->far);
	irdm_corr_clusters_free(&b->clusters);
	for (int i = 0; i < 6; i++)
		free(b->stored[i]);
	free(b->col_scale);
	free(b->head_index);
	free(b->stab);
	free(b->nodes);
	free(b->prov);
}

static void report(const struct build *b, struct irdm_precompute_report *rep)
{
	const struct irdm_model *m = &b->m;

	rep->seconds_mesh = m->seconds_mesh;
	rep->seconds_fem = m->seconds_fem;
	rep->seconds_eig = m->seconds_eig;
	rep->eig_blocks = m->modes.eig_blocks;
	rep->mesh_nodes = m->mesh.n_nodes;
	rep->mesh_tets = m->mesh.n_tets;
	rep->free_dofs = m->fem.map.n_free;
	rep->rows = m->n_rows;
	rep->cols = m->n_cols;
	rep->tris = m->n_tris;
	rep->modes = m->modes.n_modes;
	rep->modes_total = m->modes.n_elastic_total;
	rep->first_elastic_hz = m->modes.n_modes ? sqrt(m->modes.omega2[0]) / (2 * M_PI) : 0;
	rep->max_spectral_radius = b->meta.max_spectral_radius;
	for (size_t c = 0; b->stab && c < m->n_cols; c++)
		rep->unstable_cols += !(b->stab[c].flags & IRDM_STAB_STABLE);
	rep->corr_blocks = b->sparse.n_blocks;
	rep->corr_tol = b->sc->static_corr_tol;
	rep->corr_max_dropped_rel = b->sparse.max_dropped_rel;
	rep->corr_rank = b->far.rank;
	rep->corr_checked = b->far.n_checked;
	rep->corr_far_max[0] = b->far.max_before;
	rep->corr_far_max[1] = b->far.max_after;
	rep->corr_far_rms[0] = b->far.rms_before;
	rep->corr_far_rms[1] = b->far.rms_after;
	rep->corr_clusters = b->clusters.n_clusters;
	rep->corr_cluster_pairs_dense = b->clusters.n_dense;
	rep->corr_cluster_max_rank = b->clusters.max_rank;
	rep->corr_cluster_max_err = b->clusters.max_err;
	rep->corr_cluster_values = b->clusters.n_values;
}

/* Every elastic mode was solved (some may be dropped from the image). */
static bool all_modes(const struct build *b)
{
	return b->n_solved == b->m.modes.n_elastic_total && b->sc->method == IRDM_METHOD_MODAL &&
	       b->m.modes.phi && irdm_dist_size() == 1;
}

/* The reference image of scene rsc from this build's model and its first
 * n_modes modes: its own selection (the sampled nodes); nothing else
 * shared. */
static int reference_build(struct build *b, const struct irdm_scene *rsc, const char *path,
			   size_t n_modes, char *err, size_t errlen)
{
	struct irdm_precompute_opts ro = { .out_path = path };
	struct build r = { .sc = rsc, .o = &ro, .m = b->m, .reference = true };
	size_t bytes;
	int ret;

	r.m.modes.n_modes = n_modes;
	r.m.rows = r.m.cols = r.m.tris = NULL;
	r.m.row_dofs = r.m.col_dofs = NULL;
	r.m.n_rows = r.m.n_cols = r.m.n_tris = 0;
	ret = irdm_model_select(rsc, &r.m, err, errlen);
	if (!ret)
		ret = responses(&r, err, errlen);
	if (!ret) {
		fill_meta(&r);
		ret = stability(&r, err, errlen);
	}
	if (!ret)
		ret = fill_nodes_rigid(&r);
	if (!ret)
		ret = provenance(&r);
	if (!ret)
		ret = write_image(&r, path, &bytes, err, errlen);
	/* r's own allocations only: the mesh, FEM and modes are b's */
	free(r.m.rows);
	free(r.m.cols);
	free(r.m.tris);
	free(r.m.row_dofs);
	free(r.m.col_dofs);
	free(r.zoh);
	free(r.shapes);
	for (int i = 0; i < 6; i++)
		free(r.stored[i]);
	free(r.col_scale);
	free(r.stab);
	free(r.nodes);
	free(r.prov);
	free(r.head);
	free(r.head_index);
	irdm_corr_sparse_free(&r.sparse);
	irdm_corr_lowrank_free(&r.far);
	return ret;
}

/* The exact model's image from this build's own modes: the same mesh,
 * FEM and eigensolve, every mode, no static correction, in double. */
static int reference_from_model(void *ctx, const struct irdm_scene *rsc, const char *path,
				char *err, size_t errlen)
{
	struct build *b = ctx;

	return reference_build(b, rsc, path, b->m.modes.n_elastic_total, err, errlen);
}

/* Was the head built from Chebyshev series (not every mode solved)? */
static bool krylov_hybrid(const struct build *b)
{
	return b->sc->exact_head && b->sc->representation == IRDM_REPR_MODAL &&
	       b->n_solved < b->m.modes.n_elastic_total && irdm_dist_size() == 1;
}

/*
 * The exact model without every mode: the kept modes, exact, and the
 * dropped ones' whole response over the measurement's run, from Chebyshev
 * series at the sampled nodes -- a hybrid whose head outlasts the run
 * (exact_head = its ticks, so the convolution never reads the taper, and
 * only the run's samples are computed) and keeps every block between
 * them, in double.  What it shares with the image is the kept modes and
 * the method (test_krylov_head holds that to every mode); what the image
 * loses past its own head, in its dropped blocks and its storage is what
 * it measures.
 */
static int reference_by_krylov(void *ctx, const struct irdm_scene *rsc, const char *path,
			       char *err, size_t errlen)
{
	struct build *b = ctx;
	struct irdm_scene *k = malloc(sizeof(*k));
	char v[32];
	int ret;

	if (!k) {
		snprintf(err, errlen, "error measurement: out of memory");
		return IRDM_ENOMEM;
	}
	*k = *rsc;
	k->eigensolver = IRDM_EIG_LANCZOS;
	snprintf(v, sizeof(v), "modal:%zu", b->n_modes);
	ret = irdm_scene_set(k, "representation", v, "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(k, "static_correction", "yes", "error measurement", err, errlen);
	if (!ret)
		ret = irdm_scene_set(k, "static_correction_tol", "0", "error measurement", err, errlen);
	snprintf(v, sizeof(v), "%zu", irdm_measure_ticks(b->sc->dt_s));
	if (!ret)
		ret = irdm_scene_set(k, "exact_head", v, "error measurement", err, errlen);
	if (!ret)
		ret = reference_build(b, k, path, b->n_modes, err, errlen);
	free(k);
	return ret;
}

/* What may bring an image's measured error under max_error. */
static void repr_hint(const struct irdm_scene *sc, char *buf, size_t len)
{
	if (sc->representation == IRDM_REPR_FIR && !sc->fir_tail)
		snprintf(buf, len, "fir_tail = window (no tail damping), a longer FIR, or a modal representation with exact_head");
	else if (sc->representation == IRDM_REPR_FIR)
		snprintf(buf, len, "a longer FIR (fir:%u), or a modal representation with exact_head",
			 2 * sc->fir_length);
	else if (!sc->modes)
		snprintf(buf, len, "precision = f64");
	else if (!sc->static_correction)
		snprintf(buf, len, "static_correction = yes with exact_head = 128, or more modes");
	else if (!sc->exact_head)
		snprintf(buf, len, "a hybrid head (exact_head = 128) on these modes, more modes, or representation = modal:all");
	else
		snprintf(buf, len, "a longer head (exact_head = %u) or more modes (modal:%u)",
			 2 * sc->exact_head, 2 * sc->modes);
}

/* The same, f16 first: its 11 bits may be what misses (a soft object's
 * long FIR sums thousands of taps that the force cancels), or the
 * representation may be whatever the precision. */
static void error_hint(const struct irdm_scene *sc, char *buf, size_t len)
{
	char rest[160];

	if (sc->precision != IRDM_ELEM_F16) {
		repr_hint(sc, buf, len);
		return;
	}
	if (sc->representation == IRDM_REPR_MODAL && !sc->modes) {
		snprintf(buf, len, "precision = f32");
		return;
	}
	repr_hint(sc, rest, sizeof(rest));
	snprintf(buf, len, "precision = f32, and if that is not enough %s", rest);
}

/* contacts = 2: halving static_correction_tol keeps more of the blocks
 * between touchable nodes, which two contacts at once need; below this it
 * keeps them all. */
#define CONTACTS_TOL_FLOOR 1e-3

static double tighter_tol(double tol)
{
	return tol / 2 < CONTACTS_TOL_FLOOR ? 0 : tol / 2;
}

/* contacts = 2, and this try met max_error for one contact but not for
 * two at once (a pair that diverged is refused for that instead). */
static bool pairs_missed(const struct build *b, const struct irdm_precompute_report *rep)
{
	return b->sc->contacts > 1 && rep->error_measured && rep->pairs_measured &&
	       rep->measured_error <= b->sc->max_error && rep->pairs_error <= IRDM_PAIRS_DIVERGED &&
	       rep->pairs_error > b->sc->max_error;
}

/* contacts = 2: the two-contact figure held against max_error too. */
static int within_target_pairs(const struct build *b, const struct irdm_precompute_report *rep,
			       char *err, size_t errlen)
{
	char repr[64], hint[96];

	if (b->sc->contacts < 2 || (rep->pairs_measured && rep->pairs_error <= b->sc->max_error))
		return IRDM_OK;
	repr_text(b->sc, repr, sizeof(repr));
	if (!rep->pairs_measured) {
		snprintf(err, errlen, "precompute: scene %s: contacts = %u, but two contacts at once were not measured on %s: they need every mode of a grounded object solved (representation = auto, or modal:K with exact_head from every mode: not eigensolver = lanczos), two touchable nodes, and one process (not MPI ranks)",
			 b->sc->name, b->sc->contacts, repr);
		return IRDM_ENUMERIC;
	}
	if (tighter_tol(b->sc->static_corr_tol) > 0)
		snprintf(hint, sizeof(hint), "static_correction_tol = %g (it is %g) or 0",
			 tighter_tol(b->sc->static_corr_tol), b->sc->static_corr_tol);
	else if (b->sc->static_corr_tol > 0)
		snprintf(hint, sizeof(hint), "static_correction_tol = 0 (it is %g)",
			 b->sc->static_corr_tol);
	else
		snprintf(hint, sizeof(hint), "a longer head or more modes");
	snprintf(err, errlen, "precompute: scene %s: %s is %.3g off the exact model for one contact, but two contacts grabbed at once at mesh nodes %u and %u are %.3g off (relative RMS force error, %s), above max_error = %g with contacts = %u; try %s",
		 b->sc->name, repr, rep->measured_error, rep->pairs_nodes[0], rep->pairs_nodes[1],
		 rep->pairs_error, rep->pairs_run, b->sc->max_error, b->sc->contacts, hint);
	return IRDM_ENUMERIC;
}

/* Refuse an image whose measured error is above the scene's max_error. */
static int within_target(const struct build *b, const struct irdm_precompute_report *rep,
			 char *err, size_t errlen)
{
	char repr[64], hint[224];

	if (rep->pairs_measured && !(rep->pairs_error <= IRDM_PAIRS_DIVERGED)) {
		repr_text(b->sc, repr, sizeof(repr));
		snprintf(err, errlen, "precompute: scene %s: %s is certified node by node, but two contacts grabbed at once at mesh nodes %u and %u are %.3g off the exact model (relative RMS force error, %s): the pair diverges; try static_correction_tol = 0 (every block between touchable nodes kept) (max_error = none skips the check)",
			 b->sc->name, repr, rep->pairs_nodes[0], rep->pairs_nodes[1], rep->pairs_error,
			 rep->pairs_run);
		return IRDM_ENUMERIC;
	}
	/* not measured (max_error = none, MPI ranks): contacts = 2 cannot pass */
	if (!rep->error_measured || rep->measured_error <= b->sc->max_error)
		return within_target_pairs(b, rep, err, errlen);
	repr_text(b->sc, repr, sizeof(repr));
	error_hint(b->sc, hint, sizeof(hint));
	snprintf(err, errlen, "precompute: scene %s: %s is %.3g off the exact model (relative RMS force error, worst: %s at mesh node %u), above max_error = %g; try %s (max_error = none skips the check)",
		 b->sc->name, repr, rep->measured_error, rep->error_worst_run,
		 rep->error_worst_node, b->sc->max_error, hint);
	return IRDM_ENUMERIC;
}

/*
 * The image's force error against the exact model (accuracy/measure.h),
 * measured on the image as it will be written: a scratch copy beside it,
 * then the figure goes into META.  max_error = none skips it (the exact
 * model needs every mode); over MPI ranks it is not measured (the
 * reference's dense eigensolve would run on rank 0 alone).
 */
/* The exact model as a precompute of its own, when this one did not solve
 * every mode. */
static int reference_by_precompute(void *ctx, const struct irdm_scene *rsc, const char *path,
				   char *err, size_t errlen)
{
	struct irdm_precompute_opts o = { .out_path = path };
	struct irdm_precompute_report rep;

	(void)ctx;
	return irdm_precompute(rsc, &o, &rep, err, errlen);
}

/*
 * The columns the image is likely worst at (accuracy/screen.h), when it
 * drops modes this build solved and corrects them statically or by a
 * head: measured besides the spread.  Return: how many.
 */
static size_t screened_columns(const struct build *b, uint32_t *cols)
{
	struct irdm_modes all = b->m.modes;
	struct irdm_mode *zoh;
	bool *dropped;
	size_t n = 0;

	all.n_modes = b->n_solved;
	if (!all_modes(b) || b->sc->representation != IRDM_REPR_MODAL || !b->sc->static_correction ||
	    b->n_modes >= all.n_modes)
		return 0;
	zoh = malloc(all.n_modes * sizeof(*zoh));
	dropped = malloc(all.n_modes * sizeof(*dropped));
	for (size_t d = 0; dropped && d < all.n_modes; d++)
		dropped[d] = d >= b->n_modes; /* the kept ones come first */
	if (zoh && dropped && !irdm_modes_discretise(&all, &b->m.damping, b->sc->dt_s, zoh))
		n = irdm_screen_columns(&all, zoh, dropped, b->sc->exact_head, b->m.col_dofs,
					b->m.n_cols, irdm_measure_ticks(b->sc->dt_s),
					IRDM_MEASURE_SCREENED, cols, NULL);
	free(zoh);
	free(dropped);
	return n;
}

/* The measured figure into META and the report. */
static void record(struct build *b, struct irdm_precompute_report *rep, double error,
		   uint32_t worst_node, const char *worst_run, size_t cols, size_t ticks,
		   double seconds)
{
	b->meta.measured_error = (float)error;
	b->meta.flags |= IRDM_META_ERROR_MEASURED;
	rep->error_measured = true;
	rep->measured_error = error;
	rep->error_worst_node = worst_node;
	rep->error_worst_run = worst_run;
	rep->error_cols = cols;
	rep->error_ticks = ticks;
	rep->seconds_error = seconds;
}

/* error_columns: every column, when asked, or by default when it can
 * and it costs no more than the sample. */
static bool every_column(const struct build *b)
{
	switch (b->sc->error_columns) {
	case IRDM_ERROR_COLUMNS_EVERY:
		return true;
	case IRDM_ERROR_COLUMNS_SAMPLE:
		return false;
	default:
		return all_modes(b) && !b->sc->floating && b->m.n_cols <= IRDM_MEASURE_EVERY_AUTO;
	}
}

/* The image's error at every column (accuracy/scan.h). */
static int scan(struct build *b, const struct irdm_image *img, struct irdm_precompute_report *rep,
		char *err, size_t errlen)
{
	struct irdm_modes all = b->m.modes;
	struct irdm_mode *zoh = NULL;
	uint32_t *nodes = NULL;
	struct irdm_scan res;
	int ret = IRDM_EINVAL;

	all.n_modes = b->n_solved;
	if (!all_modes(b) || b->sc->floating) {
		snprintf(err, errlen, "precompute: error_columns = every needs a grounded object whose every mode is solved (representation = auto, or exact_head without eigensolver = lanczos); %s",
			 b->sc->floating ? "this one floats" : "this build solved some of them");
		return ret;
	}
	ret = IRDM_ENOMEM;
	zoh = malloc(all.n_modes * sizeof(*zoh));
	nodes = malloc(b->m.n_cols * sizeof(*nodes));
	if (!zoh || !nodes) {
		snprintf(err, errlen, "precompute: out of memory");
		goto out_free;
	}
	irdm_modes_discretise(&all, &b->m.damping, b->sc->dt_s, zoh);
	for (size_t c = 0; c < b->m.n_cols; c++)
		nodes[c] = b->m.rows[b->m.cols[c]];
	ret = irdm_scan_every_column(img, &all, zoh, b->m.col_dofs, nodes, b->m.n_cols,
				     b->o->progress, b->o->ctx, &res, err, errlen);
	if (ret)
		goto out_free;
	record(b, rep, res.worst, res.worst_node, res.worst_run, res.n_cols, res.ticks, res.seconds);
	rep->error_every_column = true;
	rep->error_median = res.median;
	rep->error_p90 = res.p90;
out_free:
	free(zoh);
	free(nodes);
	return ret;
}

/* The two-contact figure goes with the image, for irdm-fw and image info
 * (image-format.md, PROVENANCE); provenance() sized the text for it. */
static void prov_pairs(struct build *b, const struct irdm_pairs *res)
{
	size_t n = strlen(b->prov);

	snprintf(b->prov + n, PROV_BYTES - n, IRDM_PROV_TWO_CONTACTS_ERROR "=%.6g\ntwo_contacts_pairs=%zu\n",
		 res->worst, res->n_pairs);
}

/*
 * Two contacts at once (accuracy/pairs.h), at columns spread over the
 * surface: far apart, where a static correction drops the blocks between
 * them.  Measured on an image within max_error, printed and stored, held
 * against it only with contacts = 2 (the target is of one contact); a
 * pair that diverges refuses the image (within_target()).
 */
static int pairs(struct build *b, const struct irdm_image *img, struct irdm_precompute_report *rep,
		 char *err, size_t errlen)
{
	struct irdm_modes all = b->m.modes;
	struct irdm_mode *zoh = NULL;
	uint32_t cols[IRDM_PAIRS_COLS];
	double *pos = NULL;
	struct irdm_pairs res;
	size_t n;
	int ret = IRDM_ENOMEM;

	all.n_modes = b->n_solved;
	if (!all_modes(b) || b->sc->floating || b->m.n_cols < 2)
		return IRDM_OK;
	for (size_t c = 0; c < b->m.n_cols; c++)
		if (img->nodes[img->columns[c]].mesh_node != b->m.rows[b->m.cols[c]])
			return IRDM_OK; /* not the model's columns: nothing to compare with */
	zoh = malloc(all.n_modes * sizeof(*zoh));
	pos = malloc(3 * b->m.n_cols * sizeof(double));
	if (!zoh || !pos) {
		snprintf(err, errlen, "precompute: out of memory");
		goto out_free;
	}
	for (size_t c = 0; c < b->m.n_cols; c++)
		memcpy(&pos[3 * c], img->nodes[img->columns[c]].pos_m, 3 * sizeof(double));
	n = irdm_measure_spread(pos, b->m.n_cols, IRDM_PAIRS_COLS, cols);
	irdm_modes_discretise(&all, &b->m.damping, b->sc->dt_s, zoh);
	ret = irdm_pairs_measure(img, &all, zoh, b->m.col_dofs, cols, n, &res, err, errlen);
	if (ret)
		goto out_free;
	rep->pairs_measured = true;
	rep->pairs_error = res.worst;
	rep->pairs_nodes[0] = res.nodes[0];
	rep->pairs_nodes[1] = res.nodes[1];
	rep->pairs_run = res.run;
	rep->pairs_n = res.n_pairs;
	rep->seconds_error += res.seconds;
	prov_pairs(b, &res);
out_free:
	free(zoh);
	free(pos);
	return ret;
}

static int measure(struct build *b, struct irdm_precompute_report *rep, char *err, size_t errlen)
{
	uint32_t screened[IRDM_MEASURE_SCREENED];
	size_t n_screened;
	const char *out = b->o->out_path;
	size_t n = strlen(out) + 16, bytes;
	char *tmp = malloc(n), *ref = malloc(n);
	struct irdm_measure res;
	struct irdm_image img;
	int ret = IRDM_ENOMEM;

	rep->pairs_measured = false; /* an earlier try's pairs are not this one's */
	if (!(b->sc->max_error > 0) || irdm_dist_size() > 1) {
		free(tmp);
		free(ref);
		return IRDM_OK;
	}
	if (!tmp || !ref) {
		snprintf(err, errlen, "precompute: out of memory");
		goto out_free;
	}
	rep->error_reference = krylov_hybrid(b) && !all_modes(b) ? "the kept modes and Chebyshev series" :
								   "every mode";
	snprintf(tmp, n, "%s.unmeasured", out);
	snprintf(ref, n, "%s.exact", out);
	ret = write_image(b, tmp, &bytes, err, errlen);
	b->try_bytes = ret ? 0 : bytes;
	if (!ret)
		ret = irdm_image_map(tmp, 0, &img, err, errlen);
	if (ret)
		goto out_unlink;
	if (every_column(b)) {
		ret = scan(b, &img, rep, err, errlen);
		if (!ret && rep->measured_error <= b->sc->max_error)
			ret = pairs(b, &img, rep, err, errlen);
		irdm_image_unmap(&img);
		goto out_unlink;
	}
	n_screened = screened_columns(b, screened);
	ret = irdm_measure_error_at(b->sc, &img, screened, n_screened, ref,
				    all_modes(b)     ? reference_from_model :
				    krylov_hybrid(b) ? reference_by_krylov :
						       reference_by_precompute,
				    b,
				    b->o->progress, b->o->ctx, &res, err, errlen);
	if (!ret)
		record(b, rep, res.error, res.worst_node, res.worst_run, res.n_cols, res.ticks,
		       res.seconds);
	if (!ret && rep->measured_error <= b->sc->max_error)
		ret = pairs(b, &img, rep, err, errlen);
	irdm_image_unmap(&img);
out_unlink:
	unlink(tmp);
out_free:
	free(tmp);
	free(ref);
	return ret;
}

static uint64_t scene_hash(const struct irdm_scene *sc)
{
	char text[4096];

	if (irdm_scene_format(sc, text, sizeof(text)))
		return 0;
	return irdm_fnv1a(IRDM_FNV1A_INIT, text, strlen(text));
}

/* Responses, certificate, nodes, provenance, the measured error: all
 * but the write. */
static int one_try(struct build *b, struct irdm_precompute_report *rep, char *err, size_t errlen)
{
	double t1 = irdm_now_s();
	int ret = responses(b, err, errlen);

	if (ret || b->o->part_out)
		return ret;
	rep->seconds_responses += irdm_now_s() - t1;
	fill_meta(b);
	t1 = irdm_now_s();
	ret = stability(b, err, errlen);
	if (ret)
		return ret;
	rep->seconds_stability += irdm_now_s() - t1;
	ret = fill_nodes_rigid(b);
	if (!ret)
		ret = provenance(b);
	if (ret) {
		snprintf(err, errlen, ret == IRDM_ENOMEM ? "precompute: out of memory" : "precompute: the scene does not fit in the provenance text");
		return ret;
	}
	ret = measure(b, rep, err, errlen);
	return ret ? ret : within_target(b, rep, err, errlen);
}

/* Back to the model alone, every mode in it, for another try. */
static void reset_try(struct build *b, size_t n_all)
{
	free(b->zoh);
	free(b->fir);
	free(b->shapes);
	free(b->corr);
	free(b->head);
	free(b->stab);
	free(b->nodes);
	free(b->prov);
	b->zoh = NULL;
	b->fir = b->shapes = b->corr = b->head = NULL;
	b->stab = NULL;
	b->nodes = NULL;
	b->prov = NULL;
	irdm_corr_sparse_free(&b->sparse);
	irdm_corr_lowrank_free(&b->far);
	irdm_corr_clusters_free(&b->clusters);
	for (int i = 0; i < 6; i++) {
		free(b->stored[i]);
		b->stored[i] = NULL;
	}
	free(b->col_scale);
	b->col_scale = NULL;
	free(b->head_index);
	b->head_index = NULL;
	b->n_modes = 0;
	memset(&b->meta, 0, sizeof(b->meta));
	b->m.modes.n_modes = n_all;
}

/* One of auto's builds, from the model alone with its first n modes:
 * nothing of an earlier try's is left, its head under the cap. */
static void begin_auto_try(struct build *b, struct irdm_precompute_report *rep, size_t n)
{
	reset_try(b, n);
	b->auto_try = true;
	b->head_capped = 0;
	b->try_bytes = 0;
	rep->error_measured = false;
}

/* Did the try measure over max_error? */
static bool over_target(const struct build *b, const struct irdm_precompute_report *rep)
{
	return rep->error_measured && rep->measured_error > b->sc->max_error;
}

#define AUTO_ALL_MODES 300 /* at most this many modes: modal:all, exact and as cheap */

/*
 * Put the candidate's kept modes first (modal/head_split.h: the first
 * c->modes of the rank for its head, as it was sized), as split_modes()
 * and the static correction take the first K; order[] receives the
 * permutation, to undo it.
 */
static int kept_first(struct build *b, const struct irdm_auto_candidate *c, size_t *order,
		      char *err, size_t errlen)
{
	struct irdm_modes *md = &b->m.modes;
	size_t n = md->n_modes, *rank = malloc((n ? n : 1) * sizeof(*rank));
	bool *dropped = malloc((n ? n : 1) * sizeof(*dropped));
	int ret = IRDM_ENOMEM;

	if (rank && dropped)
		ret = irdm_head_split_rank(md, &b->m.damping, c->head * b->sc->dt_s, rank);
	if (!ret)
		irdm_head_split_order(rank, n, c->modes, order, dropped);
	free(rank);
	free(dropped);
	if (ret) {
		snprintf(err, errlen, "precompute: out of memory");
		return ret;
	}
	b->kept_not_lowest = false;
	for (size_t i = 0; i < c->modes; i++)
		b->kept_not_lowest |= order[i] >= c->modes;
	if (irdm_modes_permute(md, order)) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

/* Back to ascending frequency: order[] made kept_first()'s permutation of
 * all n_all modes (the try left n_modes at the kept ones). */
static int kept_undo(struct build *b, size_t n_all, const size_t *order, size_t *inv)
{
	b->m.modes.n_modes = n_all;
	for (size_t k = 0; k < n_all; k++)
		inv[order[k]] = k;
	b->kept_not_lowest = false;
	return irdm_modes_permute(&b->m.modes, inv);
}

/* One candidate's line: what it is, what it costs, what it measured;
 * refused before a measurement, why (err). */
static void say_candidate(const struct build *b, const struct irdm_auto_candidate *c,
			  const struct irdm_precompute_report *rep, int ret, const char *err)
{
	char line[768], repr[64], size[48] = "not written", meas[64] = "not measured", pred[48] = "";
	bool over, missed = ret && pairs_missed(b, rep);

	if (!b->o->progress)
		return;
	repr_text(b->sc, repr, sizeof(repr));
	if (b->try_bytes)
		snprintf(size, sizeof(size), "image %.1f MiB", (double)b->try_bytes / (1 << 20));
	if (rep->error_measured)
		snprintf(meas, sizeof(meas), "measured error %.3g", rep->measured_error);
	if (c->predicted >= 0)
		snprintf(pred, sizeof(pred), ", predicted error %.3g", c->predicted);
	over = over_target(b, rep);
	snprintf(line, sizeof(line), "auto: %s%s: estimated tick %.2f us%s, %s, %s: %s%.400s", repr,
		 c->head ? " (kept: the modes ringing longest past the head)" : "", c->tick_us, pred,
		 size, meas,
		 !ret   ? "kept, the cheapest estimated to tick that is certified and meets max_error" :
		 missed ? "two contacts at once over max_error" :
		 over   ? "over max_error" :
			  "refused: ",
		 ret && !over && !missed ? err : "");
	b->o->progress(b->o->ctx, line, -1.0);
}

/* The list, before any is built. */
static void say_candidates(const struct build *b, const struct irdm_auto_candidate *c, size_t n)
{
	char line[1024]; /* every candidate: up to IRDM_AUTO_MAX_CANDIDATES of about 50 */
	int len = snprintf(line, sizeof(line), "auto: candidates, cheapest estimated tick first:");

	if (!b->o->progress)
		return;
	for (size_t k = 0; k < n && len > 0 && (size_t)len < sizeof(line); k++)
		len += snprintf(line + len, sizeof(line) - (size_t)len,
				"%s %zu modes to %.0f Hz%s%.0u (%.2f us)", k ? "," : "", c[k].modes,
				c[k].kept_max_hz,
				c[k].head                       ? " + head " :
				c[k].modes < b->m.modes.n_modes ? " + static correction" :
								  "",
				c[k].head, c[k].tick_us);
	b->o->progress(b->o->ctx, line, -1.0);
}

/* Try candidate c on the model (every mode in it, ascending). */
static int try_candidate(struct build *b, const struct irdm_auto_candidate *c, size_t n_all,
			 struct irdm_precompute_report *rep, size_t *order, char *err,
			 size_t errlen)
{
	struct irdm_scene *eff = (struct irdm_scene *)b->sc;
	bool hybrid = c->modes < n_all && c->head;
	int ret;

	begin_auto_try(b, rep, n_all);
	eff->modes = c->modes < n_all ? (unsigned)c->modes : 0;
	eff->static_correction = c->modes < n_all;
	eff->exact_head = hybrid ? c->head : 0;
	/* a hybrid's head needs the dropped-block correction */
	eff->static_corr_cluster = !hybrid && c->modes < n_all ? b->cluster : 0;
	if (hybrid) {
		ret = kept_first(b, c, order, err, errlen);
		if (ret)
			return ret;
	} else if (c->modes < n_all) {
		b->kept_not_lowest = false;
		b->m.modes.n_modes = c->modes; /* truncated: the lowest K */
	}
	ret = one_try(b, rep, err, errlen);
	rep->auto_tries++;
	say_candidate(b, c, rep, ret, err);
	if (ret && hybrid && kept_undo(b, n_all, order, &order[n_all])) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	return ret;
}

/*
 * The probe auto sizes its hybrids on (accuracy/split.h): the columns of
 * the measurement's spread; zoh: every mode discretised.
 */
static int candidates(struct build *b, const struct irdm_mode *zoh,
		      struct irdm_auto_candidate *cand, size_t *n_cand, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	struct irdm_split_probe probe;
	uint32_t cols[IRDM_MEASURE_SPREAD];
	int64_t dofs[3 * IRDM_MEASURE_SPREAD];
	double *pos = malloc(3 * (m->n_cols ? m->n_cols : 1) * sizeof(double));
	size_t n;
	int ret = IRDM_ENOMEM;

	if (!pos)
		goto out_free;
	for (size_t c = 0; c < m->n_cols; c++)
		memcpy(&pos[3 * c], &m->mesh.pos_m[3 * (size_t)m->rows[m->cols[c]]], 3 * sizeof(double));
	n = irdm_measure_spread(pos, m->n_cols, IRDM_MEASURE_SPREAD, cols);
	for (size_t i = 0; i < n; i++)
		memcpy(&dofs[3 * i], &m->col_dofs[3 * (size_t)cols[i]], 3 * sizeof(int64_t));
	if (b->o->progress)
		b->o->progress(b->o->ctx, "auto: sizing the hybrids", 0.0);
	ret = irdm_split_probe_init(&probe, &m->modes, zoh, dofs, n, irdm_measure_ticks(b->sc->dt_s));
	if (ret)
		goto out_free;
	*n_cand = irdm_auto_candidates(&m->modes, &m->damping, b->sc->dt_s, b->sc->max_error,
				       !b->cluster, &probe, cand);
	irdm_split_probe_free(&probe);
	if (b->o->progress)
		b->o->progress(b->o->ctx, "auto: sizing the hybrids", 1.0);
out_free:
	if (ret)
		snprintf(err, errlen, ret == IRDM_ENOMEM ? "precompute: out of memory for auto's candidates" : "precompute: auto: a probed column's first response sample is singular");
	free(pos);
	return ret;
}

/*
 * A hybrid whose head was over the cap, with twice the modes: the static
 * correction of fewer dropped modes keeps fewer blocks, so its head may
 * fit, and more of the rank's modes only lower the error.  Not once it
 * would tick no cheaper than all n_all modes.
 */
static bool grow(struct irdm_auto_candidate *c, size_t n_all)
{
	size_t k = 2 * c->modes;

	if (k >= n_all || irdm_auto_tick_us(k, c->head) >= irdm_auto_tick_us(n_all, 0))
		return false;
	c->modes = k;
	c->tick_us = irdm_auto_tick_us(k, c->head);
	c->predicted = -1; /* under the one predicted for fewer */
	return true;
}

/*
 * The heads found over the cap: a hybrid that keeps K modes kept n_blocks
 * correction blocks.  Keeping more modes leaves less static correction
 * and fewer blocks, but slowly: doubling K kept 0.70 to 0.87 of them on
 * the torus and the CAD part of the benchmarks (bench_torus,
 * bench_cad_part), so a hybrid of K' modes is taken to keep at least the
 * blocks of K over 2 for every doubling from K to K' (each head length
 * ranks the modes its own way: an estimate, not a bound).
 */
struct capped {
	size_t n;
	size_t modes[4 * IRDM_AUTO_MAX_CANDIDATES];
	size_t blocks[4 * IRDM_AUTO_MAX_CANDIDATES];
};

static void capped_add(struct capped *cp, size_t modes, size_t blocks)
{
	if (cp->n < sizeof(cp->modes) / sizeof(cp->modes[0])) {
		cp->modes[cp->n] = modes;
		cp->blocks[cp->n++] = blocks;
	}
}

/* The fewest blocks a hybrid of K modes is estimated to keep (0: none
 * over the cap yet). */
static size_t capped_blocks(const struct capped *cp, size_t K)
{
	size_t least = 0;

	for (size_t i = 0; i < cp->n; i++) {
		size_t blocks = cp->blocks[i];

		for (size_t k = cp->modes[i]; k < K && blocks; k *= 2)
			blocks /= 2;
		if (blocks > least)
			least = blocks;
	}
	return least;
}

/* Is c's head estimated over the cap by capped_blocks()?  Then building
 * it would only be refused: say so. */
static bool over_cap_estimated(const struct build *b, const struct capped *cp,
			       const struct irdm_auto_candidate *c, size_t n_all)
{
	size_t blocks;
	char line[256];

	if (!c->head || c->modes >= n_all)
		return false;
	blocks = capped_blocks(cp, c->modes);
	if (!((double)head_bytes(b, blocks, c->head) > b->sc->max_head_mib * (1 << 20)))
		return false;
	if (b->o->progress) {
		snprintf(line, sizeof(line), "auto: modal:%zu + static correction + exact_head %u: not built: its head would be over max_head_mib = %g (some %zu blocks, from the heads over it)",
			 c->modes, c->head, b->sc->max_head_mib, blocks);
		b->o->progress(b->o->ctx, line, -1.0);
	}
	return true;
}

#define AUTO_SCREENED 6  /* the columns a candidate is checked at before its build */
#define AUTO_SUSPECTS 32 /* a resized candidate is screened again among these */

/*
 * The columns the screen ranks worst for candidate c (rank: its modes'
 * order, the first c->modes kept), among every column on the first round
 * (which keeps the AUTO_SUSPECTS worst in sus) and among sus after: the
 * first AUTO_SCREENED into cols and probe.  Return: IRDM_OK; IRDM_ENOMEM;
 * IRDM_EINVAL (nothing to check).
 */
static int screen_probe(const struct build *b, const struct irdm_auto_candidate *c,
			const struct irdm_mode *zoh, const size_t *rank, bool first, uint32_t *sus,
			size_t *n_sus, struct irdm_split_probe *probe, uint32_t *cols,
			size_t *n_cols)
{
	const struct irdm_modes *md = &b->m.modes;
	bool *dropped = malloc(md->n_modes * sizeof(*dropped));
	int64_t dofs[3 * AUTO_SUSPECTS];
	uint32_t pick[AUTO_SUSPECTS];
	size_t N = irdm_measure_ticks(b->sc->dt_s);
	int ret = IRDM_ENOMEM;

	if (!dropped)
		return ret;
	for (size_t i = 0; i < md->n_modes; i++)
		dropped[rank[i]] = i >= c->modes;
	if (first) {
		*n_sus = irdm_screen_columns(md, zoh, dropped, c->head, b->m.col_dofs, b->m.n_cols,
					     N, AUTO_SUSPECTS, sus, NULL);
		memcpy(pick, sus, *n_sus * sizeof(*pick));
		*n_cols = *n_sus < AUTO_SCREENED ? *n_sus : AUTO_SCREENED;
	} else {
		for (size_t i = 0; i < *n_sus; i++)
			memcpy(&dofs[3 * i], &b->m.col_dofs[3 * (size_t)sus[i]], 3 * sizeof(int64_t));
		*n_cols = irdm_screen_columns(md, zoh, dropped, c->head, dofs, *n_sus, N,
					      AUTO_SCREENED, pick, NULL);
		for (size_t i = 0; i < *n_cols; i++)
			pick[i] = sus[pick[i]];
	}
	free(dropped);
	if (!*n_cols)
		return IRDM_EINVAL;
	for (size_t i = 0; i < *n_cols; i++) {
		cols[i] = pick[i];
		memcpy(&dofs[3 * i], &b->m.col_dofs[3 * (size_t)cols[i]], 3 * sizeof(int64_t));
	}
	return irdm_split_probe_init(probe, md, zoh, dofs, *n_cols, N);
}

static void say_screened(const struct build *b, const struct irdm_auto_candidate *c,
			 const uint32_t *cols, size_t n, double e, double budget, size_t k)
{
	char line[512], at[128] = "", then[64] = "";
	int len = 0;

	if (!b->o->progress)
		return;
	for (size_t i = 0; i < n && len >= 0 && (size_t)len < sizeof(at); i++)
		len += snprintf(at + len, sizeof(at) - (size_t)len, "%s%u", i ? ", " : "",
				b->m.rows[b->m.cols[cols[i]]]);
	if (!(e <= budget))
		snprintf(then, sizeof(then), k ? ": over %.3g; %zu modes meet it there" : ": over %.3g; none meets it there",
			 budget, k);
	snprintf(line, sizeof(line), "auto: %zu modes%s%.0u: predicted error %.3g at the mesh nodes screened as worst for it (%s)%s",
		 c->modes, c->head ? " + head " : " + static correction", c->head, e, at, then);
	b->o->progress(b->o->ctx, line, -1.0);
}

#define AUTO_SCREEN_ROUNDS 3 /* a resized candidate is screened again, up to this many times */

/*
 * Candidate c checked before its build at the columns the screen ranks
 * worst for it (accuracy/screen.h), which the sizing's spread may miss:
 * when its error predicted there is over its budget, it keeps the
 * fewest modes of its rank that meet the budget there too, and is
 * screened again with what it then drops; resized, it goes back in the
 * queue at its new cost (*changed), or is dropped when none meets the
 * budget (*none).  Return: IRDM_OK; IRDM_ENOMEM.
 */
static int screen_candidate(struct build *b, struct irdm_auto_candidate *c,
			    const struct irdm_mode *zoh, bool *changed, bool *none)
{
	const struct irdm_modes *md = &b->m.modes;
	size_t n = md->n_modes, *rank = malloc(n * sizeof(*rank)), n_cols, k;
	double budget = b->sc->max_error * (c->head ? IRDM_AUTO_PREDICTED_SHARE : 1.0), e, pred;
	struct irdm_split_probe probe;
	uint32_t cols[AUTO_SCREENED], sus[AUTO_SUSPECTS];
	size_t n_sus = 0;
	int ret = IRDM_ENOMEM;

	*changed = *none = false;
	if (!rank)
		return ret;
	for (size_t i = 0; i < n; i++)
		rank[i] = i;
	ret = c->head ? irdm_head_split_rank(md, &b->m.damping, c->head * b->sc->dt_s, rank) : 0;
	for (int round = 0; !ret && round < AUTO_SCREEN_ROUNDS && !*none; round++) {
		ret = screen_probe(b, c, zoh, rank, round == 0, sus, &n_sus, &probe, cols, &n_cols);
		if (ret)
			break;
		irdm_split_begin(&probe);
		e = irdm_split_try(&probe, &rank[c->modes], n - c->modes, c->head);
		k = 0;
		if (!(e <= budget))
			k = irdm_auto_fewest(&probe, rank, n, c->modes + 1, c->head, budget, &pred);
		say_screened(b, c, cols, n_cols, e, budget, k);
		irdm_split_probe_free(&probe);
		if (e <= budget)
			break;
		*changed = true;
		*none = !k;
		if (k) {
			double w2 = 0;
			for (size_t i = 0; i < k; i++)
				w2 = fmax(w2, md->omega2[rank[i]]);
			c->modes = k;
			c->predicted = pred;
			c->tick_us = irdm_auto_tick_us(k, c->head);
			c->kept_max_hz = sqrt(w2) / (2 * M_PI);
		}
	}
	free(rank);
	return ret == IRDM_ENOMEM ? ret : IRDM_OK; /* EINVAL: nothing dropped, a fixed column */
}

/* The candidate not yet settled that is cheapest to tick (n: none). */
static size_t cheapest(const struct irdm_auto_candidate *c, const bool *settled, size_t n)
{
	size_t best = n;

	for (size_t k = 0; k < n; k++)
		if (!settled[k] && (best == n || c[k].tick_us < c[best].tick_us))
			best = k;
	return best;
}

/*
 * contacts = 2: a try that met max_error for one contact but not for two
 * at once is tried again with static_correction_tol halved (the blocks
 * between far touchable nodes are what two contacts miss), down to 0.
 * The tighter tol stays for the candidates after it.
 */
static bool tighten_for_pairs(struct build *b, const struct irdm_precompute_report *rep)
{
	struct irdm_scene *eff = (struct irdm_scene *)b->sc;
	char line[224];

	if (!pairs_missed(b, rep) || !(eff->static_corr_tol > 0))
		return false;
	snprintf(line, sizeof(line), "auto: contacts = %u: two contacts at once %.3g off, above max_error: static_correction_tol %g -> %g",
		 eff->contacts, rep->pairs_error, eff->static_corr_tol, tighter_tol(eff->static_corr_tol));
	eff->static_corr_tol = tighter_tol(eff->static_corr_tol);
	if (b->o->progress)
		b->o->progress(b->o->ctx, line, -1.0);
	return true;
}

/*
 * representation = auto: every mode is solved; the candidates
 * (candidates.h), cheapest to tick first, are built until one is
 * certified and measures within max_error.  A hybrid whose head is over
 * max_head_mib grows (grow()) and waits its turn at its new cost, and
 * one estimated over it is grown without a build.  A model of at most
 * AUTO_ALL_MODES modes takes them all.
 */
static int choose(struct build *b, struct irdm_precompute_report *rep, char *err, size_t errlen)
{
	struct irdm_auto_candidate cand[IRDM_AUTO_MAX_CANDIDATES];
	bool settled[IRDM_AUTO_MAX_CANDIDATES] = { false }, checked[IRDM_AUTO_MAX_CANDIDATES] = { false };
	struct capped cp = { .n = 0 };
	size_t n_all = b->m.modes.n_modes, n_cand, k;
	size_t *order = malloc(2 * n_all * sizeof(*order));
	struct irdm_mode *zoh = NULL;
	char last[768] = "";
	int ret = IRDM_ENUMERIC;

	if (!order) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	b->cluster = b->sc->static_corr_cluster;
	if (b->cluster && b->o->progress)
		b->o->progress(b->o->ctx, "auto: static_correction_cluster is set: no hybrid (a hybrid's head needs the dropped-block correction)", -1.0);
	if (n_all <= AUTO_ALL_MODES) {
		cand[0] = (struct irdm_auto_candidate){
			.modes = n_all,
			.predicted = -1,
			.tick_us = irdm_auto_tick_us(n_all, 0),
			.kept_max_hz = sqrt(b->m.modes.omega2[n_all - 1]) / (2 * M_PI),
		};
		n_cand = 1;
	} else {
		/* every mode discretised once: sizing and screening share it */
		zoh = malloc(n_all * sizeof(*zoh));
		if (!zoh) {
			snprintf(err, errlen, "precompute: out of memory");
			free(order);
			return IRDM_ENOMEM;
		}
		irdm_modes_discretise(&b->m.modes, &b->m.damping, b->sc->dt_s, zoh);
		ret = candidates(b, zoh, cand, &n_cand, err, errlen);
		if (ret) {
			free(zoh);
			free(order);
			return ret;
		}
	}
	say_candidates(b, cand, n_cand);
	while ((k = cheapest(cand, settled, n_cand)) < n_cand) {
		bool changed, none;

		if (over_cap_estimated(b, &cp, &cand[k], n_all)) {
			settled[k] = !grow(&cand[k], n_all);
			continue;
		}
		if (zoh && !checked[k] && cand[k].modes < n_all) {
			checked[k] = true;
			ret = screen_candidate(b, &cand[k], zoh, &changed, &none);
			if (ret) {
				snprintf(err, errlen, "precompute: out of memory");
				break;
			}
			ret = IRDM_ENUMERIC;
			settled[k] = none;
			if (changed)
				continue;
		}
		ret = try_candidate(b, &cand[k], n_all, rep, order, err, errlen);
		if (ret != IRDM_ENUMERIC)
			break;
		snprintf(last, sizeof(last), "%s", err);
		if (tighten_for_pairs(b, rep))
			continue; /* the same candidate, more blocks kept */
		if (b->head_capped)
			capped_add(&cp, cand[k].modes, b->head_capped);
		settled[k] = !b->head_capped || !grow(&cand[k], n_all);
	}
	free(zoh);
	free(order);
	if (ret == IRDM_ENUMERIC)
		snprintf(err, errlen, "precompute: representation = auto: no candidate met max_error = %g (set max_error higher%s); the last: %s",
			 b->sc->max_error, b->sc->contacts > 1 ? ", or contacts = 1" : " or none", last);
	return ret;
}

/*
 * Make sure the modes solved pass the cutoff of share `left` (lowest.h):
 * how many lie below it is counted first (fem/inertia.h), then that many
 * and IRDM_LOWEST_MARGIN more are solved when the solved ones do not
 * pass it; *K: how many of those solved are at or below it, 1 at least
 * (*ringing: whether any is).  Refused
 * (IRDM_ENUMERIC) when every mode to the top of the spectrum rings that
 * long, or when the cutoff needs more modes than a Lanczos solve takes.
 */
static int lowest_solved(struct build *b, double left, double horizon_s, double w_up, size_t *K,
			 bool *ringing, char *err, size_t errlen)
{
	struct irdm_model *m = &b->m;
	size_t n_free = m->modes.n_elastic_total, below, most = n_free > 20 ? (n_free - 20) / 2 : 0;
	double w_c = irdm_decay_cutoff(&m->damping, horizon_s, left, w_up), w_top;
	char line[320];
	int ret;

	if (!(w_c < w_up)) {
		snprintf(err, errlen, "precompute: representation = auto: every mode up to the top of the spectrum (%.4g Hz) rings past a head of %u samples to %.3g of its envelope at this damping, and every mode does not fit: more damping at high frequency, or a coarser mesh",
			 w_up / (2 * M_PI), IRDM_LOWEST_HEAD, left);
		return IRDM_ENUMERIC;
	}
	ret = irdm_fem_count_below(&m->fem, w_c * w_c, &below, err, errlen);
	if (ret)
		return ret;
	/* a Krylov solve holds twice its modes and more: at most about half
	 * of them (modal/modes.c) */
	if (below + IRDM_LOWEST_MARGIN > most) {
		snprintf(err, errlen, "precompute: representation = auto: %zu modes lie below %.4g Hz and ring past a head of %u samples to %.3g of their envelope, more than the %zu of %zu modes a Lanczos solve takes, and every mode does not fit: a coarser mesh, more damping, or max_memory_mib higher",
			 below, w_c / (2 * M_PI), IRDM_LOWEST_HEAD, left, most, n_free);
		return IRDM_ENUMERIC;
	}
	w_top = sqrt(m->modes.omega2[b->n_solved - 1]);
	if (!(w_top > w_c) && b->n_solved < n_free) {
		snprintf(line, sizeof(line), "auto: %zu modes lie below %.4g Hz (inertia), ringing past the head to %.3g of their envelope: solving the lowest %zu",
			 below, w_c / (2 * M_PI), left, below + IRDM_LOWEST_MARGIN);
		if (b->o->progress)
			b->o->progress(b->o->ctx, line, -1.0);
		ret = irdm_model_solve_lowest(b->sc, below + IRDM_LOWEST_MARGIN, b->o->progress,
					      b->o->ctx, m, err, errlen);
		if (ret)
			return ret;
		b->n_solved = m->modes.n_modes;
		/* the damping was picked again from the first mode: the same,
		 * to rounding, so the cutoff stays */
	}
	*K = irdm_lowest_below(&m->modes, b->n_solved, w_c);
	if (*K != below && b->o->progress) {
		/* a mode the solve missed is not projected off: it stays in
		 * the head with the dropped ones, and the measurement sees it */
		snprintf(line, sizeof(line), "auto: the Lanczos solve has %zu modes below %.4g Hz, the inertia %zu",
			 *K, w_c / (2 * M_PI), below);
		b->o->progress(b->o->ctx, line, -1.0);
	}
	*ringing = *K > 0;
	if (*K == 0)
		*K = 1; /* a hybrid keeps one mode at least */
	return IRDM_OK;
}

/* The head over max_head_mib: refused, saying what would build it. */
static int head_over_cap(const struct build *b, char *err, size_t errlen)
{
	double mib = (double)head_bytes(b, b->head_capped, IRDM_LOWEST_HEAD) / (1 << 20);

	snprintf(err, errlen, "precompute: representation = auto: from the lowest modes (every mode does not fit), the head would take %.4g MiB (%zu blocks x %u samples), more than max_head_mib = %g: max_head_mib = %.0f or more builds it, or static_correction_tol higher keeps fewer blocks",
		 mib, b->head_capped, 2 * IRDM_LOWEST_HEAD, b->sc->max_head_mib, ceil(mib));
	return IRDM_ENUMERIC;
}

/* One build's line: what it kept, what it measured. */
static void say_lowest(const struct build *b, size_t K, bool ringing, double left,
		       const struct irdm_precompute_report *rep, int ret, const char *err)
{
	char line[768], meas[64] = "not measured";
	bool over = over_target(b, rep);

	if (!b->o->progress)
		return;
	if (rep->error_measured)
		snprintf(meas, sizeof(meas), "measured error %.3g", rep->measured_error);
	snprintf(line, sizeof(line), "auto: modal:%zu (%s %.4g Hz, over %.3g of their envelope after the head) + static correction + exact_head %u from Chebyshev series: estimated tick %.2f us, image %.1f MiB, %s: %s%.400s",
		 K, ringing ? "the modes to" : "none rings past the head; the first mode,",
		 sqrt(b->m.modes.omega2[K - 1]) / (2 * M_PI), left, IRDM_LOWEST_HEAD,
		 irdm_auto_tick_us(K, IRDM_LOWEST_HEAD), (double)b->try_bytes / (1 << 20), meas,
		 !ret ? "kept, certified and within max_error" : over ? "over max_error" :
									"refused: ",
		 ret && !over ? err : "");
	b->o->progress(b->o->ctx, line, -1.0);
}

/*
 * The measurement's reference runs Chebyshev series over the whole run
 * (irdm_measure_ticks()), about w_up t / 2 terms (1.07 to 1.16 times
 * that measured, test_krylov_head): a stiff object's spectrum reaches so
 * high that they would be more than the series may have.  Refused before
 * the modes it would keep are solved (the first few, for the damping, are).
 */
static int lowest_measurable(const struct build *b, double w_up, char *err, size_t errlen)
{
	double t = (double)(irdm_measure_ticks(b->sc->dt_s) - 1) * b->sc->dt_s;
	double terms = 1.2 * w_up * t / 2;

	if (terms <= IRDM_KRYLOV_HEAD_MAX_TERMS)
		return IRDM_OK;
	snprintf(err, errlen, "precompute: representation = auto: every mode does not fit, and without them the error measurement over %.3g s needs Chebyshev series of about %.0f terms (the spectrum reaches %.4g Hz), more than %d: a stiff object needs every mode: max_memory_mib higher, a coarser mesh, or max_error = none",
		 t, terms, w_up / (2 * M_PI), IRDM_KRYLOV_HEAD_MAX_TERMS);
	return IRDM_ENUMERIC;
}

/*
 * representation = auto when every mode did not fit (lowest.h): the
 * lowest modes ringing past the head to `left`, the head from Chebyshev
 * series, built and measured; a miss lowers `left` and builds again.
 */
static int choose_lowest(struct build *b, struct irdm_precompute_report *rep, char *err,
			 size_t errlen)
{
	struct irdm_scene *eff = (struct irdm_scene *)b->sc;
	double left = irdm_lowest_left_first(eff->max_error);
	double w_up = sqrt(irdm_krylov_spectrum_bound(&b->m.fem));
	char last[768] = "";
	int ret = IRDM_ENUMERIC;

	rep->auto_lowest = true;
	ret = lowest_measurable(b, w_up, err, errlen);
	if (ret)
		return ret;
	/* the provenance's scene builds the image again (to rounding: its
	 * Lanczos solve is of the kept modes alone) */
	eff->eigensolver = IRDM_EIG_LANCZOS;
	eff->representation = IRDM_REPR_MODAL;
	eff->static_correction = true;
	eff->exact_head = IRDM_LOWEST_HEAD;
	for (unsigned round = 0; round < IRDM_LOWEST_ROUNDS; round++) {
		size_t K;
		bool ringing;

		ret = lowest_solved(b, left, IRDM_LOWEST_HEAD * eff->dt_s, w_up, &K, &ringing, err,
				    errlen);
		if (ret && rep->error_measured) {
			size_t len = strlen(err);

			snprintf(err + len, errlen - len, "; the last build measured %.3g", rep->measured_error);
		}
		if (ret)
			return ret;
		begin_auto_try(b, rep, K); /* the image keeps the lowest K */
		eff->modes = (unsigned)K;
		ret = one_try(b, rep, err, errlen);
		rep->auto_tries++;
		say_lowest(b, K, ringing, left, rep, ret, err);
		if (b->head_capped) /* more modes keep as many blocks: measured */
			return head_over_cap(b, err, errlen);
		if (ret != IRDM_ENUMERIC || !over_target(b, rep))
			return ret;
		snprintf(last, sizeof(last), "%s", err);
		left = irdm_lowest_left_next(left, eff->max_error, rep->measured_error);
	}
	snprintf(err, errlen, "precompute: representation = auto: from the lowest modes (every mode does not fit), no build met max_error = %g in %u (set max_error higher); the last: %s",
		 eff->max_error, IRDM_LOWEST_ROUNDS, last);
	return ret;
}

/* Columns whose force recursion is not certified stable. */
static size_t unstable_cols(const struct build *b)
{
	size_t n = 0;

	for (size_t c = 0; b->stab && c < b->m.n_cols; c++)
		n += !(b->stab[c].flags & IRDM_STAB_STABLE);
	return n;
}

#define FIR_TAIL_FACTOR_MAX 16 /* fir_tail = window: L up to this many T */

/* fir_tail = window on an FIR: the precompute chooses L. */
static bool fir_tail_auto(const struct irdm_scene *sc)
{
	return sc->representation == IRDM_REPR_FIR && sc->fir_tail_auto && !sc->fir_tail;
}

/* The first L fir_tail = window tries, and the last: 2T .. 16T, T + L at
 * most the 1000000 samples an FIR may have. */
static unsigned fir_tail_first(unsigned T)
{
	return T <= 1000000 / 3 ? 2 * T : 1000000 - T;
}

static unsigned fir_tail_last(unsigned T)
{
	return (uint64_t)T * (FIR_TAIL_FACTOR_MAX + 1) <= 1000000 ? FIR_TAIL_FACTOR_MAX * T : 1000000 - T;
}

/*
 * fir_tail = window: L = 2T, doubled until the image is certified stable
 * (a longer window tapers more gently: the tail's ripple that makes the
 * truncated recursion unstable shrinks), up to 16T.  A certified image
 * that misses max_error is refused as it is (the window's error is past
 * T; a longer FIR is the fix), one that none certifies with the longest
 * window's reasons.  Over MPI ranks or in time-domain parts the first L
 * alone is tried: every rank and part must compute the same samples.
 */
static int fir_tail_search(struct build *b, struct irdm_precompute_report *rep, char *err,
			   size_t errlen)
{
	struct irdm_scene *eff = (struct irdm_scene *)b->sc;
	size_t n_all = b->m.modes.n_modes;
	unsigned T = eff->fir_length, last = fir_tail_last(T);
	bool one = irdm_dist_size() > 1 || b->o->part_out || b->o->n_merge;
	char why[768];
	int ret;

	for (;;) {
		ret = one_try(b, rep, err, errlen);
		if (one || eff->fir_tail >= last || (ret && ret != IRDM_ENUMERIC) || !unstable_cols(b))
			break;
		if (b->o->progress)
			b->o->progress(b->o->ctx, "fir_tail = window: a longer window", -1.0);
		reset_try(b, n_all);
		eff->fir_tail = (unsigned)((uint64_t)eff->fir_tail * 2 < last ? eff->fir_tail * 2 : last);
	}
	if (ret == IRDM_ENUMERIC && unstable_cols(b) && !one) {
		snprintf(why, sizeof(why), "%s", err);
		snprintf(err, errlen, "%s (fir_tail = window tried window:%u to window:%u)", why,
			 fir_tail_first(T), eff->fir_tail);
	}
	return ret;
}

int irdm_precompute(const struct irdm_scene *sc, const struct irdm_precompute_opts *o,
		    struct irdm_precompute_report *rep, char *err, size_t errlen)
{
	struct build b = { .sc = sc, .o = o };
	/* auto resolves to a representation (fir_tail = window to a length):
	 * the image's provenance says which */
	struct irdm_scene *eff = sc->repr_auto || fir_tail_auto(sc) ? malloc(sizeof(*eff)) : NULL;
	bool auto_choice = sc->repr_auto && sc->max_error > 0 && irdm_dist_size() == 1;
	double t0 = irdm_now_s();
	int ret;

	memset(rep, 0, sizeof(*rep));
	if ((sc->repr_auto || fir_tail_auto(sc)) && !eff) {
		snprintf(err, errlen, "precompute: out of memory");
		return IRDM_ENOMEM;
	}
	if (eff) {
		*eff = *sc;
		eff->repr_auto = false;
		if (fir_tail_auto(sc))
			eff->fir_tail = fir_tail_first(sc->fir_length);
		eff->fir_tail_auto = false;
		b.sc = eff;
	}
	b.scene_hash = scene_hash(sc);
	ret = irdm_model_build(sc, modes_needed(sc), o->progress, o->ctx, &b.m, err, errlen);
	if (ret) {
		free(eff);
		return ret;
	}
	b.scene_hash = irdm_fnv1a(b.scene_hash, &b.m.damping, sizeof(b.m.damping));
	b.n_solved = b.m.modes.n_modes;
	/* over MPI the ranks other than 0 are done once the eigenvectors are
	 * gathered (rank 0 alone holds them and makes the image), or once they
	 * gave rank 0 their share of the time-domain inputs */
	if (irdm_dist_rank() != 0) {
		if (sc->method == IRDM_METHOD_TIME_DOMAIN && !o->part_out && !o->n_merge)
			ret = td_distributed(&b, list_inputs(&b.m, NULL, NULL), err, errlen);
		goto out_worker;
	}
	if (auto_choice && b.m.lowest_only)
		ret = choose_lowest(&b, rep, err, errlen);
	else if (auto_choice)
		ret = choose(&b, rep, err, errlen);
	else
		ret = fir_tail_auto(sc) ? fir_tail_search(&b, rep, err, errlen) : one_try(&b, rep, err, errlen);
	if (ret || o->part_out)
		goto out_done;
	if (o->progress)
		o->progress(o->ctx, "contact BVH and image", 0.0);
	ret = write_image(&b, o->out_path, &rep->image_bytes, err, errlen);
	if (ret)
		goto out_free;
	if (o->progress)
		o->progress(o->ctx, "contact BVH and image", 1.0);
out_done:
	if (!ret)
		report(&b, rep);
out_worker:
	rep->seconds_total = irdm_now_s() - t0;
out_free:
	repr_text(b.sc, rep->representation, sizeof(rep->representation));
	build_free(&b);
	free(eff);
	return ret;
}

int irdm_precompute_count_inputs(const struct irdm_scene *sc, size_t *n_inputs,
				 char *err, size_t errlen)
{
	struct irdm_model m;
	int ret;

	ret = irdm_model_build(sc, 1, NULL, NULL, &m, err, errlen);
	if (ret)
		return ret;
	*n_inputs = list_inputs(&m, NULL, NULL);
	irdm_model_free(&m);
	return IRDM_OK;
}
