/* SPDX-License-Identifier: MIT */
/* The view's messages, byte by byte (view_msg.h; docs/view.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "view/view_msg.h"

_Static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE 754 binary32/64");
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the view's messages are little-endian, written as they are in memory"
#endif

static unsigned char *put(unsigned char *p, const void *v, size_t n)
{
	memcpy(p, v, n);
	return p + n;
}

static unsigned char *put_u32(unsigned char *p, uint32_t v)
{
	return put(p, &v, 4);
}

static unsigned char *put_f32(unsigned char *p, float v)
{
	return put(p, &v, 4);
}

static unsigned char *put_f64(unsigned char *p, double v)
{
	return put(p, &v, 8);
}

size_t view_hello_size(uint32_t n_nodes, uint32_t n_tris)
{
	return VIEW_HELLO_HEAD + 12 * (size_t)n_nodes + 12 * (size_t)n_tris;
}

size_t view_hello_write(unsigned char *buf, const struct view_hello *h)
{
	unsigned char *p = buf;
	char name[64] = { 0 };

	if (h->name)
		strncpy(name, h->name, sizeof(name) - 1);
	p = put_u32(p, VIEW_MAGIC);
	p = put_u32(p, VIEW_KIND_HELLO);
	p = put_u32(p, VIEW_VERSION);
	p = put_u32(p, h->mode);
	p = put_u32(p, h->n_nodes);
	p = put_u32(p, h->n_tris);
	p = put_u32(p, h->n_dev);
	p = put_f32(p, h->period_s);
	p = put_f32(p, h->scale_m);
	p = put_f32(p, h->duration_s);
	p = put_u32(p, h->n_frames);
	p = put(p, name, sizeof(name));
	p = put(p, h->rest_m, 12 * (size_t)h->n_nodes);
	p = put(p, h->tris, 12 * (size_t)h->n_tris);
	return (size_t)(p - buf);
}

float view_colour_scale(const float *rest_m, uint32_t n)
{
	float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	float ext = INFINITY;

	for (size_t i = 0; i < 3 * (size_t)n; i++) {
		lo[i % 3] = fminf(lo[i % 3], rest_m[i]);
		hi[i % 3] = fmaxf(hi[i % 3], rest_m[i]);
	}
	for (int k = 0; k < 3; k++)
		ext = fminf(ext, hi[k] - lo[k]);
	return ext > 0 && isfinite(ext) ? 0.1f * ext : 0.01f;
}

size_t view_hello_image(unsigned char **buf, const struct irdm_image *img, struct view_hello *h)
{
	uint32_t n = img->meta->n_nodes;
	float *rest = malloc(12 * (size_t)(n ? n : 1));
	size_t len = 0;

	*buf = malloc(view_hello_size(n, img->meta->n_tris));
	if (!rest || !*buf)
		goto out;
	for (uint32_t i = 0; i < n; i++)
		for (int k = 0; k < 3; k++)
			rest[3 * i + k] = img->nodes[i].pos_m[k];
	h->n_nodes = n;
	h->n_tris = img->meta->n_tris;
	h->scale_m = view_colour_scale(rest, n);
	h->rest_m = rest;
	h->tris = img->tris;
	len = view_hello_write(*buf, h);
	h->rest_m = NULL;
out:
	free(rest);
	if (!len) {
		free(*buf);
		*buf = NULL;
	}
	return len;
}

size_t view_frame_size(uint32_t n_nodes, uint32_t n_samples)
{
	return VIEW_FRAME_HEAD + VIEW_SAMPLE_BYTES * (size_t)n_samples + 12 * (size_t)n_nodes;
}

static unsigned char *put_dev(unsigned char *p, const struct view_dev *d)
{
	for (int k = 0; k < 3; k++)
		p = put_f32(p, d->tip_m[k]);
	for (int k = 0; k < 3; k++)
		p = put_f32(p, d->force_n[k]);
	for (int k = 0; k < 3; k++)
		p = put_f32(p, d->bary[k]);
	for (int k = 0; k < 3; k++)
		p = put_f32(p, d->target_m[k]);
	p = put_u32(p, d->tri);
	p = put_u32(p, d->proxy);
	p = put_u32(p, 0);
	return put_u32(p, 0);
}

size_t view_frame_write(unsigned char *buf, const struct view_frame *f, const float *pos,
			uint32_t n_nodes, const struct view_sample *smp, uint32_t n_samples)
{
	unsigned char *p = buf;

	p = put_u32(p, VIEW_MAGIC);
	p = put_u32(p, VIEW_KIND_FRAME);
	p = put_u32(p, pos ? VIEW_FRAME_POSITIONS : 0);
	p = put_u32(p, f->state);
	p = put_u32(p, f->faults);
	p = put_u32(p, f->n_dev);
	p = put_u32(p, n_samples);
	p = put_u32(p, pos ? n_nodes : 0);
	p = put_f64(p, f->tick);
	p = put_f64(p, f->t_s);
	p = put_f64(p, f->newest_tick);
	p = put_f64(p, f->sent_ms);
	p = put_f64(p, f->dropped);
	for (unsigned i = 0; i < VIEW_DEVICES; i++)
		p = put_dev(p, &f->dev[i]);
	for (uint32_t i = 0; i < n_samples; i++) {
		p = put_f32(p, smp[i].t_s);
		p = put_f32(p, smp[i].force_n[0]);
		p = put_f32(p, smp[i].force_n[1]);
		p = put_f32(p, smp[i].compute_us);
	}
	if (pos)
		p = put(p, pos, 12 * (size_t)n_nodes);
	return (size_t)(p - buf);
}

static float norm3(const double *v)
{
	return (float)sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

void view_sample_from_record(struct view_sample *s, const struct irdm_tick_record *r,
			     double period_s)
{
	s->t_s = (float)((double)r->tick * period_s);
	for (unsigned i = 0; i < VIEW_DEVICES; i++)
		s->force_n[i] = i < r->n_devices ? norm3(r->dev[i].force_n) : 0.0f;
	s->compute_us = (float)r->compute_ns * 1e-3f;
}

void view_frame_from_record(struct view_frame *f, const struct irdm_tick_record *r)
{
	f->state = r->state;
	f->faults = r->fault_flags;
	f->n_dev = r->n_devices < VIEW_DEVICES ? r->n_devices : VIEW_DEVICES;
	for (unsigned i = 0; i < VIEW_DEVICES; i++) {
		const struct irdm_tick_dev *d = &r->dev[i];
		struct view_dev *v = &f->dev[i];

		for (int k = 0; k < 3; k++) {
			v->tip_m[k] = (float)d->tip_pos_m[k];
			v->force_n[k] = (float)d->force_n[k];
			v->bary[k] = (float)d->site_bary[k];
			v->target_m[k] = (float)d->target_m[k];
		}
		v->tri = i < f->n_dev ? d->site_tri : UINT32_MAX;
		v->proxy = d->proxy;
	}
}
