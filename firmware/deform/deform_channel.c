/* SPDX-License-Identifier: MIT */
/*
 * Deformation channel: its memory, and the lock-free triple buffer between
 * the force tick (writer: publish) and the worker (reader: take).
 */
#include <limits.h>
#include <stdio.h>

#include "irdm/deform_channel.h"

struct deform_layout {
	size_t payload_off, slot_bytes;
	size_t off_slot, total;
};

/* Whether the image has a history the snapshots can hold. */
static bool image_usable(const struct irdm_image *img)
{
	const struct irdm_meta *m = img ? img->meta : NULL;

	if (!m)
		return false;
	if (m->representation == IRDM_REPR_MODAL)
		return m->n_modes >= 1 && m->n_modes <= INT_MAX / 2;
	if (m->representation == IRDM_REPR_FIR)
		return m->fir_length >= 1;
	return false;
}

static void deform_layout(const struct irdm_image *img, struct deform_layout *l)
{
	const struct irdm_meta *m = img->meta;
	size_t payload;

	l->payload_off = deform_align_up(sizeof(struct deform_snap));
	payload = m->representation == IRDM_REPR_MODAL ?
			  2 * (size_t)m->n_modes * sizeof(double) :
			  (size_t)m->fir_length * sizeof(struct irdm_force_tick);
	l->slot_bytes = deform_align_up(l->payload_off + payload);
	l->off_slot = deform_align_up(sizeof(struct irdm_deform));
	l->total = l->off_slot + 3 * l->slot_bytes;
}

size_t irdm_deform_mem_size(const struct irdm_image *img)
{
	struct deform_layout l;

	if (!image_usable(img))
		return 0;
	deform_layout(img, &l);
	return l.total + DEFORM_ALIGN; /* room to align the caller's memory */
}

int irdm_deform_init(struct irdm_deform **dp, const struct irdm_image *img, void *mem,
		     size_t mem_size, char *err, size_t errlen)
{
	const struct irdm_meta *m;
	struct deform_layout l;
	struct irdm_deform *d;
	unsigned char *base;

	*dp = NULL;
	if (!image_usable(img)) {
		snprintf(err, errlen, "deform: image is not a usable FIR or modal image");
		return IRDM_EINVAL;
	}
	deform_layout(img, &l);
	base = deform_place(mem, mem_size, l.total);
	if (!base) {
		snprintf(err, errlen, "deform: %zu bytes of memory given, %zu needed", mem_size,
			 irdm_deform_mem_size(img));
		return IRDM_ENOMEM;
	}
	m = img->meta;
	d = (struct irdm_deform *)base;
	d->img = img;
	d->repr = m->representation;
	d->n_modes = d->repr == IRDM_REPR_MODAL ? m->n_modes : 0;
	d->T = d->repr == IRDM_REPR_FIR ? m->fir_length : 0;
	d->slot_bytes = l.slot_bytes;
	d->payload_off = l.payload_off;
	for (int i = 0; i < 3; i++)
		d->slot[i] = base + l.off_slot + (size_t)i * l.slot_bytes;
	d->front = 0;
	atomic_init(&d->mid, 1u);
	d->back = 2;
	*dp = d;
	return IRDM_OK;
}

/*
 * Hand the filled back slot over.  Release: the slot's contents are visible
 * to whoever acquires the index.  Acquire: the slot we get back was released
 * by the reader, whose reads of it are over.
 */
static void swap_back(struct irdm_deform *d)
{
	uint32_t old = atomic_exchange_explicit(&d->mid, d->back | TB_FRESH,
						memory_order_acq_rel);

	d->back = old & TB_INDEX;
}

struct deform_snap *deform_take(struct irdm_deform *d)
{
	uint32_t old;

	/* only the writer sets the bit, only we clear it: a set bit stays set */
	if (!(atomic_load_explicit(&d->mid, memory_order_relaxed) & TB_FRESH))
		return NULL;
	old = atomic_exchange_explicit(&d->mid, d->front, memory_order_acq_rel);
	d->front = old & TB_INDEX;
	return (struct deform_snap *)d->slot[d->front];
}

/* Writer: the slot to fill, then swap_back() hands it over. */
static struct deform_snap *back_slot(struct irdm_deform *d)
{
	return (struct deform_snap *)d->slot[d->back];
}

/* Only the n force nodes in use are copied: that keeps a FIR publish cheap. */
static void copy_forces(struct irdm_force_tick *dst, const struct irdm_force_tick *src)
{
	uint32_t n = src ? src->n : 0;

	if (n > IRDM_MAX_FORCE_NODES)
		n = IRDM_MAX_FORCE_NODES;
	dst->n = n;
	if (!n)
		return;
	memcpy(dst->col, src->col, n * sizeof(src->col[0]));
	memcpy(dst->f_n, src->f_n, n * sizeof(src->f_n[0]));
}

static void copy_pose(struct irdm_pose *dst, const struct irdm_pose *src)
{
	static const struct irdm_pose identity = { .q = { 1, 0, 0, 0 } };

	*dst = src ? *src : identity;
}

void irdm_deform_publish_modal(struct irdm_deform *d, uint64_t tick, const double *x,
			       const struct irdm_force_tick *f, const struct irdm_pose *pose)
{
	struct deform_snap *s;

	if (d->repr != IRDM_REPR_MODAL || !x)
		return;
	s = back_slot(d);
	s->tick = tick;
	copy_pose(&s->pose, pose);
	copy_forces(&s->f, f);
	s->n_hist = 0;
	memcpy(deform_payload(d, s), x, 2 * (size_t)d->n_modes * sizeof(double));
	swap_back(d);
}

void irdm_deform_publish_fir(struct irdm_deform *d, uint64_t tick,
			     const struct irdm_fir_ring *ring, const struct irdm_pose *pose)
{
	struct irdm_force_tick *h;
	struct deform_snap *s;
	uint32_t n, idx;

	if (d->repr != IRDM_REPR_FIR || !ring || !ring->tick || !ring->T)
		return;
	s = back_slot(d);
	h = deform_payload(d, s);
	n = ring->T < d->T ? ring->T : d->T;
	idx = ring->head % ring->T;
	/* newest first, so the reader indexes R[s] and the history alike */
	for (uint32_t i = 0; i < n; i++) {
		copy_forces(&h[i], &ring->tick[idx]);
		idx = idx ? idx - 1 : ring->T - 1;
	}
	s->tick = tick;
	s->n_hist = n;
	s->f.n = 0;
	copy_pose(&s->pose, pose);
	swap_back(d);
}
