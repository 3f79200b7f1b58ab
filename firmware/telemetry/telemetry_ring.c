/* SPDX-License-Identifier: MIT */
/*
 * The telemetry ring: one producer (the force tick), one consumer (the log
 * writer), records copied in and out of caller memory.
 *
 * head counts records pushed, tail records popped; both only grow (mod
 * 2^32, so head - tail is the fill even across the wrap) and each has one
 * writer.  The producer publishes a slot with a release store of head after
 * copying into it; the consumer's acquire load of head makes the copy
 * visible before it reads the slot.  Symmetrically the consumer's release
 * store of tail, after it copied a slot out, lets the producer's acquire
 * load of tail reuse that slot safely.  head and tail sit on separate cache
 * lines so the two sides do not bounce one line between cores on every
 * record.  No lock, no call: the tick may push.
 */
#include <stdalign.h>
#include <stdatomic.h>
#include <string.h>

#include "irdm/telemetry.h"

/* The tick must never take a lock hidden in a non-lock-free atomic. */
_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "the telemetry ring needs lock-free 32-bit atomics");
_Static_assert(ATOMIC_LLONG_LOCK_FREE == 2, "the drop counter needs lock-free 64-bit atomics");

#define CACHE_LINE 64

struct irdm_telem_ring {
	alignas(CACHE_LINE) atomic_uint head;  /* written by the producer */
	atomic_ullong drops;                   /* written by the producer */
	alignas(CACHE_LINE) atomic_uint tail;  /* written by the consumer */
	alignas(CACHE_LINE) uint32_t capacity; /* read-only after init */
	uint32_t mask;
	struct irdm_tick_record *slot;
};

static bool capacity_ok(uint32_t capacity)
{
	return capacity >= 2 && capacity <= IRDM_TELEM_RING_MAX && !(capacity & (capacity - 1));
}

size_t irdm_telem_ring_mem_size(uint32_t capacity)
{
	if (!capacity_ok(capacity))
		return 0;
	/* slack so that any mem can be aligned to a cache line inside */
	return CACHE_LINE - 1 + sizeof(struct irdm_telem_ring) +
	       (size_t)capacity * sizeof(struct irdm_tick_record);
}

int irdm_telem_ring_init(struct irdm_telem_ring **ring, void *mem, size_t mem_size,
			 uint32_t capacity)
{
	struct irdm_telem_ring *r;
	uintptr_t at;

	if (!ring)
		return IRDM_EINVAL;
	*ring = NULL;
	if (!mem || !capacity_ok(capacity))
		return IRDM_EINVAL;
	if (mem_size < irdm_telem_ring_mem_size(capacity))
		return IRDM_ENOMEM;
	at = ((uintptr_t)mem + CACHE_LINE - 1) & ~(uintptr_t)(CACHE_LINE - 1);
	r = (struct irdm_telem_ring *)at;
	memset(r, 0, sizeof(*r));
	atomic_init(&r->head, 0);
	atomic_init(&r->tail, 0);
	atomic_init(&r->drops, 0);
	r->capacity = capacity;
	r->mask = capacity - 1;
	r->slot = (struct irdm_tick_record *)(r + 1);
	*ring = r;
	return IRDM_OK;
}

int irdm_telem_ring_push(struct irdm_telem_ring *r, const struct irdm_tick_record *rec)
{
	unsigned head = atomic_load_explicit(&r->head, memory_order_relaxed);
	unsigned tail = atomic_load_explicit(&r->tail, memory_order_acquire);

	if (head - tail >= r->capacity) {
		/* only this thread writes drops: a load and a store suffice */
		atomic_store_explicit(&r->drops,
				      atomic_load_explicit(&r->drops, memory_order_relaxed) + 1,
				      memory_order_relaxed);
		return IRDM_EBUSY;
	}
	r->slot[head & r->mask] = *rec;
	atomic_store_explicit(&r->head, head + 1, memory_order_release);
	return IRDM_OK;
}

size_t irdm_telem_ring_pop(struct irdm_telem_ring *r, struct irdm_tick_record *out, size_t max)
{
	unsigned tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
	unsigned head = atomic_load_explicit(&r->head, memory_order_acquire);
	size_t n = head - tail;

	if (n > max)
		n = max;
	for (size_t i = 0; i < n; i++)
		out[i] = r->slot[(tail + (unsigned)i) & r->mask];
	atomic_store_explicit(&r->tail, tail + (unsigned)n, memory_order_release);
	return n;
}

uint64_t irdm_telem_ring_drops(const struct irdm_telem_ring *r)
{
	return atomic_load_explicit(&r->drops, memory_order_relaxed);
}

uint32_t irdm_telem_ring_used(const struct irdm_telem_ring *r)
{
	unsigned tail = atomic_load_explicit(&r->tail, memory_order_acquire);
	unsigned head = atomic_load_explicit(&r->head, memory_order_acquire);

	return head - tail;
}

uint32_t irdm_telem_ring_capacity(const struct irdm_telem_ring *r)
{
	return r->capacity;
}
