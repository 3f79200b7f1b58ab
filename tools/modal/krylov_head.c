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
 * brings back of them shows as Ritz values below the dropped spectrum,
 * whose weight is dropped.  A run is stopped by watching its rows (its
 * column's blocks) converge; a column's three runs share each pass over
 * K.
 *
 * Runs on A^-1 instead (a solve with K's factor per step, the kept
 * modes, then the top of the spectrum, projected out at each) take fewer
 * steps, and their number does not grow with the mesh as these do, but
 * on the paper's cuboid each step cost an order of magnitude more and
 * the head took longer.
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
/* A Ritz value this far below the highest kept mode is not a dropped
 * mode's (they lie above the kept ones) but one of the kept modes that
 * rounding brought back: its weight is dropped.  A dropped mode equal to
 * the highest kept one stays (a double eigenvalue split by K). */
#define SPURIOUS 1e-6

/* One axis's run; a column's three go side by side. */
struct run {
	double beta0, b_prev, change;
	size_t m;
	size_t next_check;    /* the step of its next check */
	size_t open_check;    /* its last check not within tol (0: none yet) */
	int done;             /* 1 converged, -1 failed, 0 running */
	double *alpha, *beta; /* m_max each */
	double *Vr;           /* its vectors at the rows asked: R x m_max */
	double *cur, *prev;   /* its rows' responses at the last two checks: R x S */
};

struct kh {
	const struct irdm_fem *fem;
	const struct irdm_modes *kept;
	const struct irdm_rayleigh *damp;
	double dt;
	size_t n, S, m_max;
	double tol;
	double *dinv;           /* M^-1/2, n */
	double *msq;            /* M^1/2, n */
	double *v, *vp, *w, *t; /* the three runs' vectors interleaved, [i][axis]: 3n each */
	double *x, *coef;       /* a start vector (n) and its kept-mode part */
	struct run run[3];
	double *d, *e, *z; /* the tridiagonal eigensolve: m, m, m x m */
	double *work;
	int *iwork;
	int lwork, liwork;
	double *hs;            /* [s][l]: each Ritz value's weighted response, m x S */
	double *W;             /* R x m_max */
	double *G;             /* m_max x S */
	struct irdm_mode *zoh; /* m_max */
	double *hd;            /* one Ritz value's response: S */
	/* a run's first check: where the first column's runs had their last
	 * check not within tol (the runs of one model converge alike; each
	 * check is an eigensolve of T, m^2 to m^3).  Taken from the first
	 * column alone, before the others start, so that every column's
	 * result is the same whichever thread runs it. */
	size_t first_check;
	size_t hint; /* the last column's: its runs' earliest open check */
	struct irdm_krylov_head_stats st;
};

/*
 * y = A x for the three interleaved vectors at once: K is read once for
 * the three, which is most of a step's memory traffic.
 */
static void apply_a3(const struct kh *k, const double *x, double *y)
{
	const struct irdm_csc *K = &k->fem->K;

	for (size_t i = 0; i < k->n; i++)
		for (int a = 0; a < 3; a++)
			k->t[3 * i + (size_t)a] = k->dinv[i] * x[3 * i + (size_t)a];
	memset(y, 0, 3 * k->n * sizeof(double));
	for (size_t j = 0; j < k->n; j++) {
		const double *tj = &k->t[3 * j];

		for (int64_t q = K->colptr[j]; q < K->colptr[j + 1]; q++) {
			double *yi = &y[3 * (size_t)K->rowind[q]], kv = K->val[q];

			yi[0] += kv * tj[0];
			yi[1] += kv * tj[1];
			yi[2] += kv * tj[2];
		}
	}
	for (size_t i = 0; i < k->n; i++)
		for (int a = 0; a < 3; a++)
			y[3 * i + (size_t)a] *= k->dinv[i];
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

/* sum over i of a[3 i + ax] b[3 i + ax] */
static double dot3(const double *a, const double *b, size_t n, int ax)
{
	double s = 0;

	for (size_t i = 0; i < n; i++)
		s += a[3 * i + (size_t)ax] * b[3 * i + (size_t)ax];
	return s;
}

/*
 * After m steps of run u: Y[r + R s] = row r of beta0 V h_s(T) e1, its R
 * rows.  The eigenpairs of T by divide and conquer; a Ritz value below
 * the highest kept mode (SPURIOUS) gets no weight.
 */
static int ritz_rows(struct kh *k, const struct run *u, size_t R, double *Y)
{
	int mi = (int)u->m, info, Si = (int)k->S, Ri = (int)R;
	size_t m = u->m;
	double one = 1.0, zero = 0.0;
	struct irdm_modes ritz = { .n = 0, .n_modes = m, .omega2 = k->d };
	double lowest = (1 - SPURIOUS) * k->kept->omega2[k->kept->n_modes - 1];

	memcpy(k->d, u->alpha, m * sizeof(double));
	memcpy(k->e, u->beta, (m - 1) * sizeof(double));
	dstedc_("I", &mi, k->d, k->e, k->z, &mi, k->work, &k->lwork, k->iwork, &k->liwork, &info);
	if (info)
		return info;
	for (size_t l = 0; l < m; l++)
		k->d[l] = fmax(k->d[l], lowest);
	if (irdm_modes_discretise(&ritz, k->damp, k->dt, k->zoh))
		return -1;
	for (size_t l = 0; l < m; l++) {
		double g = k->d[l] > lowest ? u->beta0 * k->z[l * m] : 0.0;

		irdm_zoh_response(&k->zoh[l], k->S, k->hd);
		for (size_t s = 0; s < k->S; s++)
			k->hs[s * m + l] = g * k->hd[s];
	}
	/* Y = V_rows Q hs, the cheaper way round: many rows (a column's
	 * blocks) make Q hs first (m x S), a few V_rows Q first */
	if (R > k->S) {
		dgemm_("N", "N", &mi, &Si, &mi, &one, k->z, &mi, k->hs, &mi, &zero, k->G, &mi);
		dgemm_("N", "N", &Ri, &Si, &mi, &one, u->Vr, &Ri, k->G, &mi, &zero, Y, &Ri);
		return 0;
	}
	dgemm_("N", "N", &Ri, &mi, &mi, &one, u->Vr, &Ri, k->z, &mi, &zero, k->W, &Ri);
	dgemm_("N", "N", &Ri, &Si, &mi, &one, k->W, &Ri, k->hs, &mi, &zero, Y, &Ri);
	return 0;
}

/* max_s |a_s - b_s| / max_s |a_s|, a_s the nr rows of sample s */
static double rel_change(const double *a, const double *b, size_t nr, size_t S)
{
	double num = 0, den = 0;

	for (size_t s = 0; s < S; s++) {
		double dn = 0, dd = 0;

		for (size_t r = 0; r < nr; r++) {
			double x = a[r + nr * s], y = b[r + nr * s];

			dn += (x - y) * (x - y);
			dd += x * x;
		}
		num = fmax(num, dn);
		den = fmax(den, dd);
	}
	return den > 0 ? sqrt(num / den) : 0;
}

/*
 * Is run u done after its m steps (b: the next beta)?  Checked at
 * u->next_check, the next one a quarter further (at least
 * IRDM_KRYLOV_HEAD_CHECK steps), on every row of the column's blocks (an
 * off-diagonal block can converge later than the column's own); or when
 * the run has found an invariant subspace (b negligible: exact).  Its
 * rows' responses at the last check are in u->prev.
 */
static int converged(struct kh *k, struct run *u, double b, size_t R)
{
	double *swap;
	bool exact = !(b > 1e-13 * fabs(u->alpha[u->m - 1]));
	size_t gap = u->m / 4 > IRDM_KRYLOV_HEAD_CHECK ? u->m / 4 : IRDM_KRYLOV_HEAD_CHECK;

	if (!exact && u->m < u->next_check)
		return 0;
	if (ritz_rows(k, u, R, u->cur))
		return -1;
	u->change = exact ? 0 : u->open_check ? rel_change(u->cur, u->prev, R, k->S) :
						INFINITY;
	u->next_check = u->m + gap;
	if (u->change >= k->tol)
		u->open_check = u->m;
	swap = u->cur;
	u->cur = u->prev;
	u->prev = swap;
	return u->change < k->tol;
}

/* Run ax's start: P M^-1/2 e_d0 normalised into its lane of v (none at a
 * fixed DoF, or if the kept modes span it: done with a zero response). */
static void start(struct kh *k, int ax, int64_t d0)
{
	struct run *u = &k->run[ax];
	size_t n = k->n;

	u->m = 0;
	u->next_check = k->first_check;
	u->open_check = 0;
	u->b_prev = 0;
	u->change = INFINITY;
	u->beta0 = 0;
	u->done = 1;
	memset(k->x, 0, n * sizeof(double));
	if (d0 >= 0) {
		k->x[d0] = k->dinv[d0];
		project(k, k->x);
		project(k, k->x); /* twice: the first leaves rounding of the kept modes */
		for (size_t i = 0; i < n; i++)
			u->beta0 += k->x[i] * k->x[i];
		u->beta0 = sqrt(u->beta0);
		u->done = !(u->beta0 > 0);
	}
	for (size_t i = 0; i < n; i++) {
		k->v[3 * i + (size_t)ax] = u->done ? 0.0 : k->x[i] / u->beta0;
		k->vp[3 * i + (size_t)ax] = 0.0;
	}
}

/* One step of run ax after w = A v: its coefficients, its check, its next
 * vector in w's lane. */
static void step(struct kh *k, int ax, size_t R)
{
	struct run *u = &k->run[ax];
	double *v = k->v, *vp = k->vp, *w = k->w, a, b;
	size_t n = k->n, x = (size_t)ax;

	a = dot3(w, v, n, ax);
	for (size_t i = 0; i < n; i++)
		w[3 * i + x] -= a * v[3 * i + x] + u->b_prev * vp[3 * i + x];
	b = sqrt(dot3(w, w, n, ax));
	u->alpha[u->m++] = a;
	u->done = converged(k, u, b, R);
	if (u->done) {
		for (size_t i = 0; i < n; i++)
			w[3 * i + x] = 0.0; /* its lane rests */
		return;
	}
	u->beta[u->m - 1] = b;
	for (size_t i = 0; i < n; i++)
		w[3 * i + x] /= b;
	u->b_prev = b;
}

/*
 * The three runs of a column from its free DoFs d0[0..2] side by side,
 * their vectors kept at rdofs[0..R-1], until each is done or k->m_max
 * steps.
 * Return: 0; IRDM_ENUMERIC one not converged or LAPACK failed.
 */
static int run_column(struct kh *k, const int64_t *d0, const int64_t *rdofs, size_t R)
{
	size_t steps = 0, hint = 0;
	int ret = 0;

	for (int ax = 0; ax < 3; ax++)
		start(k, ax, d0[ax]);
	while (steps++ < k->m_max && !(k->run[0].done && k->run[1].done && k->run[2].done)) {
		double *tmp;

		for (int ax = 0; ax < 3; ax++)
			for (size_t r = 0; !k->run[ax].done && r < R; r++)
				k->run[ax].Vr[k->run[ax].m * R + r] =
					rdofs[r] < 0 ? 0.0 : k->v[3 * (size_t)rdofs[r] + (size_t)ax];
		apply_a3(k, k->v, k->w);
		for (int ax = 0; ax < 3; ax++)
			if (!k->run[ax].done)
				step(k, ax, R);
		tmp = k->vp;
		k->vp = k->v;
		k->v = k->w;
		k->w = tmp;
	}
	for (int ax = 0; ax < 3; ax++) {
		struct run *u = &k->run[ax];

		if (!u->m)
			continue; /* a fixed DoF: no run */
		if (u->done != 1)
			ret = IRDM_ENUMERIC;
		k->st.runs++;
		k->st.steps_sum += u->m;
		k->st.steps_max = u->m > k->st.steps_max ? u->m : k->st.steps_max;
		k->st.last_change = fmax(k->st.last_change, u->change);
		if (u->done == 1 && u->open_check && (!hint || u->open_check < hint))
			hint = u->open_check;
	}
	/* the earliest: a run that met a transient jump in its checks (a
	 * Ritz value appearing) does not delay the next columns */
	k->hint = hint;
	return ret;
}

/* Column c's blocks from its first computed one: its three runs, each
 * read from its last check. */
static int column(struct kh *k, const struct irdm_corr_sparse *corr, const int64_t *col_dofs,
		  size_t c, int64_t *rdofs, double *head)
{
	uint32_t k0 = irdm_head_upper_begin(corr, c), nb = corr->start[c + 1] - k0;
	long kd = irdm_corr_sparse_find(corr, c, (uint32_t)c);
	size_t R = 3 * (size_t)nb, S = k->S;
	int ret;

	if (kd < (long)k0)
		return IRDM_EINVAL; /* the diagonal block is always kept */
	for (uint32_t b = 0; b < nb; b++)
		for (int i = 0; i < 3; i++)
			rdofs[3 * b + (uint32_t)i] = col_dofs[3 * (size_t)corr->rows[k0 + b] + (size_t)i];
	ret = run_column(k, &col_dofs[3 * c], rdofs, R);
	for (int j = 0; !ret && j < 3; j++) {
		const struct run *u = &k->run[j];

		for (uint32_t b = 0; b < nb; b++)
			for (size_t s = 0; s < S; s++)
				for (int i = 0; i < 3; i++) {
					int64_t r = rdofs[3 * b + (uint32_t)i];

					head[((size_t)(k0 + b) * S + s) * 9 + 3 * (size_t)i + (size_t)j] =
						!u->m || r < 0 ? 0.0 : k->dinv[r] * u->prev[3 * b + (size_t)i + R * s];
				}
	}
	return ret;
}

static void kh_free(struct kh *k)
{
	free(k->dinv);
	free(k->msq);
	free(k->v);
	free(k->vp);
	free(k->w);
	free(k->t);
	free(k->x);
	free(k->coef);
	for (int ax = 0; ax < 3; ax++) {
		free(k->run[ax].alpha);
		free(k->run[ax].beta);
		free(k->run[ax].Vr);
		free(k->run[ax].cur);
		free(k->run[ax].prev);
	}
	free(k->d);
	free(k->e);
	free(k->z);
	free(k->work);
	free(k->iwork);
	free(k->hs);
	free(k->W);
	free(k->G);
	free(k->zoh);
	free(k->hd);
}

static int kh_alloc(struct kh *k, size_t R_max)
{
	size_t n = k->n, m = k->m_max, S = k->S;
	bool ok = true;

	k->lwork = (int)(1 + 4 * m + m * m);
	k->liwork = (int)(3 + 5 * m);
	k->dinv = malloc(n * sizeof(double));
	k->msq = malloc(n * sizeof(double));
	k->v = malloc(3 * n * sizeof(double));
	k->vp = malloc(3 * n * sizeof(double));
	k->w = malloc(3 * n * sizeof(double));
	k->t = malloc(3 * n * sizeof(double));
	k->x = malloc(n * sizeof(double));
	k->coef = malloc(k->kept->n_modes * sizeof(double));
	for (int ax = 0; ax < 3; ax++) {
		struct run *u = &k->run[ax];

		u->alpha = malloc(m * sizeof(double));
		u->beta = malloc(m * sizeof(double));
		u->Vr = malloc(R_max * m * sizeof(double));
		u->cur = malloc(R_max * S * sizeof(double));
		u->prev = malloc(R_max * S * sizeof(double));
		ok = ok && u->alpha && u->beta && u->Vr && u->cur && u->prev;
	}
	k->d = malloc(m * sizeof(double));
	k->e = malloc(m * sizeof(double));
	k->z = malloc(m * m * sizeof(double));
	k->work = malloc((size_t)k->lwork * sizeof(double));
	k->iwork = malloc((size_t)k->liwork * sizeof(int));
	k->hs = malloc(m * S * sizeof(double));
	k->W = malloc(R_max * m * sizeof(double));
	k->G = malloc(m * S * sizeof(double));
	k->zoh = malloc(m * sizeof(*k->zoh));
	k->hd = malloc(S * sizeof(double));
	for (size_t i = 0; k->dinv && k->msq && i < n; i++) {
		k->msq[i] = sqrt(k->fem->M.val[k->fem->M.colptr[i]]);
		k->dinv[i] = 1 / k->msq[i];
	}
	ok = ok && k->dinv && k->msq && k->v && k->vp && k->w && k->t && k->x && k->coef && k->d &&
	     k->e && k->z && k->work && k->iwork && k->hs && k->W && k->G && k->zoh && k->hd;
	return ok ? 0 : IRDM_ENOMEM;
}

/* What every worker reads. */
struct kh_in {
	const struct irdm_fem *fem;
	const struct irdm_modes *kept;
	const struct irdm_rayleigh *damp;
	double dt;
	size_t S;
	const struct irdm_krylov_head_opts *o;
};

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
		ret = column(&w->k, p->corr, p->col_dofs, c, w->rdofs, p->head);
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

/* Worker w's scratch for rows of up to R_max. */
static int worker_init(struct worker *w, struct pool *p, const struct kh_in *in,
		       size_t R_max)
{
	w->k = (struct kh){ .fem = in->fem, .kept = in->kept, .damp = in->damp, .dt = in->dt, .n = in->fem->K.n, .S = in->S, .m_max = in->o->max_steps, .tol = in->o->tol, .first_check = FIRST_CHECK };
	w->p = p;
	w->rdofs = malloc(R_max * sizeof(int64_t));
	return kh_alloc(&w->k, R_max) || !w->rdofs ? IRDM_ENOMEM : 0;
}

static void worker_free(struct worker *w, struct irdm_krylov_head_stats *st)
{
	if (st)
		merge_stats(st, &w->k.st);
	kh_free(&w->k);
	free(w->rdofs);
}

/* The first column on this thread, its checks setting every worker's
 * first check; the pool goes on from the second. */
static void first_column(struct pool *p, struct worker *w, unsigned nt)
{
	size_t c = atomic_fetch_add(&p->next, 1);
	int ret;

	if (c >= p->corr->n_cols)
		return;
	ret = column(&w[0].k, p->corr, p->col_dofs, c, w[0].rdofs, p->head);
	if (ret) {
		p->fail_col = c;
		p->fail_ret = ret;
		atomic_store(&p->failed, 1);
		return;
	}
	atomic_fetch_add(&p->done, 1);
	for (unsigned t = 0; t < nt; t++)
		w[t].k.first_check = w[0].k.hint > FIRST_CHECK ? w[0].k.hint : FIRST_CHECK;
}

/* The columns' runs over nt threads. */
static int run_pool(struct pool *p, struct worker *w, unsigned nt, irdm_progress_fn progress,
		    void *ctx, char *err, size_t errlen)
{
	pthread_t th[KH_THREADS_MAX];
	unsigned started = 0;
	int ret = 0, blas;

	/* one thread per run: OpenBLAS's own threads would oversubscribe */
	blas = irdm_blas_serial_begin();
	first_column(p, w, nt);
	for (unsigned t = 0; t < nt && !ret && !atomic_load(&p->failed); t++, started++)
		if (pthread_create(&th[t], NULL, work, &w[t])) {
			atomic_store(&p->failed, 1);
			snprintf(err, errlen, "krylov head: cannot start a thread");
			ret = IRDM_ENOMEM;
			break;
		}
	progress_wait(p, th, started, progress, ctx);
	irdm_blas_serial_end(blas);
	if (!ret && atomic_load(&p->failed)) {
		ret = p->fail_ret == IRDM_EINVAL ? IRDM_EINVAL : IRDM_ENUMERIC;
		snprintf(err, errlen, ret == IRDM_EINVAL ? "krylov head: column %zu has no diagonal block" : "krylov head: column %zu: the Lanczos run did not converge to %g in %zu steps",
			 p->fail_col, w[0].k.tol, w[0].k.m_max);
	}
	return ret;
}

int irdm_krylov_head(const struct irdm_fem *fem, const struct irdm_modes *kept,
		     const struct irdm_rayleigh *damping, double dt_s, const int64_t *col_dofs,
		     const struct irdm_corr_sparse *corr, const double *target, size_t H,
		     const struct irdm_krylov_head_opts *o, irdm_progress_fn progress, void *ctx, double *head,
		     struct irdm_krylov_head_stats *st, char *err, size_t errlen)
{
	struct pool p = { .corr = corr, .col_dofs = col_dofs, .head = head, .lock = PTHREAD_MUTEX_INITIALIZER };
	struct kh_in in = { fem, kept, damping, dt_s, 2 * H, o };
	struct worker w[KH_THREADS_MAX];
	unsigned nt = n_workers(o->threads, corr->n_cols), ready = 0;
	size_t R_max = 3, S = 2 * H;
	int ret = 0;

	if (st)
		memset(st, 0, sizeof(*st));
	if (fem->M.nnz != fem->M.n || !kept->n_modes || !kept->phi || H < 1 || o->max_steps < 2) {
		snprintf(err, errlen, "krylov head: needs a lumped mass, kept modes and a head (H = %zu)", H);
		return IRDM_EINVAL;
	}
	for (size_t c = 0; c < corr->n_cols; c++) {
		size_t R = 3 * (size_t)(corr->start[c + 1] - irdm_head_upper_begin(corr, c));
		R_max = R > R_max ? R : R_max;
	}
	atomic_init(&p.next, 0);
	atomic_init(&p.done, 0);
	atomic_init(&p.failed, 0);
	for (; ready < nt; ready++)
		if (worker_init(&w[ready], &p, &in, R_max)) {
			snprintf(err, errlen, "krylov head: out of memory (%zu rows of %zu steps, %u threads)",
				 R_max, o->max_steps, nt);
			ret = IRDM_ENOMEM;
			ready++; /* what it did allocate is freed below */
			break;
		}
	if (!ret)
		ret = run_pool(&p, w, nt, progress, ctx, err, errlen);
	if (!ret) {
		for (size_t c = 0; c < corr->n_cols; c++)
			irdm_head_mirror(corr, c, irdm_head_upper_begin(corr, c), S, head);
		for (size_t b = 0; b < corr->n_blocks; b++)
			irdm_head_taper(&head[b * S * 9], H, &target[9 * b]);
	}
	for (unsigned t = 0; t < ready; t++)
		worker_free(&w[t], st);
	return ret;
}
