/* SPDX-License-Identifier: MIT */
/*
 * Internals of the deformation channel (deform_channel.c), shared with its
 * reader, the worker (deform_worker.c).  Nothing here needs BLAS or threads.
 */
#ifndef IRDM_DEFORM_CHANNEL_PRIV_H
#define IRDM_DEFORM_CHANNEL_PRIV_H

#include <stdatomic.h>
#include <stdbool.h>
#include <string.h>

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
	uint32_t n_hist;          /* FIR: ticks held, newest first */
	struct irdm_force_tick f; /* modal: this tick's forces */
};

struct irdm_deform {
	const struct irdm_image *img;
	uint32_t repr;
	uint32_t n_modes, T; /* modal: n_modes; FIR: T */
	size_t slot_bytes, payload_off;
	unsigned char *slot[3];

	/* one cache line each, so the two sides do not share one */
	_Alignas(DEFORM_ALIGN) _Atomic uint32_t mid;
	_Alignas(DEFORM_ALIGN) uint32_t back;  /* writer's */
	_Alignas(DEFORM_ALIGN) uint32_t front; /* reader's */
};

static inline size_t deform_align_up(size_t x)
{
	return (x + DEFORM_ALIGN - 1) & ~(size_t)(DEFORM_ALIGN - 1);
}

/*
 * Caller memory of any alignment -> its first DEFORM_ALIGN boundary, with
 * every page touched now (nothing page-faults later); NULL if `need` bytes
 * from there do not fit.
 */
static inline unsigned char *deform_place(void *mem, size_t mem_size, size_t need)
{
	uintptr_t p = (uintptr_t)mem;
	size_t pad = (size_t)(((p + DEFORM_ALIGN - 1) & ~(uintptr_t)(DEFORM_ALIGN - 1)) - p);

	if (!mem || mem_size < pad || mem_size - pad < need)
		return NULL;
	memset(mem, 0, mem_size);
	return (unsigned char *)mem + pad;
}

static inline void *deform_payload(const struct irdm_deform *d, struct deform_snap *s)
{
	return (unsigned char *)s + d->payload_off;
}

/*
 * Reader: the newest snapshot if one was published since the last take,
 * else NULL.  The slot is the reader's until its next take.
 */
struct deform_snap *deform_take(struct irdm_deform *d);

#endif
