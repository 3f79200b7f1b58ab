/* SPDX-License-Identifier: MIT */
/*
 * The dropped modes' head from Lanczos runs.  The head is a function of
 * the stiffness: each dropped mode's response h_s(w^2) weighted by its
 * shape at two columns.  A Lanczos run of m steps on A = M^-1/2 K M^-1/2
 * from P M^-1/2 e_j (P: off the kept modes) gives h_s(A) of that vector
 * for every sample s at once, as beta0 V h_s(T) e1 with T the run's
 * tridiagonal matrix: m products with K, no dense eigensolve.
 *
 * The plain recurrence is used, without reorthogonalisation: the Ritz
 * values it repeats ("ghosts") carry the weights of the values they copy,
 * so h_s(T) e1 still converges, a few hundred steps later than with full
 * reorthogonalisation but at a cost linear in m instead of quadratic.
 * Only the start vector is projected off the kept modes: what rounding
 * brings back of them has a weight of the order of the projection's
 * residual.  A run is stopped by watching its own block converge.
 */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "modal/head_layout.h"
#include "modal/krylov_head.h"
#include "modal/lapack.h"
#include "modal/response.h"

#define FIRST_CHECK 200 /* no run converges sooner on a model worth this */
#define KH_THREADS_MAX 64

struct kh {
	const struct irdm_fem *fem;
	const struct irdm_modes *kept;
	const struct irdm_rayleigh *damp;
	double dt;
	size_t n, S, m_max;
	double *dinv;          /* M^-1/2, n */
	double *msq;           /* M^1/2, n */
	double *v, *vp, *w, *t; /* n each */
	double *coef;          /* kept->n_modes */
	double *alpha, *beta;  /* m_max each */
	double *Vr;            /* the run's vectors at the rows asked: R x m_max */
	double *d, *e, *z;     /* the tridiagonal eigensolve: m, m, m x m */
	double *work;
	int *iwork;
	int lwork, liwork;
	double *hs;            /* [s][l]: m_max x S, then the weights folded in */
	double *W;             /* R x m_max */
	struct irdm_mode *zoh; /* m_max */
	double *hd;            /* one Ritz value's response: S */
	double *own, *own_prev; /* 3 x S */
	struct irdm_krylov_head_stats st;
};

/* y = A x */
static void apply_a(const struct kh *k, const double *x, double *y)
{
	for (size_t i = 0; i < k->n; i++)
		k->t[i] = k->dinv[i] * x[i];
	irdm_csc_matvec(&k->fem->K, k->t, y);
	for (size_t i = 0; i < k->n; i++)
		y[i] *= k->dinv[i];
}

/* x -= Psi Psi^T x, Psi = M^1/2 Phi (orthonormal): off the kept modes. */
static void project(const struct kh *k, double *x)
{
	const struct irdm_modes *p = k->kept;
	int n = (int)k->n, K = (int)p->n_modes, one = 1;
	double d_one = 1.0, d_zero = 0.0, d_minus = -1.0;

	for (size_t i = 0; i < k->n; i++)
		k->t[i] = k->msq[i] * x[i];
	dgemm_("T", "N", &K, &one, &n, &d_one, p->phi, &n, k->t, &n, &d_zero, k->coef, &K);
	dgemm_("N", "N", &n, &one, &K, &d_minus, p->phi, &n, k->coef, &K, &d_zero, k->t, &n);
	for (size_t i = 0; i < k->n; i++)
		x[i] += k->msq[i] * k->t[i];
}

static double dot(const double *a, const double *b, size_t n)
{
	double s = 0;

	for (size_t i = 0; i < n; i++)
		s += a[i] * b[i];
	return s;
}

/*
 * After m steps: Y[r + R s] = rows r0 .. r0 + nr - 1 of beta0 V h_s(T) e1
 * (R: Vr's leading dimension).  The eigenpairs of T by divide and
 * conquer; a Ritz value below the lowest kept mode is rounding (the
 * dropped spectrum lies above it) and is lifted to it.
 */
static int ritz_rows(struct kh *k, size_t m, double beta0, size_t R, size_t r0, size_t nr,
		     double *Y)
{
	int mi = (int)m, info, nri = (int)nr, Si = (int)k->S, Ri = (int)R;
	double one = 1.0, zero = 0.0;
	struct irdm_modes ritz = { .n = 0, .n_modes = m, .omega2 = k->d };

	memcpy(k->d, k->alpha, m * sizeof(double));
	memcpy(k->e, k->beta, (m - 1) * sizeof(double));
	dstedc_("I", &mi, k->d, k->e, k->z, &mi, k->work, &k->lwork, k->iwork, &k->liwork, &info);
	if (info)
		return info;
	for (size_t l = 0; l < m; l++)
		k->d[l] = fmax(k->d[l], k->kept->omega2[0]);
	if (irdm_modes_discretise(&ritz, k->damp, k->dt, k->zoh))
		return -1;
	/* hs[s m + l] = beta0 Q_0l h_s(theta_l): an m x S matrix */
	for (size_t l = 0; l < m; l++) {
		double g = beta0 * k->z[l * m];

		irdm_zoh_response(&k->zoh[l], k->S, k->hd);
		for (size_t s = 0; s < k->S; s++)
			k->hs[s * m + l] = g * k->hd[s];
	}
	/* W = V_rows Q (nr x m), Y = W hs (nr x S) */
	dgemm_("N", "N", &nri, &mi, &mi, &one, &k->Vr[r0], &Ri, k->z, &mi, &zero, k->W, &nri);
	dgemm_("N", "N", &nri, &Si, &mi, &one, k->W, &nri, k->hs, &mi, &zero, Y, &nri);
	return 0;
}

/* max_s |a_s - b_s| / max_s |a_s| over 3 x S values */
static double rel_change(const double *a, const double *b, size_t S)
{
	double num = 0, den = 0;

	for (size_t s = 0; s < S; s++) {
		double dn = 0, dd = 0;

		for (int i = 0; i < 3; i++) {
			dn += (a[3 * s + (size_t)i] - b[3 * s + (size_t)i]) * (a[3 * s + (size_t)i] - b[3 * s + (size_t)i]);
			dd += a[3 * s + (size_t)i] * a[3 * s + (size_t)i];
		}
		num = fmax(num, dn);
		den = fmax(den, dd);
	}
	return den > 0 ? sqrt(num / den) : 0;
}

/* Is the run done after m steps (b: the next beta)?  Checked every
 * IRDM_KRYLOV_HEAD_CHECK steps from FIRST_CHECK, or when the run has
 * found an invariant subspace (b negligible: exact). */
static int converged(struct kh *k, size_t m, double beta0, double b, size_t R, size_t own,
		     double *change)
{
	double *swap;
	bool exact = !(b > 1e-13 * fabs(k->alpha[m - 1]));

	if (!exact && (m < FIRST_CHECK || (m - FIRST_CHECK) % IRDM_KRYLOV_HEAD_CHECK))
		return 0;
	if (exact) {
		*change = 0;
		return 1;
	}
	if (ritz_rows(k, m, beta0, R, own, 3, k->own))
		return -1;
	*change = m > FIRST_CHECK ? rel_change(k->own, k->own_prev, k->S) : INFINITY;
	swap = k->own;
	k->own = k->own_prev;
	k->own_prev = swap;
	return *change < IRDM_KRYLOV_HEAD_TOL;
}

/*
 * One run from the free DoF d0, its vectors kept at rdofs[0..R-1] (the
 * column's own three rows at own): Y (R x S) the rows' response.
 * Return: 0; IRDM_ENUMERIC not converged or LAPACK failed.
 */
static int run_axis(struct kh *k, int64_t d0, const int64_t *rdofs, size_t R, size_t own,
		    double *Y)
{
	double beta0, b_prev = 0, change = INFINITY, *v = k->v, *vp = k->vp, *w = k->w;
	size_t m = 0, n = k->n;
	int done = 0;

	memset(v, 0, n * sizeof(double));
	v[d0] = k->dinv[d0];
	project(k, v);
	project(k, v); /* twice: the first leaves rounding of the kept modes */
	beta0 = sqrt(dot(v, v, n));
	if (!(beta0 > 0)) {
		memset(Y, 0, R * k->S * sizeof(double));
		return 0;
	}
	for (size_t i = 0; i < n; i++)
		v[i] /= beta0;
	memset(vp, 0, n * sizeof(double));
	while (!done && m < k->m_max) {
		double a, b, *tmp;

		for (size_t r = 0; r < R; r++)
			k->Vr[m * R + r] = rdofs[r] < 0 ? 0.0 : v[rdofs[r]];
		apply_a(k, v, w);
		a = dot(w, v, n);
		for (size_t i = 0; i < n; i++)
			w[i] -= a * v[i] + b_prev * vp[i];
		b = sqrt(dot(w, w, n));
		k->alpha[m++] = a;
		done = converged(k, m, beta0, b, R, own, &change);
		if (done)
			break;
		k->beta[m - 1] = b;
		for (size_t i = 0; i < n; i++)
			w[i] /= b;
		tmp = vp;
		vp = v;
		v = w;
		w = tmp;
		b_prev = b;
	}
	k->v = v;
	k->vp = vp;
	k->w = w;
	if (done < 0)
		return IRDM_ENUMERIC;
	k->st.runs++;
	k->st.steps_sum += m;
	k->st.steps_max = m > k->st.steps_max ? m : k->st.steps_max;
	if (!done)
		return IRDM_ENUMERIC;
	k->st.last_change = fmax(k->st.last_change, change);
	return ritz_rows(k, m, beta0, R, 0, R, Y) ? IRDM_ENUMERIC : 0;
}

/* Column c's blocks from its first computed one: each axis a run. */
static int column(struct kh *k, const struct irdm_corr_sparse *corr, const int64_t *col_dofs,
		  size_t c, int64_t *rdofs, double *Y, double *head)
{
	uint32_t k0 = irdm_head_upper_begin(corr, c), nb = corr->start[c + 1] - k0;
	long kd = irdm_corr_sparse_find(corr, c, (uint32_t)c);
	size_t R = 3 * (size_t)nb, S = k->S;

	if (kd < (long)k0)
		return IRDM_EINVAL; /* the diagonal block is always kept */
	for (uint32_t b = 0; b < nb; b++)
		for (int i = 0; i < 3; i++)
			rdofs[3 * b + (uint32_t)i] = col_dofs[3 * (size_t)corr->rows[k0 + b] + (size_t)i];
	for (int j = 0; j < 3; j++) {
		int64_t d0 = col_dofs[3 * c + (size_t)j];
		int ret = d0 < 0 ? 0 : run_axis(k, d0, rdofs, R, 3 * (size_t)(kd - k0), Y);

		if (ret)
			return ret;
		for (uint32_t b = 0; b < nb; b++)
			for (size_t s = 0; s < S; s++)
				for (int i = 0; i < 3; i++) {
					int64_t r = rdofs[3 * b + (uint32_t)i];

					head[((size_t)(k0 + b) * S + s) * 9 + 3 * (size_t)i + (size_t)j] =
						d0 < 0 || r < 0 ? 0.0 : k->dinv[r] * Y[3 * b + (size_t)i + R * s];
				}
	}
	return 0;
}

static void kh_free(struct kh *k)
{
	free(k->dinv);
	free(k->msq);
	free(k->v);
	free(k->vp);
	free(k->w);
	free(k->t);
	free(k->coef);
	free(k->alpha);
	free(k->beta);
	free(k->Vr);
	free(k->d);
	free(k->e);
	free(k->z);
	free(k->work);
	free(k->iwork);
	free(k->hs);
	free(k->W);
	free(k->zoh);
	free(k->hd);
	free(k->own);
	free(k->own_prev);
}

static int kh_alloc(struct kh *k, size_t R_max)
{
	size_t n = k->n, m = k->m_max, S = k->S;

	k->lwork = (int)(1 + 4 * m + m * m);
	k->liwork = (int)(3 + 5 * m);
	k->dinv = malloc(n * sizeof(double));
	k->msq = malloc(n * sizeof(double));
	k->v = malloc(n * sizeof(double));
	k->vp = malloc(n * sizeof(double));
	k->w = malloc(n * sizeof(double));
	k->t = malloc(n * sizeof(double));
	k->coef = malloc(k->kept->n_modes * sizeof(double));
	k->alpha = malloc(m * sizeof(double));
	k->beta = malloc(m * sizeof(double));
	k->Vr = malloc(R_max * m * sizeof(double));
	k->d = malloc(m * sizeof(double));
	k->e = malloc(m * sizeof(double));
	k->z = malloc(m * m * sizeof(double));
	k->work = malloc((size_t)k->lwork * sizeof(double));
	k->iwork = malloc((size_t)k->liwork * sizeof(int));
	k->hs = malloc(m * S * sizeof(double));
	k->W = malloc(R_max * m * sizeof(double));
	k->zoh = malloc(m * sizeof(*k->zoh));
	k->hd = malloc(S * sizeof(double));
	k->own = malloc(3 * S * sizeof(double));
	k->own_prev = malloc(3 * S * sizeof(double));
	for (size_t i = 0; k->dinv && k->msq && i < n; i++) {
		k->msq[i] = sqrt(k->fem->M.val[k->fem->M.colptr[i]]);
		k->dinv[i] = 1 / k->msq[i];
	}
	return k->dinv && k->msq && k->v && k->vp && k->w && k->t && k->coef && k->alpha &&
			       k->beta && k->Vr && k->d && k->e && k->z && k->work && k->iwork &&
			       k->hs && k->W && k->zoh && k->hd && k->own && k->own_prev ?
		       0 :
		       IRDM_ENOMEM;
}

/* The runs over threads: each takes the next column (their blocks are
 * its own); the first failure stops the others. */
struct pool {
	const struct irdm_corr_sparse *corr;
	const int64_t *col_dofs;
	double *head;
	atomic_size_t next, done;
	atomic_int failed;
	size_t fail_col;
	int fail_ret;
	pthread_mutex_t lock;
};

struct worker {
	struct kh k;
	struct pool *p;
	int64_t *rdofs;
	double *Y;
};

static void *work(void *arg)
{
	struct worker *w = arg;
	struct pool *p = w->p;

	while (!atomic_load(&p->failed)) {
		size_t c = atomic_fetch_add(&p->next, 1);
		int ret;

		if (c >= p->corr->n_cols)
			break;
		ret = column(&w->k, p->corr, p->col_dofs, c, w->rdofs, w->Y, p->head);
		if (ret) {
			pthread_mutex_lock(&p->lock);
			if (!atomic_load(&p->failed)) {
				p->fail_col = c;
				p->fail_ret = ret;
				atomic_store(&p->failed, 1);
			}
			pthread_mutex_unlock(&p->lock);
			break;
		}
		atomic_fetch_add(&p->done, 1);
	}
	return NULL;
}

static void merge_stats(struct irdm_krylov_head_stats *a, const struct irdm_krylov_head_stats *b)
{
	a->runs += b->runs;
	a->steps_sum += b->steps_sum;
	a->steps_max = b->steps_max > a->steps_max ? b->steps_max : a->steps_max;
	a->last_change = fmax(a->last_change, b->last_change);
}

static unsigned n_workers(unsigned threads, size_t n_cols)
{
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);
	size_t nt = threads ? threads : (size_t)(cpus > 0 ? cpus : 1);

	nt = nt > KH_THREADS_MAX ? KH_THREADS_MAX : nt;
	return (unsigned)(nt > n_cols ? (n_cols ? n_cols : 1) : nt);
}

static void progress_wait(struct pool *p, pthread_t *th, unsigned nt, irdm_progress_fn progress,
			  void *ctx)
{
	size_t n_cols = p->corr->n_cols, last = 0;

	/* the caller's progress is not thread-safe: reported from here */
	while (progress && !atomic_load(&p->failed) && atomic_load(&p->done) < n_cols) {
		size_t d = atomic_load(&p->done);
		struct timespec ts = { 0, 100000000 };

		if (d != last)
			progress(ctx, "krylov head", (double)d / (double)n_cols);
		last = d;
		nanosleep(&ts, NULL);
	}
	for (unsigned t = 0; t < nt; t++)
		pthread_join(th[t], NULL);
	if (progress && !atomic_load(&p->failed))
		progress(ctx, "krylov head", 1.0);
}

int irdm_krylov_head(const struct irdm_fem *fem, const struct irdm_modes *kept,
		     const struct irdm_rayleigh *damping, double dt_s, const int64_t *col_dofs,
		     const struct irdm_corr_sparse *corr, const double *target, size_t H,
		     unsigned threads, irdm_progress_fn progress, void *ctx, double *head,
		     struct irdm_krylov_head_stats *st, char *err, size_t errlen)
{
	struct pool p = { .corr = corr, .col_dofs = col_dofs, .head = head,
			  .lock = PTHREAD_MUTEX_INITIALIZER };
	struct worker w[KH_THREADS_MAX];
	pthread_t th[KH_THREADS_MAX];
	unsigned nt = n_workers(threads, corr->n_cols), started = 0;
	size_t R_max = 3, S = 2 * H;
	int ret = IRDM_OK, blas;

	if (fem->M.nnz != fem->M.n || !kept->n_modes || !kept->phi || H < 1) {
		snprintf(err, errlen, "krylov head: needs a lumped mass, kept modes and a head (H = %zu)", H);
		return IRDM_EINVAL;
	}
	for (size_t c = 0; c < corr->n_cols; c++) {
		size_t R = 3 * (size_t)(corr->start[c + 1] - irdm_head_upper_begin(corr, c));
		R_max = R > R_max ? R : R_max;
	}
	memset(w, 0, sizeof(w));
	atomic_init(&p.next, 0);
	atomic_init(&p.done, 0);
	atomic_init(&p.failed, 0);
	for (unsigned t = 0; t < nt && !ret; t++) {
		w[t].k = (struct kh){ .fem = fem, .kept = kept, .damp = damping, .dt = dt_s,
				      .n = fem->K.n, .S = S, .m_max = IRDM_KRYLOV_HEAD_MAX_STEPS };
		w[t].p = &p;
		w[t].rdofs = malloc(R_max * sizeof(int64_t));
		w[t].Y = malloc(R_max * S * sizeof(double));
		if (kh_alloc(&w[t].k, R_max) || !w[t].rdofs || !w[t].Y) {
			snprintf(err, errlen, "krylov head: out of memory (%zu rows of %zu steps, %u threads)",
				 R_max, w[t].k.m_max, nt);
			ret = IRDM_ENOMEM;
		}
	}
	/* one thread per run: OpenBLAS's own threads would oversubscribe */
	blas = irdm_blas_serial_begin();
	for (unsigned t = 0; t < nt && !ret; t++, started++)
		if (pthread_create(&th[t], NULL, work, &w[t])) {
			atomic_store(&p.failed, 1);
			snprintf(err, errlen, "krylov head: cannot start a thread");
			ret = IRDM_ENOMEM;
		}
	progress_wait(&p, th, started, progress, ctx);
	irdm_blas_serial_end(blas);
	if (!ret && atomic_load(&p.failed)) {
		ret = p.fail_ret == IRDM_EINVAL ? IRDM_EINVAL : IRDM_ENUMERIC;
		snprintf(err, errlen, ret == IRDM_EINVAL ? "krylov head: column %zu has no diagonal block" :
			 "krylov head: column %zu: the Lanczos run did not converge to %g in %d steps",
			 p.fail_col, IRDM_KRYLOV_HEAD_TOL, IRDM_KRYLOV_HEAD_MAX_STEPS);
	}
	if (!ret) {
		for (size_t c = 0; c < corr->n_cols; c++)
			irdm_head_mirror(corr, c, irdm_head_upper_begin(corr, c), S, head);
		for (size_t b = 0; b < corr->n_blocks; b++)
			irdm_head_taper(&head[b * S * 9], H, &target[9 * b]);
	}
	if (st)
		memset(st, 0, sizeof(*st));
	for (unsigned t = 0; t < nt; t++) {
		if (st)
			merge_stats(st, &w[t].k.st);
		kh_free(&w[t].k);
		free(w[t].rdofs);
		free(w[t].Y);
	}
	return ret;
}
