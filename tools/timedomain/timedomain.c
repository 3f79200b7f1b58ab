/* SPDX-License-Identifier: MIT */
/*
 * Time-domain responses R[s] by Newmark average-acceleration integration,
 * parallel over input DoFs.  See timedomain.h for the convention.
 *
 * The step.  Newmark with beta = 1/4, gamma = 1/2 is the trapezoidal rule on
 * the state (u, v):
 *     u+ - u = h/2 (v + v+)
 *     M (v+ - v) = h/2 (f_l + f_r) - h/2 C (v + v+) - h/2 K (u + u+)
 * where f_l, f_r are the force at the step's left and right ends.  Writing
 * D = u+ - u and eliminating v+ = 2 D / h - v gives
 *     S D = h M v - h^2/2 K u + h^2/4 (f_l + f_r),   S = M + h/2 C + h^2/4 K
 *     u+ = u + D,   v+ = 2 D / h - v.
 * This is algebraically the textbook acceleration form with a_0 = M^-1 f_0,
 * but it never needs a_0 (so no second factor of a consistent M) and it
 * takes the force's jump at t = dt as it comes: every step inside [0, dt]
 * has f = 1 at both ends (the left limit at dt), every later step f = 0 at
 * both ends.  The acceleration form would have to re-solve M a = f - C v -
 * K u at the jump instead.
 *
 * Determinism.  Inputs are integrated in blocks whose sizes depend only on
 * n_in; blocks are handed to threads dynamically, but a block's arithmetic
 * does not depend on which thread runs it or how many there are, and
 * OpenBLAS runs single-threaded meanwhile, so the output is the same bit for
 * bit for any thread count.  (It may differ in the last bits between block
 * sizes: one right-hand side goes through other BLAS kernels than eight.)
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fem/factor.h"
#include "modal/lapack.h"
#include "timedomain/rigid_fit.h"
#include "timedomain/td_priv.h"
#include "timedomain/timedomain.h"

/*
 * At most this many input columns are integrated together: several
 * right-hand sides per solve run CHOLMOD's supernodal solve as BLAS-3 and
 * read the factor once for all (measured on a 2700-DoF box: 390 us per
 * column and step alone, 120 us with 8 together).  Blocks are balanced and
 * depend on n_in only (see "Determinism").
 */
#define TD_BLOCK 8

struct td_job {
	/* read-only while the workers run */
	const struct irdm_mesh *mesh;
	const struct irdm_fem *fem;
	const struct irdm_td_opts *o;
	const int64_t *in_dofs;
	size_t n_in;
	const uint32_t *out_nodes;
	size_t n_out;
	double *R;         /* a worker writes only its own inputs' slices */
	cholmod_factor *L; /* shared; CHOLMOD's solve only reads it */
	double h;
	double rel_eps;
	size_t n_blocks;
	/* shared, under lock */
	pthread_mutex_t lock;
	size_t next_block;
	size_t done;
	bool failed;
	int code; /* the first failure's IRDM_E* */
	char *err;
	size_t errlen;
};

/* Everything one thread touches: CHOLMOD's common is not thread-safe, so
 * each worker has its own, plus its own solve workspaces (y, e). */
struct td_worker {
	struct td_job *job;
	pthread_t tid;
	bool started;
	cholmod_common cc;
	cholmod_dense *b, *x, *y, *e;
	double *u, *v, *ku, *mv; /* n_free x TD_BLOCK, column-major */
	double *full, *def;      /* 3 * n_nodes, floating only */
	char err[200];
};

/* ---- validation --------------------------------------------------------- */

static int check_opts(const struct irdm_td_opts *o, char *err, size_t errlen)
{
	if (!isfinite(o->dt_s) || o->dt_s <= 0) {
		snprintf(err, errlen, "time-domain: dt must be finite and > 0 s (got %g)",
			 o->dt_s);
		return IRDM_EINVAL;
	}
	if (o->n_samples < 1 || o->substeps < 1) {
		snprintf(err, errlen,
			 "time-domain: need n_samples >= 1 and substeps >= 1 (got %u, %u)",
			 o->n_samples, o->substeps);
		return IRDM_EINVAL;
	}
	if (!isfinite(o->damping.a_per_s) || !isfinite(o->damping.b_s) ||
	    o->damping.a_per_s < 0 || o->damping.b_s < 0) {
		snprintf(err, errlen,
			 "time-domain: Rayleigh damping must be finite and >= 0 (got a=%g /s, b=%g s)",
			 o->damping.a_per_s, o->damping.b_s);
		return IRDM_EINVAL;
	}
	if (o->rigid != IRDM_TD_RIGID_KABSCH && o->rigid != IRDM_TD_RIGID_LINEAR) {
		snprintf(err, errlen, "time-domain: unknown rigid-removal method %d",
			 (int)o->rigid);
		return IRDM_EINVAL;
	}
	if (!(o->kabsch_rel_eps >= 0 && o->kabsch_rel_eps <= 1e-2)) {
		snprintf(err, errlen,
			 "time-domain: kabsch_rel_eps must be in [0, 1e-2] (0: default; got %g)",
			 o->kabsch_rel_eps);
		return IRDM_EINVAL;
	}
	return 0;
}

static int check_model(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
		       bool floating, char *err, size_t errlen)
{
	if (fem->map.n_dof != 3 * mesh->n_nodes || fem->K.n != fem->map.n_free ||
	    fem->M.n != fem->map.n_free) {
		snprintf(err, errlen,
			 "time-domain: FEM (%zu DoFs, %zu free) does not belong to the mesh (%zu nodes)",
			 fem->map.n_dof, fem->map.n_free, mesh->n_nodes);
		return IRDM_EINVAL;
	}
	if (floating && fem->map.n_free != fem->map.n_dof) {
		snprintf(err, errlen,
			 "time-domain: a floating object must have no fixed node (%zu of %zu DoFs fixed)",
			 fem->map.n_dof - fem->map.n_free, fem->map.n_dof);
		return IRDM_EINVAL;
	}
	return 0;
}

static int check_io(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
		    const struct irdm_td_opts *o, const int64_t *in_dofs, size_t n_in,
		    const uint32_t *out_nodes, size_t n_out, const double *R,
		    char *err, size_t errlen)
{
	size_t per_in = (size_t)o->n_samples * 3;

	if ((n_in && !in_dofs) || (n_out && !out_nodes) || (n_in && n_out && !R)) {
		snprintf(err, errlen, "time-domain: NULL input, output or result array");
		return IRDM_EINVAL;
	}
	if (n_out > SIZE_MAX / per_in / sizeof(double) ||
	    (n_in && n_out * per_in > SIZE_MAX / sizeof(double) / n_in)) {
		snprintf(err, errlen, "time-domain: %zu x %u x %zu responses do not fit in memory",
			 n_in, o->n_samples, n_out);
		return IRDM_EINVAL;
	}
	for (size_t i = 0; i < n_in; i++) {
		int64_t g = in_dofs[i];

		if (g < 0 || (uint64_t)g >= fem->map.n_dof) {
			snprintf(err, errlen,
				 "time-domain: input DoF %lld (entry %zu) out of range (mesh has %zu DoFs)",
				 (long long)g, i, fem->map.n_dof);
			return IRDM_EINVAL;
		}
		if (fem->map.free_of[g] < 0) {
			snprintf(err, errlen,
				 "time-domain: input DoF %lld (node %lld axis %c) is fixed; responses exist only for free DoFs",
				 (long long)g, (long long)(g / 3), "xyz"[g % 3]);
			return IRDM_EINVAL;
		}
	}
	for (size_t i = 0; i < n_out; i++) {
		if (out_nodes[i] >= mesh->n_nodes) {
			snprintf(err, errlen,
				 "time-domain: output node %u (entry %zu) out of range (mesh has %zu nodes)",
				 out_nodes[i], i, mesh->n_nodes);
			return IRDM_EINVAL;
		}
	}
	return 0;
}

/* ---- one worker ---------------------------------------------------------- */

static void worker_fini(struct td_worker *w)
{
	cholmod_l_free_dense(&w->b, &w->cc);
	cholmod_l_free_dense(&w->x, &w->cc);
	cholmod_l_free_dense(&w->y, &w->cc);
	cholmod_l_free_dense(&w->e, &w->cc);
	cholmod_l_finish(&w->cc);
	free(w->u);
	free(w->v);
	free(w->ku);
	free(w->mv);
	free(w->full);
	free(w->def);
}

static int worker_init(struct td_worker *w, struct td_job *job)
{
	size_t nb = job->fem->K.n * TD_BLOCK, nf = 3 * job->mesh->n_nodes;

	memset(w, 0, sizeof(*w));
	w->job = job;
	cholmod_l_start(&w->cc);
	w->cc.print = 0; /* errors come back through err, not stdout */
	w->u = malloc(nb * sizeof(double));
	w->v = malloc(nb * sizeof(double));
	w->ku = malloc(nb * sizeof(double));
	w->mv = malloc(nb * sizeof(double));
	if (job->o->floating) {
		w->full = malloc(nf * sizeof(double));
		w->def = malloc(nf * sizeof(double));
	}
	if (!w->u || !w->v || !w->ku || !w->mv ||
	    (job->o->floating && (!w->full || !w->def)))
		return IRDM_ENOMEM;
	return IRDM_OK;
}

/* Right-hand side holder with k columns (the last block may be short). */
static int worker_rhs(struct td_worker *w, size_t k)
{
	if (w->b && w->b->ncol == k)
		return 0;
	cholmod_l_free_dense(&w->b, &w->cc);
	w->b = cholmod_l_allocate_dense(w->job->fem->K.n, k, w->job->fem->K.n,
					CHOLMOD_REAL, &w->cc);
	if (!w->b) {
		snprintf(w->err, sizeof(w->err), "time-domain: out of memory (right-hand side)");
		return IRDM_ENOMEM;
	}
	return 0;
}

/* Rigid motion out of one full-length response column: w->def. */
static int worker_rigid(struct td_worker *w, const double *col)
{
	const struct td_job *job = w->job;
	const struct irdm_dofmap *map = &job->fem->map;
	const struct irdm_mesh *mesh = job->mesh;
	int rc;

	/* floating: every DoF is free */
	for (size_t g = 0; g < map->n_dof; g++)
		w->full[g] = col[map->free_of[g]];
	if (job->o->rigid == IRDM_TD_RIGID_LINEAR)
		rc = irdm_rigid_project_linear(mesh->n_nodes, mesh->pos_m,
					       job->fem->lumped_mass_kg, w->full, w->def);
	else
		rc = irdm_rigid_remove_kabsch(mesh->n_nodes, mesh->pos_m,
					      job->fem->lumped_mass_kg, w->full,
					      job->rel_eps, w->def);
	if (rc)
		snprintf(w->err, sizeof(w->err),
			 "time-domain: rigid-motion fit failed (collinear mesh or non-finite response)");
	return rc;
}

/* Store sample s of the k columns starting at input i0. */
static int worker_record(struct td_worker *w, size_t i0, size_t k, size_t s)
{
	const struct td_job *job = w->job;
	const int64_t *free_of = job->fem->map.free_of;
	size_t n = job->fem->K.n, no = job->n_out;

	for (size_t c = 0; c < k; c++) {
		const double *col = w->u + c * n;
		double *dst = job->R + ((i0 + c) * job->o->n_samples + s) * 3 * no;
		int ret = job->o->floating ? worker_rigid(w, col) : IRDM_OK;

		if (ret)
			return ret;
		for (size_t o = 0; o < no; o++) {
			for (size_t a = 0; a < 3; a++) {
				size_t g = 3 * (size_t)job->out_nodes[o] + a;

				if (job->o->floating)
					dst[3 * o + a] = w->def[g];
				else
					dst[3 * o + a] = free_of[g] < 0 ? 0.0 : col[free_of[g]];
			}
		}
	}
	return 0;
}

/* b = h M v - h^2/2 K u + h^2/4 (f_l + f_r) e_in, for the k columns. */
static void worker_load(struct td_worker *w, size_t i0, size_t k, double fsum)
{
	const struct td_job *job = w->job;
	const struct irdm_fem *fem = job->fem;
	size_t n = fem->K.n;
	double h = job->h, *b = w->b->x;

	irdm_td_matvec_block(&fem->K, w->u, w->ku, k);
	irdm_td_matvec_block(&fem->M, w->v, w->mv, k);
	for (size_t i = 0; i < n * k; i++)
		b[i] = h * w->mv[i] - 0.5 * h * h * w->ku[i];
	if (fsum == 0.0)
		return;
	for (size_t c = 0; c < k; c++)
		b[c * n + (size_t)fem->map.free_of[job->in_dofs[i0 + c]]] += 0.25 * h * h * fsum;
}

/* Integrate k inputs from rest over T samples. */
static int worker_block(struct td_worker *w, size_t i0, size_t k)
{
	const struct td_job *job = w->job;
	size_t n = job->fem->K.n;
	uint64_t m = job->o->substeps, steps = m * job->o->n_samples;
	double h = job->h;
	int ret;

	ret = worker_rhs(w, k);
	if (ret)
		return ret;
	memset(w->u, 0, n * k * sizeof(double));
	memset(w->v, 0, n * k * sizeof(double));
	for (uint64_t st = 0; st < steps; st++) {
		/* steps 0..m-1 lie inside [0, dt]: force 1 at both ends */
		worker_load(w, i0, k, st < m ? 2.0 : 0.0);
		if (!cholmod_l_solve2(CHOLMOD_A, job->L, w->b, NULL, &w->x, NULL, &w->y, &w->e,
				      &w->cc)) {
			snprintf(w->err, sizeof(w->err),
				 "time-domain: CHOLMOD solve failed (status %d)", w->cc.status);
			return w->cc.status == CHOLMOD_OUT_OF_MEMORY ? IRDM_ENOMEM : IRDM_ENUMERIC;
		}
		const double *d = w->x->x;

		for (size_t i = 0; i < n * k; i++) {
			w->v[i] = 2.0 * d[i] / h - w->v[i];
			w->u[i] += d[i];
		}
		if ((st + 1) % m == 0)
			ret = worker_record(w, i0, k, (size_t)((st + 1) / m - 1));
		if (ret)
			return ret;
	}
	return IRDM_OK;
}

/* Columns of block b: n_in split into n_blocks near-equal runs. */
static void block_range(const struct td_job *job, size_t b, size_t *i0, size_t *k)
{
	size_t base = job->n_in / job->n_blocks, extra = job->n_in % job->n_blocks;

	*i0 = b * base + (b < extra ? b : extra);
	*k = base + (b < extra);
}

/* Take blocks until none is left or someone failed. */
static void *worker_main(void *arg)
{
	struct td_worker *w = arg;
	struct td_job *job = w->job;

	for (;;) {
		size_t b, i0, k;

		pthread_mutex_lock(&job->lock);
		b = job->next_block++;
		if (job->failed || b >= job->n_blocks) {
			pthread_mutex_unlock(&job->lock);
			return NULL;
		}
		pthread_mutex_unlock(&job->lock);

		block_range(job, b, &i0, &k);
		int rc = worker_block(w, i0, k);

		pthread_mutex_lock(&job->lock);
		if (rc && !job->failed) {
			snprintf(job->err, job->errlen, "%s", w->err);
			job->code = rc;
		}
		job->failed |= rc != 0;
		job->done += rc ? 0 : k;
		/* under the lock: the callback is never entered concurrently */
		if (!rc && job->o->progress)
			job->o->progress(job->o->progress_ctx, job->done, job->n_in);
		pthread_mutex_unlock(&job->lock);
		if (rc)
			return NULL;
	}
}

/* ---- the job ------------------------------------------------------------- */

static unsigned thread_count(unsigned asked, size_t n_blocks)
{
	long online = sysconf(_SC_NPROCESSORS_ONLN);
	size_t t = asked ? asked : (online > 0 ? (size_t)online : 1);

	return (unsigned)(t < n_blocks ? t : n_blocks);
}

/* Run the workers: w[0] in the calling thread, the rest in new threads.  A
 * thread that cannot be created is not an error: the others take its
 * blocks from the shared queue. */
static void run_workers(struct td_worker *w, unsigned nt)
{
	int blas_threads = irdm_blas_serial_begin();

	for (unsigned t = 1; t < nt; t++)
		w[t].started = !pthread_create(&w[t].tid, NULL, worker_main, &w[t]);
	worker_main(&w[0]);
	for (unsigned t = 1; t < nt; t++)
		if (w[t].started)
			pthread_join(w[t].tid, NULL);
	irdm_blas_serial_end(blas_threads);
}

int irdm_td_responses(const struct irdm_mesh *mesh, const struct irdm_fem *fem,
		      const struct irdm_td_opts *o, const int64_t *in_dofs, size_t n_in,
		      const uint32_t *out_nodes, size_t n_out, double *R,
		      char *err, size_t errlen)
{
	struct td_job job = {
		.mesh = mesh,
		.fem = fem,
		.o = o,
		.in_dofs = in_dofs,
		.n_in = n_in,
		.out_nodes = out_nodes,
		.n_out = n_out,
		.R = R,
		.err = err,
		.errlen = errlen,
	};
	struct td_worker *w = NULL;
	cholmod_common cc;
	unsigned nt, n_init = 0;
	int rc;

	if (!mesh || !fem || !o) {
		snprintf(err, errlen, "time-domain: NULL mesh, FEM or options");
		return IRDM_EINVAL;
	}
	rc = check_opts(o, err, errlen);
	if (!rc)
		rc = check_model(mesh, fem, o->floating, err, errlen);
	if (!rc)
		rc = check_io(mesh, fem, o, in_dofs, n_in, out_nodes, n_out, R, err, errlen);
	if (rc || n_in == 0)
		return rc;
	job.h = o->dt_s / o->substeps;
	job.rel_eps = o->kabsch_rel_eps > 0 ? o->kabsch_rel_eps : IRDM_TD_KABSCH_REL_EPS;

	cholmod_l_start(&cc);
	cc.print = 0;
	/* S = M + h/2 (a M + b K) + h^2/4 K */
	/* S = M + h/2 C + h^2/4 K with C = a M + b K */
	rc = irdm_fem_factor(fem, 0.5 * job.h * o->damping.b_s + 0.25 * job.h * job.h,
			     1.0 + 0.5 * job.h * o->damping.a_per_s, "time-domain", &cc, &job.L,
			     err, errlen);
	if (rc)
		goto out_finish;
	rc = IRDM_ENOMEM;
	job.n_blocks = (n_in + TD_BLOCK - 1) / TD_BLOCK;
	nt = thread_count(o->threads, job.n_blocks);
	w = calloc(nt, sizeof(*w));
	if (!w) {
		snprintf(err, errlen, "time-domain: out of memory (%u workers)", nt);
		goto out_free_factor;
	}
	for (n_init = 0; n_init < nt; n_init++) {
		if (worker_init(&w[n_init], &job)) {
			n_init++;
			snprintf(err, errlen, "time-domain: out of memory (worker %u, %zu DoFs)",
				 n_init - 1, fem->K.n);
			goto out_free_workers;
		}
	}
	if (pthread_mutex_init(&job.lock, NULL)) {
		snprintf(err, errlen, "time-domain: cannot create a mutex");
		rc = IRDM_ETHREAD;
		goto out_free_workers;
	}
	run_workers(w, nt);
	pthread_mutex_destroy(&job.lock);
	rc = job.failed ? job.code : IRDM_OK;

out_free_workers:
	for (unsigned t = 0; t < n_init; t++)
		worker_fini(&w[t]);
	free(w);
out_free_factor:
	cholmod_l_free_factor(&job.L, &cc);
out_finish:
	cholmod_l_finish(&cc);
	return rc;
}
