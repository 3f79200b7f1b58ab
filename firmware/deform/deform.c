/* SPDX-License-Identifier: MIT */
/*
 * Deformation context: memory, the lock-free triple buffer between the force
 * tick (writer) and the deformation context (reader), and the update.
 */
#include <limits.h>
#include <stdio.h>
#include <string.h>

#include "deform_priv.h"

struct deform_layout {
	size_t payload_off, slot_bytes;
	size_t off_slot, off_y, off_uf, off_shapes, off_frame, total;
};

static size_t align_up(size_t x)
{
	return (x + DEFORM_ALIGN - 1) & ~(size_t)(DEFORM_ALIGN - 1);
}

/* Whether the image has what the update reads (the loader checked sizes). */
static bool image_usable(const struct irdm_image *img)
{
	const struct irdm_meta *m = img ? img->meta : NULL;

	if (!m || !img->nodes || m->n_nodes == 0 || !img->columns)
		return false;
	/* BLAS dimensions are int */
	if ((uint64_t)m->n_nodes * 3 > INT_MAX)
		return false;
	if (m->precision != IRDM_ELEM_F16 && m->precision != IRDM_ELEM_F32 &&
	    m->precision != IRDM_ELEM_F64)
		return false;
	if (m->representation == IRDM_REPR_MODAL)
		return m->n_modes >= 1 && m->n_modes <= INT_MAX / 2 && img->modes &&
		       img->mode_shapes;
	if (m->representation == IRDM_REPR_FIR)
		return m->fir_length >= 1 && img->fir;
	return false;
}

static void deform_layout(const struct irdm_image *img, struct deform_layout *l)
{
	const struct irdm_meta *m = img->meta;
	size_t n3 = 3 * (size_t)m->n_nodes, K = m->n_modes, payload;
	bool modal = m->representation == IRDM_REPR_MODAL;

	l->payload_off = align_up(sizeof(struct deform_snap));
	payload = modal ? 2 * K * sizeof(double) :
			  (size_t)m->fir_length * sizeof(struct irdm_force_tick);
	l->slot_bytes = align_up(l->payload_off + payload);
	l->off_slot = align_up(sizeof(struct irdm_deform));
	l->off_y = l->off_slot + 3 * l->slot_bytes;
	l->off_uf = l->off_y + (modal ? align_up(K * sizeof(double)) : 0);
	l->off_shapes = l->off_uf;
	if (modal && m->precision != IRDM_ELEM_F64)
		l->off_shapes += align_up(n3 * sizeof(float));
	l->off_frame = l->off_shapes;
	if (modal && m->precision == IRDM_ELEM_F16)
		l->off_frame += align_up(n3 * K * sizeof(float));
	l->total = l->off_frame + align_up(n3 * sizeof(double));
}

size_t irdm_deform_mem_size(const struct irdm_image *img)
{
	struct deform_layout l;

	if (!image_usable(img))
		return 0;
	deform_layout(img, &l);
	return l.total + DEFORM_ALIGN;          /* room to align the caller's memory */
}

/* BLAS takes f32 or f64: an f16 image's shapes are widened once, here. */
static const void *blas_shapes(const struct irdm_image *img, unsigned char *base,
			       const struct deform_layout *l)
{
	const struct irdm_meta *m = img->meta;
	size_t n = 3 * (size_t)m->n_nodes * m->n_modes;
	const uint16_t *h = img->mode_shapes;
	float *f = (float *)(base + l->off_shapes);

	if (m->precision != IRDM_ELEM_F16)
		return img->mode_shapes;
	for (size_t i = 0; i < n; i++)
		f[i] = irdm_f16_to_f32(h[i]);
	return f;
}

static void deform_setup(struct irdm_deform *d, const struct irdm_image *img,
			 unsigned char *base, const struct deform_layout *l)
{
	const struct irdm_meta *m = img->meta;

	d->img = img;
	d->repr = m->representation;
	d->prec = m->precision;
	d->n_nodes = m->n_nodes;
	d->n_cols = m->n_cols;
	d->n_modes = m->representation == IRDM_REPR_MODAL ? m->n_modes : 0;
	d->T = m->representation == IRDM_REPR_FIR ? m->fir_length : 0;
	d->slot_bytes = l->slot_bytes;
	d->payload_off = l->payload_off;
	for (int i = 0; i < 3; i++)
		d->slot[i] = base + l->off_slot + (size_t)i * l->slot_bytes;
	if (d->repr == IRDM_REPR_MODAL) {
		d->shapes = blas_shapes(img, base, l);
		d->shapes_f64 = m->precision == IRDM_ELEM_F64;
		d->y = base + l->off_y;
		d->uf = d->shapes_f64 ? NULL : (float *)(base + l->off_uf);
	}
	d->frame_pos = (double *)(base + l->off_frame);
	d->front = 0;
	atomic_init(&d->mid, 1u);
	d->back = 2;
}

int irdm_deform_init(struct irdm_deform **d, const struct irdm_image *img, void *mem,
		     size_t mem_size, char *err, size_t errlen)
{
	struct deform_layout l;
	uintptr_t p = (uintptr_t)mem;
	size_t pad;

	*d = NULL;
	if (!image_usable(img)) {
		snprintf(err, errlen, "deform: image is not a usable FIR or modal image");
		return IRDM_DEFORM_EINVAL;
	}
	deform_layout(img, &l);
	pad = (size_t)(((p + DEFORM_ALIGN - 1) & ~(uintptr_t)(DEFORM_ALIGN - 1)) - p);
	if (!mem || mem_size < pad + l.total) {
		snprintf(err, errlen, "deform: %zu bytes of memory given, %zu needed", mem_size,
			 irdm_deform_mem_size(img));
		return IRDM_DEFORM_ENOMEM;
	}
	/* touch every page now: the update never page-faults later */
	memset(mem, 0, mem_size);
	unsigned char *base = (unsigned char *)mem + pad;
	struct irdm_deform *dd = (struct irdm_deform *)base;
	deform_setup(dd, img, base, &l);
	deform_warmup(dd);
	*d = dd;
	return IRDM_DEFORM_OK;
}

uint32_t irdm_deform_rows(const struct irdm_deform *d)
{
	return d->n_nodes;
}

/*
 * Hand the filled back slot over.  Release: the slot's contents are visible
 * to whoever acquires the index.  Acquire: the slot we get back was released
 * by the reader, whose reads of it are over.
 */
void deform_swap_back(struct irdm_deform *d)
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
	s = deform_back(d);
	s->tick = tick;
	copy_pose(&s->pose, pose);
	copy_forces(&s->f, f);
	s->n_hist = 0;
	memcpy(deform_payload(d, s), x, 2 * (size_t)d->n_modes * sizeof(double));
	deform_swap_back(d);
}

void irdm_deform_publish_fir(struct irdm_deform *d, uint64_t tick,
			     const struct irdm_fir_ring *ring, const struct irdm_pose *pose)
{
	struct irdm_force_tick *h;
	struct deform_snap *s;
	uint32_t n, idx;

	if (d->repr != IRDM_REPR_FIR || !ring || !ring->tick || !ring->T)
		return;
	s = deform_back(d);
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
	deform_swap_back(d);
}

/* world = com + R(q) (p - com_rest); q need not be normalised exactly. */
static void apply_pose(const struct irdm_rigid *rg, const struct irdm_pose *ps, double *pos,
		       uint32_t n)
{
	double w = ps->q[0], x = ps->q[1], y = ps->q[2], z = ps->q[3];
	double nn = w * w + x * x + y * y + z * z, k = nn > 0 ? 2 / nn : 0;
	double R[9] = {
		1 - k * (y * y + z * z), k * (x * y - w * z), k * (x * z + w * y),
		k * (x * y + w * z), 1 - k * (x * x + z * z), k * (y * z - w * x),
		k * (x * z - w * y), k * (y * z + w * x), 1 - k * (x * x + y * y),
	};

	for (uint32_t r = 0; r < n; r++) {
		double *p = pos + 3 * (size_t)r, v[3];
		for (int i = 0; i < 3; i++)
			v[i] = p[i] - rg->com_m[i];
		for (int i = 0; i < 3; i++)
			p[i] = ps->com_m[i] + R[3 * i] * v[0] + R[3 * i + 1] * v[1] +
			       R[3 * i + 2] * v[2];
	}
}

static void add_rest(const struct irdm_image *img, double *pos, uint32_t n)
{
	for (uint32_t r = 0; r < n; r++)
		for (int i = 0; i < 3; i++)
			pos[3 * (size_t)r + (size_t)i] += img->nodes[r].pos_m[i];
}

bool irdm_deform_update(struct irdm_deform *d, double *pos_m, uint64_t *tick)
{
	struct deform_snap *s = deform_take(d);

	if (!s)
		return false;
	if (d->repr == IRDM_REPR_MODAL)
		deform_modal(d, s, pos_m);
	else
		deform_fir(d, s, pos_m);
	add_rest(d->img, pos_m, d->n_nodes);
	if (d->img->rigid)
		apply_pose(d->img->rigid, &s->pose, pos_m, d->n_nodes);
	if (tick)
		*tick = s->tick;
	return true;
}
