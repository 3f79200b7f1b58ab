/* SPDX-License-Identifier: MIT */
/* Internals of the deformation worker (deform_worker.c, deform_update.c,
 * deform_thread.c): the channel's reader, with BLAS and its thread. */
#ifndef IRDM_DEFORM_WORKER_PRIV_H
#define IRDM_DEFORM_WORKER_PRIV_H

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <time.h>

#include "irdm/deform_channel.h"
#include "irdm/posix/deform_worker.h"

struct irdm_deform_thread {
	pthread_t tid;
	struct irdm_deform_worker *w;
	void (*frame)(void *ctx, const double *pos_m, uint64_t tick);
	void *ctx;
	struct timespec period;
	atomic_bool stop;
	sem_t started;  /* init-time handshake only */
	int prio_errno; /* nice + 5 failed in the thread */
	bool running;
};

struct irdm_deform_worker {
	struct irdm_deform *d; /* the channel read */
	const struct irdm_image *img;
	uint32_t repr, prec;
	uint32_t n_nodes, n_cols, n_modes, T;

	/* mode shapes as a row-major (3 n_nodes) x n_modes BLAS matrix: the
	 * image's own for f32/f64, converted for f16 */
	const void *shapes;
	bool shapes_f64;
	void *y;           /* n_modes of the matrix's type */
	float *uf;         /* f32 product, 3 n_nodes */
	double *frame_pos; /* the thread's frame, 3 n_nodes */
	/* the static correction's far field (NULL without one): the weights
	 * diag(lambda) U^T f, corr_rank */
	double *far_g;
	/* the clustered correction's low-rank weights (NULL without a
	 * low-rank pair): F^T f of one pair, the header's max_rank */
	double *cl_g;

	struct irdm_deform_thread th;
};

/* Displacements (object frame) of every image node from a snapshot. */
void deform_modal(struct irdm_deform_worker *w, struct deform_snap *s, double *pos);
void deform_fir(struct irdm_deform_worker *w, struct deform_snap *s, double *pos);
/* pos += the clustered correction's displacement of every column under f
 * (deform_clusters.c); the image has STATIC_CORR_CLUSTERS. */
void deform_clusters(const struct irdm_deform_worker *w, const struct irdm_force_tick *f,
		     double *pos);
/* pos = Phi y with y as it stands: the warm-up's product. */
void deform_modal_product(struct irdm_deform_worker *w, double *pos);

#endif
