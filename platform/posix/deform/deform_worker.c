/* SPDX-License-Identifier: MIT */
/*
 * Deformation worker: its memory and BLAS operands, and the update that
 * turns the channel's newest snapshot into world positions.
 */
#include <limits.h>
#include <stdio.h>

#include "worker_priv.h"

struct worker_layout {
	size_t off_y, off_uf, off_shapes, off_frame, off_far, off_cl, total;
};

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

static void worker_layout(const struct irdm_image *img, struct worker_layout *l)
{
	const struct irdm_meta *m = img->meta;
	size_t n3 = 3 * (size_t)m->n_nodes, K = m->n_modes;
	bool modal = m->representation == IRDM_REPR_MODAL;

	l->off_y = deform_align_up(sizeof(struct irdm_deform_worker));
	l->off_uf = l->off_y + (modal ? deform_align_up(K * sizeof(double)) : 0);
	l->off_shapes = l->off_uf;
	if (modal && m->precision != IRDM_ELEM_F64)
		l->off_shapes += deform_align_up(n3 * sizeof(float));
	l->off_frame = l->off_shapes;
	if (modal && m->precision == IRDM_ELEM_F16)
		l->off_frame += deform_align_up(n3 * K * sizeof(float));
	l->off_far = l->off_frame + deform_align_up(n3 * sizeof(double));
	l->off_cl = l->off_far;
	if (modal && img->corr_rank) /* the far field's weights */
		l->off_cl += deform_align_up(img->corr_rank * sizeof(double));
	l->total = l->off_cl;
	if (modal && img->corr_clusters) /* one low-rank pair's weights */
		l->total += deform_align_up(img->corr_clusters->max_rank * sizeof(double));
}

size_t irdm_deform_worker_mem_size(const struct irdm_image *img)
{
	struct worker_layout l;

	if (!image_usable(img))
		return 0;
	worker_layout(img, &l);
	return l.total + DEFORM_ALIGN; /* room to align the caller's memory */
}

/* BLAS takes f32 or f64: an f16 image's shapes are widened once, here. */
static const void *blas_shapes(const struct irdm_image *img, unsigned char *base,
			       const struct worker_layout *l)
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

static void worker_setup(struct irdm_deform_worker *w, struct irdm_deform *d,
			 unsigned char *base, const struct worker_layout *l)
{
	const struct irdm_image *img = d->img;
	const struct irdm_meta *m = img->meta;

	w->d = d;
	w->img = img;
	w->repr = m->representation;
	w->prec = m->precision;
	w->n_nodes = m->n_nodes;
	w->n_cols = m->n_cols;
	w->n_modes = d->n_modes;
	w->T = d->T;
	if (w->repr == IRDM_REPR_MODAL) {
		w->shapes = blas_shapes(img, base, l);
		w->shapes_f64 = m->precision == IRDM_ELEM_F64;
		w->y = base + l->off_y;
		w->uf = w->shapes_f64 ? NULL : (float *)(base + l->off_uf);
	}
	w->frame_pos = (double *)(base + l->off_frame);
	if (w->repr == IRDM_REPR_MODAL && img->corr_rank)
		w->far_g = (double *)(base + l->off_far);
	if (w->repr == IRDM_REPR_MODAL && img->corr_clusters && img->corr_clusters->max_rank)
		w->cl_g = (double *)(base + l->off_cl);
}

int irdm_deform_worker_init(struct irdm_deform_worker **wp, struct irdm_deform *d, void *mem,
			    size_t mem_size, char *err, size_t errlen)
{
	struct irdm_deform_worker *w;
	struct worker_layout l;
	unsigned char *base;

	*wp = NULL;
	if (!d || !image_usable(d->img)) {
		snprintf(err, errlen, "deform: image is not a usable FIR or modal image");
		return IRDM_EINVAL;
	}
	worker_layout(d->img, &l);
	base = deform_place(mem, mem_size, l.total);
	if (!base) {
		snprintf(err, errlen, "deform: %zu bytes of memory given, %zu needed", mem_size,
			 irdm_deform_worker_mem_size(d->img));
		return IRDM_ENOMEM;
	}
	w = (struct irdm_deform_worker *)base;
	worker_setup(w, d, base, &l);
	/*
	 * One product now (y is zero): OpenBLAS sets up its buffers and the
	 * shapes come into cache on the first call, which then is not the first
	 * frame's cost.
	 */
	if (w->repr == IRDM_REPR_MODAL)
		deform_modal_product(w, w->frame_pos);
	*wp = w;
	return IRDM_OK;
}

uint32_t irdm_deform_rows(const struct irdm_deform_worker *w)
{
	return w->n_nodes;
}

/* world = com + R(q) (p - com_rest); q need not be normalised exactly. */
static void apply_pose(const struct irdm_rigid *rg, const struct irdm_pose *ps, double *pos,
		       uint32_t n)
{
	double w = ps->q[0], x = ps->q[1], y = ps->q[2], z = ps->q[3];
	double nn = w * w + x * x + y * y + z * z, k = nn > 0 ? 2 / nn : 0;
	double R[9] = {
		1 - k * (y * y + z * z),
		k * (x * y - w * z),
		k * (x * z + w * y),
		k * (x * y + w * z),
		1 - k * (x * x + z * z),
		k * (y * z - w * x),
		k * (x * z - w * y),
		k * (y * z + w * x),
		1 - k * (x * x + y * y),
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

bool irdm_deform_update(struct irdm_deform_worker *w, double *pos_m, uint64_t *tick)
{
	struct deform_snap *s = deform_take(w->d);

	if (!s)
		return false;
	if (w->repr == IRDM_REPR_MODAL)
		deform_modal(w, s, pos_m);
	else
		deform_fir(w, s, pos_m);
	add_rest(w->img, pos_m, w->n_nodes);
	if (w->img->rigid)
		apply_pose(w->img->rigid, &s->pose, pos_m, w->n_nodes);
	if (tick)
		*tick = s->tick;
	return true;
}
