/* SPDX-License-Identifier: MIT */
/* Internals of the deformation context (firmware/deform/). */
#ifndef IRDM_DEFORM_PRIV_H
#define IRDM_DEFORM_PRIV_H

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>

#include "irdm/deform.h"

#define DEFORM_ALIGN 64u

/*
 * Triple buffer: the three slots are owned one each by the writer (back),
 * the reader (front) and nobody (the one in `mid`).  Publishing swaps back
 * and mid with one atomic exchange and sets the fresh bit; taking swaps
 * front and mid and clears it.  Neither side ever waits for the other.
 */
#define TB_FRESH 4u
#define TB_INDEX 3u

/* Head of a snapshot slot; the payload follows at payload_off. */
struct deform_snap {
	uint64_t tick;
	struct irdm_pose pose;
	uint32_t n_hist;                    /* FIR: ticks held, newest first */
	struct irdm_force_tick f;           /* modal: this tick's forces */
};

struct irdm_deform_thread {
	pthread_t tid;
	struct irdm_deform *d;
	void (*frame)(void *ctx, const double *pos_m, uint64_t tick);
	void *ctx;
	struct timespec period;
	atomic_bool stop;
	sem_t started;                      /* init-time handshake only */
	int prio_errno;                     /* nice + 5 failed in the thread */
	bool running;
};

struct irdm_deform {
	const struct irdm_image *img;
	uint32_t repr, prec;
	uint32_t n_nodes, n_cols, n_modes, T;
	size_t slot_bytes, payload_off;
	unsigned char *slot[3];

	/* mode shapes as a row-major (3 n_nodes) x n_modes BLAS matrix: the
	 * image's own for f32/f64, converted for f16 */
	const void *shapes;
	bool shapes_f64;
	void *y;                            /* n_modes of the matrix's type */
	float *uf;                          /* f32 product, 3 n_nodes */
	double *frame_pos;                  /* the thread's frame, 3 n_nodes */

	struct irdm_deform_thread th;

	/* one cache line each, so the two sides do not share one */
	_Alignas(DEFORM_ALIGN) _Atomic uint32_t mid;
	_Alignas(DEFORM_ALIGN) uint32_t back;   /* writer's */
	_Alignas(DEFORM_ALIGN) uint32_t front;  /* reader's */
};

/* Writer: the slot to fill, then hand it over. */
static inline struct deform_snap *deform_back(struct irdm_deform *d)
{
	return (struct deform_snap *)d->slot[d->back];
}

static inline void *deform_payload(struct irdm_deform *d, struct deform_snap *s)
{
	return (unsigned char *)s + d->payload_off;
}

void deform_swap_back(struct irdm_deform *d);
/* Reader: the newest snapshot if one is fresh, else NULL. */
struct deform_snap *deform_take(struct irdm_deform *d);

void deform_warmup(struct irdm_deform *d);
void deform_modal(struct irdm_deform *d, struct deform_snap *s, double *pos);
void deform_fir(struct irdm_deform *d, struct deform_snap *s, double *pos);

#endif
