/* SPDX-License-Identifier: MIT */
/*
 * The dropped modes' head from Chebyshev expansions.  The head is a
 * function of the stiffness: each dropped mode's response h_s(w^2)
 * weighted by its shape at two columns, i.e. h_s(A) with
 * A = M^-1/2 K M^-1/2 applied to P M^-1/2 e_j (P: off the kept modes).
 * On [0, lam_up], lam_up above the spectrum, h_s is entire in the
 * eigenvalue, and its Chebyshev series
 *   h_s(A) b = sum_k c_k(s) T_k(2 A / lam_up - 1) b
 * converges once k passes about w_max t / 2 (t = s dt: the series of
 * cos(w t) in T_k(x) are Bessel functions J_2k(w_max t)).  So one
 * three-term recurrence per start vector gives every sample at once, and:
 *  - the degree is known before any product with K, from the
 *    coefficients alone, with a bound on what the truncation leaves
 *    (sum of |c_k| past it, since |T_k| <= 1 on the spectrum); no
 *    run-time check, no tridiagonal eigensolve;
 *  - every run has the same length, so many columns share each pass over
 *    K (a batch), and a column's result does not depend on its batch
 *    mates or its thread (no inner products between lanes);
 *  - rounding stays small: on the spectrum |T_k| <= 1, so an error made
 *    at one step is carried on at most linearly in the steps left, about
 *    terms x eps of the response in all.
 * lam_up is Gershgorin's bound, which holds for any matrix; an eigenvalue
 * above it would make the recurrence grow, which is checked.
 *
 * A Lanczos run adapts to the start vector's spectrum and needs a little
 * fewer steps, but its stopping is a heuristic, its ghosts must be
 * filtered and each check is an eigensolve of its tridiagonal matrix.
 */
#include <complex.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fem/fem.h"
#include "modal/fft.h"
#include "modal/head_layout.h"
#include "modal/krylov_head.h"
#include "modal/lapack.h"

#define KH_THREADS_MAX 64
#define KH_BATCH 8 /* columns per pass over K */
#define KH_LANES (3 * KH_BATCH)
#define KH_CHUNK 64 /* steps whose rows go to one GEMM with the coefficients */
/* A lane whose vector grew past this factor of its start met an
 * eigenvalue above lam_up (|T_k| <= 1 on the spectrum, exact arithmetic). */
#define KH_GROWTH 2.0
/* A Chebyshev coefficient below this fraction of the largest value
 * transformed is the transform's rounding (some 2e-13). */
#define KH_NOISE (1024 * DBL_EPSILON)

/* The expansion every run shares. */
struct cheb {
	double lam_up; /* Gershgorin's bound on A's spectrum */
	double scale;  /* 2 / lam_up */
	size_t N;      /* terms kept: T_0 .. T_{N-1} */
	size_t S;      /* samples computed exactly */
	size_t S_out;  /* samples of a head (2H): the rest are 0 before the taper */
	double *C;     /* c_k(s): N x S, column-major */
	double tail;   /* sum of max_s |c_k(s)| past N, over the largest dropped response */
};

/* What every worker reads. */
struct kh_in {
	const struct irdm_fem *fem;
	const struct irdm_modes *kept;
	const struct irdm_corr_sparse *corr;
	const int64_t *col_dofs;
	const struct cheb *ch;
	double *dinv, *msq; /* M^-1/2, M^1/2: n */
	size_t n;
};

/* One lane: a column's axis. */
struct lane {
	int axis;
	bool live;     /* a start vector (not a fixed DoF, not spanned by the kept modes) */
	double norm0;  /* its start's norm */
	uint32_t k0;   /* its column's first block to compute */
	size_t R;      /* rows: 3 per block from k0 */
	int64_t *rdof; /* R_max */
	double *Vb;    /* its rows over a chunk of steps: R x KH_CHUNK */
	double *Y;     /* h_s(A) b at its rows: R x S */
};

struct kh {
	const struct kh_in *in;
	size_t L;               /* lanes of this batch */
	double *x, *xp, *w, *t; /* the lanes' vectors interleaved [i][lane]: n L each */
	double *coef, *corrv;   /* the projection's: L x K, L x n */
	struct lane lane[KH_LANES];
};

/* y += K t for L interleaved vectors.  Inlined with L a constant (a full
 * batch), the lane loop is vectorised; the sums and their order are the
 * same either way. */
static inline void spmm(const struct irdm_csc *K, const double *restrict t, double *restrict y,
			size_t L)
{
	for (size_t j = 0; j < K->n; j++) {
		const double *tj = &t[j * L];

		for (int64_t q = K->colptr[j]; q < K->colptr[j + 1]; q++) {
			double *yi = &y[(size_t)K->rowind[q] * L], kv = K->val[q];

			for (size_t l = 0; l < L; l++)
				yi[l] += kv * tj[l];
		}
	}
}

/* y = A x for the L interleaved vectors at once: K is read once for all. */
static void apply_a(const struct kh *k, const double *x, double *y)
{
	const struct irdm_csc *K = &k->in->fem->K;
	const double *dinv = k->in->dinv;
	size_t n = k->in->n, L = k->L;

	for (size_t i = 0; i < n; i++)
		for (size_t l = 0; l < L; l++)
			k->t[i * L + l] = dinv[i] * x[i * L + l];
	memset(y, 0, n * L * sizeof(double));
	if (L == KH_LANES)
		spmm(K, k->t, y, KH_LANES);
	else
		spmm(K, k->t, y, L);
	for (size_t i = 0; i < n; i++)
		for (size_t l = 0; l < L; l++)
			y[i * L + l] *= dinv[i];
}

/* x -= Psi Psi^T x for the L lanes, Psi = M^1/2 Phi (orthonormal): off the
 * kept modes, as two GEMMs over the lanes. */
static void project(const struct kh *k, double *x)
{
	const struct irdm_modes *p = k->in->kept;
	int n = (int)k->in->n, K = (int)p->n_modes, L = (int)k->L;
	double one = 1.0, zero = 0.0;

	for (size_t i = 0; i < k->in->n; i++)
		for (size_t l = 0; l < k->L; l++)
			k->t[i * k->L + l] = k->in->msq[i] * x[i * k->L + l];
	dgemm_("N", "N", &L, &K, &n, &one, k->t, &L, p->phi, &n, &zero, k->coef, &L);
	dgemm_("N", "T", &L, &n, &K, &one, k->coef, &L, p->phi, &n, &zero, k->corrv, &L);
	for (size_t i = 0; i < k->in->n; i++)
		for (size_t l = 0; l < k->L; l++)
			x[i * k->L + l] -= k->in->msq[i] * k->corrv[i * k->L + l];
}

static double lane_norm(const struct kh *k, const double *x, size_t l)
{
	double s = 0;

	for (size_t i = 0; i < k->in->n; i++)
		s += x[i * k->L + l] * x[i * k->L + l];
	return sqrt(s);
}

/* The batch's lanes for columns c0 .. c0 + nc - 1 and their starts
 * P M^-1/2 e_d in x. */
static void start(struct kh *k, size_t c0, size_t nc)
{
	const struct kh_in *in = k->in;
	size_t n = in->n;

	k->L = 3 * nc;
	memset(k->x, 0, n * k->L * sizeof(double));
	for (size_t l = 0; l < k->L; l++) {
		struct lane *u = &k->lane[l];
		size_t c = c0 + l / 3;
		int64_t d = in->col_dofs[3 * c + l % 3];

		u->axis = (int)(l % 3);
		u->k0 = irdm_head_upper_begin(in->corr, c);
		u->R = 3 * (size_t)(in->corr->start[c + 1] - u->k0);
		for (uint32_t b = 0; b < u->R / 3; b++)
			for (int i = 0; i < 3; i++)
				u->rdof[3 * b + (uint32_t)i] =
					in->col_dofs[3 * (size_t)in->corr->rows[u->k0 + b] + (size_t)i];
		memset(u->Y, 0, u->R * in->ch->S * sizeof(double));
		if (d >= 0)
			k->x[(size_t)d * k->L + l] = in->dinv[d];
	}
	project(k, k->x);
	project(k, k->x); /* twice: the first leaves rounding of the kept modes */
	for (size_t l = 0; l < k->L; l++) {
		struct lane *u = &k->lane[l];

		u->norm0 = lane_norm(k, k->x, l);
		u->live = u->norm0 > 0;
	}
}

/* Step k's vector's rows into each lane's chunk buffer; a full chunk (or
 * the last step) is summed into Y with the chunk's coefficients. */
static void gather(struct kh *k, const double *x, size_t step)
{
	const struct cheb *ch = k->in->ch;
	size_t j = step % KH_CHUNK;
	bool flush = j == KH_CHUNK - 1 || step == ch->N - 1;

	for (size_t l = 0; l < k->L; l++) {
		struct lane *u = &k->lane[l];

		if (!u->live)
			continue;
		for (size_t r = 0; r < u->R; r++)
			u->Vb[r + u->R * j] = u->rdof[r] < 0 ? 0.0 : x[(size_t)u->rdof[r] * k->L + l];
		if (flush) {
			int R = (int)u->R, S = (int)ch->S, m = (int)j + 1, ldc = (int)ch->N;
			double one = 1.0;

			dgemm_("N", "N", &R, &S, &m, &one, u->Vb, &R, &ch->C[step - j], &ldc, &one,
			       u->Y, &R);
		}
	}
}

/* Has a lane grown (an eigenvalue above lam_up)?  Checked once a chunk. */
static bool grew(const struct kh *k, const double *x)
{
	for (size_t l = 0; l < k->L; l++)
		if (k->lane[l].live && lane_norm(k, x, l) > KH_GROWTH * k->lane[l].norm0)
			return true;
	return false;
}

/*
 * The batch's recurrence: x_0 = b, x_1 = B b, x_{k+1} = 2 B x_k - x_{k-1},
 * B = scale A - I, each step's rows summed with c_k.
 * Return: 0; IRDM_ENUMERIC a lane grew.
 */
static int recur(struct kh *k)
{
	const struct cheb *ch = k->in->ch;
	size_t nL = k->in->n * k->L;
	double *tmp;

	gather(k, k->x, 0);
	if (ch->N < 2)
		return 0;
	apply_a(k, k->x, k->w);
	for (size_t i = 0; i < nL; i++)
		k->w[i] = ch->scale * k->w[i] - k->x[i];
	tmp = k->xp, k->xp = k->x, k->x = k->w, k->w = tmp;
	gather(k, k->x, 1);
	for (size_t step = 2; step < ch->N; step++) {
		apply_a(k, k->x, k->w);
		for (size_t i = 0; i < nL; i++)
			k->w[i] = 2 * (ch->scale * k->w[i] - k->x[i]) - k->xp[i];
		tmp = k->xp, k->xp = k->x, k->x = k->w, k->w = tmp;
		gather(k, k->x, step);
		if (step % KH_CHUNK == 0 && grew(k, k->x))
			return IRDM_ENUMERIC;
	}
	return grew(k, k->x) ? IRDM_ENUMERIC : 0;
}

/* The lanes' rows into the head: block (k0 + b), sample s, [i][axis]. */
static void store(const struct kh *k, double *head)
{
	const struct kh_in *in = k->in;
	size_t S = in->ch->S, So = in->ch->S_out;

	for (size_t l = 0; l < k->L; l++) {
		const struct lane *u = &k->lane[l];

		for (uint32_t b = 0; b < u->R / 3; b++)
			for (size_t s = 0; s < So; s++)
				for (int i = 0; i < 3; i++) {
					int64_t r = u->rdof[3 * b + (uint32_t)i];
					double v = !u->live || r < 0 || s >= S ?
							   0.0 :
							   in->dinv[r] * u->Y[3 * b + (size_t)i + u->R * s];

					head[((size_t)(u->k0 + b) * So + s) * 9 + 3 * (size_t)i +
					     (size_t)u->axis] = v;
				}
	}
}

/* Gershgorin's bound: every eigenvalue is at most the largest absolute
 * row sum (the same arithmetic as the runs' 1 / sqrt(M_ii)). */
double irdm_krylov_spectrum_bound(const struct irdm_fem *fem)
{
	const struct irdm_csc *K = &fem->K, *M = &fem->M;
	double up = 0;

	for (size_t j = 0; j < K->n; j++) {
		double s = 0;

		for (int64_t q = K->colptr[j]; q < K->colptr[j + 1]; q++)
			s += fabs(K->val[q]) * (1 / sqrt(M->val[M->colptr[K->rowind[q]]]));
		up = fmax(up, s * (1 / sqrt(M->val[M->colptr[j]])));
	}
	return up;
}

/* Each mode's response h_s(lam) at the Chebyshev points
 * lam_j = lam_up (1 + cos(pi (j + 1/2) / Nc)) / 2: F[s Nc + j]; the
 * largest |h| at all of them and at those of the dropped modes. */
static int responses_at_points(const struct irdm_rayleigh *damp, double dt, double lam_up,
			       size_t Nc, size_t S, double *F, double *all_max, double *dropped_max,
			       double lam_kept)
{
	double *h = malloc(S * sizeof(double));

	if (!h)
		return IRDM_ENOMEM;
	*all_max = *dropped_max = 0;
	for (size_t j = 0; j < Nc; j++) {
		double lam = lam_up * (1 + cos(M_PI * ((double)j + 0.5) / (double)Nc)) / 2;
		double w = sqrt(lam);
		struct irdm_mode md;

		irdm_zoh_mode(w, irdm_rayleigh_ratio(damp, w), dt, &md);
		irdm_zoh_response(&md, S, h);
		for (size_t s = 0; s < S; s++) {
			F[s * Nc + j] = h[s];
			*all_max = fmax(*all_max, fabs(h[s]));
			if (lam >= lam_kept)
				*dropped_max = fmax(*dropped_max, fabs(h[s]));
		}
	}
	free(h);
	return 0;
}

/* c_k(s) = (2 - [k = 0]) / Nc sum_j F[s][j] cos(pi k (j + 1/2) / Nc), k < Nc,
 * by an FFT of the even extension (2 Nc points). */
static int dct(const double *F, size_t Nc, size_t S, double *Cfull)
{
	double complex *y = malloc(2 * Nc * sizeof(*y));

	if (!y)
		return IRDM_ENOMEM;
	for (size_t s = 0; s < S; s++) {
		const double *f = &F[s * Nc];

		for (size_t j = 0; j < Nc; j++)
			y[j] = y[2 * Nc - 1 - j] = f[j];
		irdm_fft_inverse_sign(y, 2 * Nc);
		for (size_t k = 0; k < Nc; k++) {
			double v = creal(cexp(I * M_PI * (double)k / (2.0 * (double)Nc)) * y[k]) / 2;
			Cfull[k * S + s] = (k ? 2.0 : 1.0) * v / (double)Nc;
		}
	}
	free(y);
	return 0;
}

/*
 * The fewest terms N whose tail (sum over k >= N of max_s |c_k(s)|) is
 * within tol of the largest dropped response; coefficients at the
 * rounding level of the largest value, noise of the transform (a slow
 * mode's response can be a hundred times a dropped one's), count as 0.
 */
static size_t cut(const double *Cf, size_t Nc, size_t S, double tol, double fmax_d, double fmax_all,
		  double *tail)
{
	double floor = KH_NOISE * fmax_all;
	size_t N = Nc;

	*tail = 0;
	for (; N > 1; N--) {
		double cmax = 0;

		for (size_t s = 0; s < S; s++)
			cmax = fmax(cmax, fabs(Cf[(N - 1) * S + s]));
		cmax = fmax(cmax - floor, 0);
		if (*tail + cmax > tol * fmax_d)
			break;
		*tail += cmax;
	}
	*tail = fmax_d > 0 ? *tail / fmax_d : 0;
	return N;
}

/* Cf (k-major, Nc x S) cut to N terms into ch->C (column-major N x S). */
static int keep_terms(struct cheb *ch, const double *Cf, size_t N)
{
	ch->N = N;
	ch->C = malloc(N * ch->S * sizeof(double));
	if (!ch->C)
		return IRDM_ENOMEM;
	for (size_t k = 0; k < N; k++)
		for (size_t s = 0; s < ch->S; s++)
			ch->C[k + N * s] = Cf[k * ch->S + s];
	return 0;
}

/*
 * The expansion for samples [0, S) to tol of the largest dropped response
 * (at an eigenvalue at or above the highest kept mode's): the points
 * double until the coefficients have died out well before the last one
 * (no aliasing), up to max_terms.
 */
static int expansion(struct cheb *ch, const struct irdm_rayleigh *damp, double dt, double lam_kept,
		     double tol, size_t max_terms, char *err, size_t errlen)
{
	double w_up = sqrt(ch->lam_up), t = (double)(ch->S ? ch->S - 1 : 0) * dt;
	size_t need = (size_t)(0.5 * w_up * t) + 64, Nc = 256;

	if (need > max_terms) {
		ch->N = need;
		return IRDM_ENUMERIC;
	}
	while (Nc < 2 * need)
		Nc *= 2;
	for (;; Nc *= 2) {
		double *F = malloc(Nc * ch->S * sizeof(double));
		double *Cf = malloc(Nc * ch->S * sizeof(double));
		double fmax_all, fmax_d;
		size_t N;
		int ret = !F || !Cf ? IRDM_ENOMEM : 0;

		if (!ret)
			ret = responses_at_points(damp, dt, ch->lam_up, Nc, ch->S, F, &fmax_all,
						  &fmax_d, lam_kept);
		if (!ret)
			ret = dct(F, Nc, ch->S, Cf);
		free(F);
		if (ret) {
			free(Cf);
			snprintf(err, errlen, "krylov head: out of memory for %zu Chebyshev points", Nc);
			return IRDM_ENOMEM;
		}
		N = cut(Cf, Nc, ch->S, tol, fmax_d, fmax_all, &ch->tail);
		if (4 * N <= 3 * Nc && N <= max_terms) {
			ret = keep_terms(ch, Cf, N);
			free(Cf);
			if (ret)
				snprintf(err, errlen, "krylov head: out of memory for %zu coefficients", N);
			return ret;
		}
		free(Cf);
		if (4 * N <= 3 * Nc || Nc >= 4 * max_terms) {
			ch->N = N;
			return IRDM_ENUMERIC;
		}
	}
}

/* Columns in batches over threads; the first failure stops the others. */
struct pool {
	const struct kh_in *in;
	double *head;
	size_t n_batches;
	atomic_size_t next, done;
	atomic_int failed;
	size_t fail_batch;
	pthread_mutex_t lock;
};

struct worker {
	struct kh k;
	struct pool *p;
};

static int batch(struct worker *w, size_t bi)
{
	size_t nc_all = w->p->in->corr->n_cols, c0 = bi * KH_BATCH;
	size_t nc = nc_all - c0 < KH_BATCH ? nc_all - c0 : KH_BATCH;
	int ret;

	start(&w->k, c0, nc);
	ret = recur(&w->k);
	if (!ret)
		store(&w->k, w->p->head);
	return ret;
}

static void *work(void *arg)
{
	struct worker *w = arg;
	struct pool *p = w->p;

	while (!atomic_load(&p->failed)) {
		size_t bi = atomic_fetch_add(&p->next, 1);

		if (bi >= p->n_batches)
			break;
		if (batch(w, bi)) {
			pthread_mutex_lock(&p->lock);
			if (!atomic_load(&p->failed)) {
				p->fail_batch = bi;
				atomic_store(&p->failed, 1);
			}
			pthread_mutex_unlock(&p->lock);
			break;
		}
		atomic_fetch_add(&p->done, 1);
	}
	return NULL;
}

static void worker_free(struct worker *w)
{
	free(w->k.x);
	free(w->k.xp);
	free(w->k.w);
	free(w->k.t);
	free(w->k.coef);
	free(w->k.corrv);
	for (int l = 0; l < KH_LANES; l++) {
		free(w->k.lane[l].rdof);
		free(w->k.lane[l].Vb);
		free(w->k.lane[l].Y);
	}
}

static int worker_init(struct worker *w, struct pool *p, size_t R_max)
{
	const struct kh_in *in = p->in;
	size_t nL = in->n * KH_LANES;
	bool ok;

	memset(w, 0, sizeof(*w));
	w->p = p;
	w->k.in = in;
	w->k.x = malloc(nL * sizeof(double));
	w->k.xp = malloc(nL * sizeof(double));
	w->k.w = malloc(nL * sizeof(double));
	w->k.t = malloc(nL * sizeof(double));
	w->k.coef = malloc(KH_LANES * in->kept->n_modes * sizeof(double));
	w->k.corrv = malloc(nL * sizeof(double));
	ok = w->k.x && w->k.xp && w->k.w && w->k.t && w->k.coef && w->k.corrv;
	for (int l = 0; ok && l < KH_LANES; l++) {
		struct lane *u = &w->k.lane[l];

		u->rdof = malloc(R_max * sizeof(int64_t));
		u->Vb = malloc(R_max * KH_CHUNK * sizeof(double));
		u->Y = malloc(R_max * in->ch->S * sizeof(double));
		ok = u->rdof && u->Vb && u->Y;
	}
	return ok ? 0 : IRDM_ENOMEM;
}

static unsigned n_workers(unsigned threads, size_t n_batches)
{
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);
	size_t nt = threads ? threads : (size_t)(cpus > 0 ? cpus : 1);

	nt = nt > KH_THREADS_MAX ? KH_THREADS_MAX : nt;
	return (unsigned)(nt > n_batches ? (n_batches ? n_batches : 1) : nt);
}

static void progress_wait(struct pool *p, pthread_t *th, unsigned nt, irdm_progress_fn progress,
			  void *ctx)
{
	size_t last = 0;

	/* the caller's progress is not thread-safe: reported from here */
	while (progress && !atomic_load(&p->failed) && atomic_load(&p->done) < p->n_batches) {
		size_t d = atomic_load(&p->done);
		struct timespec ts = { 0, 100000000 };

		if (d != last)
			progress(ctx, "krylov head", (double)d / (double)p->n_batches);
		last = d;
		nanosleep(&ts, NULL);
	}
	for (unsigned t = 0; t < nt; t++)
		pthread_join(th[t], NULL);
	if (progress && !atomic_load(&p->failed))
		progress(ctx, "krylov head", 1.0);
}

static int run_pool(struct pool *p, struct worker *w, unsigned nt, irdm_progress_fn progress,
		    void *ctx, char *err, size_t errlen)
{
	pthread_t th[KH_THREADS_MAX];
	unsigned started = 0;
	int ret = 0, blas;

	/* one thread per batch: OpenBLAS's own threads would oversubscribe */
	blas = irdm_blas_serial_begin();
	for (unsigned t = 0; t < nt; t++, started++)
		if (pthread_create(&th[t], NULL, work, &w[t])) {
			atomic_store(&p->failed, 1);
			snprintf(err, errlen, "krylov head: cannot start a thread");
			ret = IRDM_ENOMEM;
			break;
		}
	progress_wait(p, th, started, progress, ctx);
	irdm_blas_serial_end(blas);
	if (!ret && atomic_load(&p->failed)) {
		snprintf(err, errlen, "krylov head: columns %zu..: a Chebyshev run grew past %g times its start (an eigenvalue above Gershgorin's bound %g: rounding)",
			 p->fail_batch * KH_BATCH, KH_GROWTH, p->in->ch->lam_up);
		ret = IRDM_ENUMERIC;
	}
	return ret;
}

static int check_args(const struct irdm_fem *fem, const struct irdm_modes *kept,
		      const struct irdm_corr_sparse *corr, size_t H,
		      const struct irdm_krylov_head_opts *o, char *err, size_t errlen)
{
	if (fem->M.nnz != fem->M.n || !kept->n_modes || !kept->phi || H < 1 || o->max_steps < 2) {
		snprintf(err, errlen, "krylov head: needs a lumped mass, kept modes and a head (H = %zu)", H);
		return IRDM_EINVAL;
	}
	for (size_t c = 0; c < corr->n_cols; c++)
		if (irdm_corr_sparse_find(corr, c, (uint32_t)c) < (long)irdm_head_upper_begin(corr, c)) {
			snprintf(err, errlen, "krylov head: column %zu has no diagonal block", c);
			return IRDM_EINVAL;
		}
	return 0;
}

/* M^-1/2, M^1/2 and the expansion. */
static int setup(struct kh_in *in, struct cheb *ch, const struct irdm_rayleigh *damping,
		 double dt_s, const struct irdm_krylov_head_opts *o, char *err, size_t errlen)
{
	const struct irdm_fem *fem = in->fem;
	double lam_kept = in->kept->omega2[in->kept->n_modes - 1];
	int ret;

	in->dinv = malloc(in->n * sizeof(double));
	in->msq = malloc(in->n * sizeof(double));
	if (!in->dinv || !in->msq) {
		snprintf(err, errlen, "krylov head: out of memory");
		return IRDM_ENOMEM;
	}
	for (size_t i = 0; i < in->n; i++) {
		in->msq[i] = sqrt(fem->M.val[fem->M.colptr[i]]);
		in->dinv[i] = 1 / in->msq[i];
	}
	ch->lam_up = irdm_krylov_spectrum_bound(fem);
	ch->scale = 2 / ch->lam_up;
	ret = expansion(ch, damping, dt_s, lam_kept, o->tol, o->max_steps, err, errlen);
	if (ret == IRDM_ENUMERIC)
		snprintf(err, errlen, "krylov head: %zu samples at dt %g s up to w = %.4g rad/s need a Chebyshev expansion of %zu terms, more than %zu",
			 ch->S, dt_s, sqrt(ch->lam_up), ch->N, o->max_steps);
	return ret;
}

int irdm_krylov_head(const struct irdm_fem *fem, const struct irdm_modes *kept,
		     const struct irdm_rayleigh *damping, double dt_s, const int64_t *col_dofs,
		     const struct irdm_corr_sparse *corr, const double *target, size_t H,
		     const struct irdm_krylov_head_opts *o, irdm_progress_fn progress, void *ctx, double *head,
		     struct irdm_krylov_head_stats *st, char *err, size_t errlen)
{
	struct cheb ch = { .S = 2 * H, .S_out = 2 * H };
	struct kh_in in = { .fem = fem, .kept = kept, .corr = corr, .col_dofs = col_dofs, .ch = &ch, .n = fem->K.n };
	struct pool p = { .in = &in, .head = head, .lock = PTHREAD_MUTEX_INITIALIZER };
	struct worker w[KH_THREADS_MAX];
	unsigned nt, ready = 0;
	size_t R_max = 3;
	int ret;

	if (st)
		memset(st, 0, sizeof(*st));
	ret = check_args(fem, kept, corr, H, o, err, errlen);
	if (ret)
		return ret;
	if (o->samples && o->samples < ch.S)
		ch.S = o->samples;
	ret = setup(&in, &ch, damping, dt_s, o, err, errlen);
	p.n_batches = (corr->n_cols + KH_BATCH - 1) / KH_BATCH;
	nt = n_workers(o->threads, p.n_batches);
	for (size_t c = 0; !ret && c < corr->n_cols; c++) {
		size_t R = 3 * (size_t)(corr->start[c + 1] - irdm_head_upper_begin(corr, c));
		R_max = R > R_max ? R : R_max;
	}
	atomic_init(&p.next, 0);
	atomic_init(&p.done, 0);
	atomic_init(&p.failed, 0);
	for (; !ret && ready < nt; ready++)
		if (worker_init(&w[ready], &p, R_max)) {
			snprintf(err, errlen, "krylov head: out of memory (%zu rows of %zu samples, %u threads)",
				 R_max, ch.S, nt);
			ret = IRDM_ENOMEM; /* the loop's step counts it: its part is freed below */
		}
	if (!ret)
		ret = run_pool(&p, w, nt, progress, ctx, err, errlen);
	if (!ret) {
		for (size_t c = 0; c < corr->n_cols; c++)
			irdm_head_mirror(corr, c, irdm_head_upper_begin(corr, c), ch.S_out, head);
		for (size_t b = 0; b < corr->n_blocks; b++)
			irdm_head_taper(&head[b * ch.S_out * 9], H, &target[9 * b]);
	}
	if (st) {
		st->runs = 3 * corr->n_cols;
		st->terms = ch.N;
		st->tail = ch.tail;
		st->lam_up = ch.lam_up;
		st->samples = ch.S;
	}
	for (unsigned t = 0; t < ready; t++)
		worker_free(&w[t]);
	free(in.dinv);
	free(in.msq);
	free(ch.C);
	return ret;
}
