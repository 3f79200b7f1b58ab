/* SPDX-License-Identifier: MIT */
/*
 * Test fixture: small valid IRDM images (see image_fixture.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/elem_store.h"
#include "image_fixture.h"

#define TWO_PI 6.283185307179586

double img_fixture_value(uint32_t kind, uint64_t i)
{
	/* k/1024 with |k| <= 500: exact in binary16, 32 and 64. */
	uint64_t k = ((i * 31 + kind * 7919u) * 2654435761u) % 1001;

	return ((double)k - 500.0) / 1024.0;
}

/* An array of n values of the given precision for section kind. */
static void *fill_values(uint32_t kind, uint32_t precision, uint64_t n,
			 uint64_t *bytes)
{
	size_t es = irdm_elem_size(precision);
	void *data;

	*bytes = n * es;
	data = calloc(n ? n : 1, es ? es : 8);
	if (!data)
		return NULL;
	for (uint64_t i = 0; i < n; i++)
		irdm_elem_put(data, precision, i, img_fixture_value(kind, i));
	return data;
}

static void fill_meta(struct img_fixture *fx, uint32_t repr, uint32_t precision,
		      uint32_t n_nodes, uint32_t n_cols)
{
	struct irdm_meta *m = &fx->meta;

	m->representation = repr;
	m->precision = precision;
	m->n_nodes = n_nodes;
	m->n_cols = n_cols;
	m->n_tris = n_nodes >= 3 ? n_nodes - 2 : 0;
	m->dt_s = 0.001;
	m->young_pa = 2000;
	m->poisson = 0.49;
	m->density_kg_m3 = 110;
	m->rayleigh_a_per_s = 1.5;
	m->rayleigh_b_s = 1e-4;
	m->damping_ratio[0] = 0.05;
	m->damping_ratio[1] = 0.05;
	m->damping_freq_hz[0] = 4.2;
	m->damping_freq_hz[1] = 100;
	m->first_elastic_hz = 4.2;
	m->mesh_nodes = 2 * n_nodes;
	m->mesh_tets = 3 * n_nodes;
	m->mesh_hash = 0xcbf29ce484222325u;
	snprintf(m->tool_version, sizeof(m->tool_version), "irdm-test 0.1");
	snprintf(m->mesh_name, sizeof(m->mesh_name), "fixture-grid-%u", n_nodes);
	fx->provenance_len = (size_t)snprintf(fx->provenance,
					      sizeof(fx->provenance),
					      "mesh=fixture-grid-%u\nmaterial=E2000 nu0.49 rho110\n"
					      "damping=5%% at 4.2 Hz and 100 Hz\ndt=0.001\ntool=irdm-test 0.1\n",
					      n_nodes);
}

/* Nodes on a 4 x 4 x k grid (1 cm), columns the last nodes in reverse order,
 * a fan of triangles, and one stability entry per column. */
static int fill_geometry(struct img_fixture *fx, double radius, bool stable)
{
	const struct irdm_meta *m = &fx->meta;

	fx->nodes = calloc(m->n_nodes, sizeof(*fx->nodes));
	fx->columns = calloc(m->n_cols, sizeof(*fx->columns));
	fx->tris = calloc(3 * (size_t)m->n_tris + 1, sizeof(*fx->tris));
	fx->stability = calloc(m->n_cols, sizeof(*fx->stability));
	if (!fx->nodes || !fx->columns || !fx->tris || !fx->stability)
		return -1;
	fx->nodes_bytes = (uint64_t)m->n_nodes * sizeof(*fx->nodes);
	fx->columns_bytes = (uint64_t)m->n_cols * sizeof(*fx->columns);
	fx->tris_bytes = (uint64_t)m->n_tris * 3 * sizeof(*fx->tris);
	fx->stability_bytes = (uint64_t)m->n_cols * sizeof(*fx->stability);
	for (uint32_t i = 0; i < m->n_nodes; i++) {
		fx->nodes[i].pos_m[0] = 0.01f * (float)(i % 4);
		fx->nodes[i].pos_m[1] = 0.01f * (float)(i / 4 % 4);
		fx->nodes[i].pos_m[2] = 0.01f * (float)(i / 16);
		fx->nodes[i].mesh_node = 2 * i + 1;
	}
	for (uint32_t c = 0; c < m->n_cols; c++)
		fx->columns[c] = m->n_nodes - 1 - c;
	for (uint32_t t = 0; t < m->n_tris; t++) {
		fx->tris[3 * t] = 0;
		fx->tris[3 * t + 1] = t + 1;
		fx->tris[3 * t + 2] = t + 2;
	}
	for (uint32_t c = 0; c < m->n_cols; c++) {
		fx->stability[c].spectral_radius = (float)radius;
		fx->stability[c].flags = stable ? IRDM_STAB_STABLE : 0;
	}
	fx->meta.max_spectral_radius = (float)radius;
	return 0;
}

int img_fixture_fir(struct img_fixture *fx, uint32_t precision,
		    uint32_t n_nodes, uint32_t n_cols, uint32_t fir_length)
{
	uint64_t n = (uint64_t)n_cols * n_nodes * fir_length * 9;

	memset(fx, 0, sizeof(*fx));
	fill_meta(fx, IRDM_REPR_FIR, precision, n_nodes, n_cols);
	fx->meta.fir_length = fir_length;
	fx->meta.flags = IRDM_META_TIME_DOMAIN;
	/* A truncated FIR: the paper's cuboid at T = 500 is not stable. */
	if (fill_geometry(fx, 1.004, false))
		goto fail;
	fx->fir = fill_values(IRDM_SEC_FIR, precision, n, &fx->fir_bytes);
	if (!fx->fir)
		goto fail;
	return 0;
fail:
	img_fixture_free(fx);
	return -1;
}

/* Exact zero-order-hold discretisation of q'' + 2 z w q' + w^2 q = g. */
static void zoh_mode(struct irdm_mode *md, double w, double z, double dt)
{
	double wd = w * sqrt(1 - z * z);
	double e = exp(-z * w * dt);
	double c = cos(wd * dt), s = sin(wd * dt);

	md->omega_rad_s = w;
	md->zeta = z;
	md->a[0] = e * (c + z * w / wd * s);
	md->a[1] = e * s / wd;
	md->a[2] = -e * w * w / wd * s;
	md->a[3] = e * (c - z * w / wd * s);
	md->b[0] = (1 - md->a[0]) / (w * w);
	md->b[1] = md->a[1];
}

static void fill_rigid(struct irdm_rigid *rg)
{
	memset(rg, 0, sizeof(*rg));
	rg->mass_kg = 0.19;
	rg->com_m[0] = 0.015;
	rg->com_m[1] = 0.015;
	rg->com_m[2] = 0.005;
	rg->inertia_kg_m2[0] = 2.3e-4;
	rg->inertia_kg_m2[4] = 2.3e-4;
	rg->inertia_kg_m2[8] = 1.4e-4;
}

/* Every block of the n_cols x n_cols correction kept, rows in order. */
static int fill_corr_index(struct img_fixture *fx, uint32_t n_cols)
{
	uint64_t n = (uint64_t)n_cols + 1 + (uint64_t)n_cols * n_cols;
	uint32_t *rows;

	fx->corr_index = malloc(n * sizeof(uint32_t));
	if (!fx->corr_index)
		return -1;
	fx->corr_index_bytes = n * sizeof(uint32_t);
	rows = fx->corr_index + n_cols + 1;
	for (uint32_t c = 0; c <= n_cols; c++)
		fx->corr_index[c] = c * n_cols;
	for (uint32_t c = 0; c < n_cols; c++)
		for (uint32_t r = 0; r < n_cols; r++)
			rows[c * n_cols + r] = r;
	return 0;
}

int img_fixture_modal(struct img_fixture *fx, uint32_t precision,
		      uint32_t n_nodes, uint32_t n_cols, uint32_t n_modes,
		      uint32_t meta_flags)
{
	memset(fx, 0, sizeof(*fx));
	fill_meta(fx, IRDM_REPR_MODAL, precision, n_nodes, n_cols);
	fx->meta.n_modes = n_modes;
	fx->meta.n_modes_total = 3 * n_nodes - 6;
	fx->meta.flags = meta_flags;
	if (fill_geometry(fx, 0.9989, true))
		goto fail;
	fx->modes = calloc(n_modes, sizeof(*fx->modes));
	if (!fx->modes)
		goto fail;
	fx->modes_bytes = (uint64_t)n_modes * sizeof(*fx->modes);
	for (uint32_t k = 0; k < n_modes; k++)
		zoh_mode(&fx->modes[k], TWO_PI * (4.2 + 7.0 * k), 0.05,
			 fx->meta.dt_s);
	fx->mode_shapes = fill_values(IRDM_SEC_MODE_SHAPES, precision,
				      (uint64_t)n_nodes * 3 * n_modes,
				      &fx->shapes_bytes);
	if (!fx->mode_shapes)
		goto fail;
	if (meta_flags & IRDM_META_STATIC_CORR) {
		fx->static_corr = fill_values(IRDM_SEC_STATIC_CORR, precision,
					      (uint64_t)n_cols * n_cols * 9,
					      &fx->corr_bytes);
		if (!fx->static_corr || fill_corr_index(fx, n_cols))
			goto fail;
	}
	if (meta_flags & IRDM_META_FLOATING)
		fill_rigid(&fx->rigid);
	return 0;
fail:
	img_fixture_free(fx);
	return -1;
}

int img_fixture_lowrank(struct img_fixture *fx, uint32_t rank)
{
	struct irdm_corr_lowrank_header h = { .rank = rank };
	uint64_t n = (uint64_t)rank * (1 + 3 * (uint64_t)fx->meta.n_cols), vb;
	void *v = fill_values(IRDM_SEC_STATIC_CORR_LOWRANK, fx->meta.precision, n, &vb);
	uint8_t *p = malloc(sizeof(h) + vb);

	if (!v || !p) {
		free(v);
		free(p);
		return -1;
	}
	memcpy(p, &h, sizeof(h));
	memcpy(p + sizeof(h), v, vb);
	free(v);
	free(fx->corr_lowrank);
	fx->corr_lowrank = p;
	fx->lowrank_bytes = sizeof(h) + vb;
	return 0;
}

/* STATIC_CORR_CLUSTERS's layout as the fixture builds it (image_fixture.h). */
struct cl_layout {
	uint32_t n_cols, n_clusters, rank;
	uint32_t *start, *members;
};

uint64_t img_fixture_clusters_tables(uint32_t n_clusters, uint32_t n_cols)
{
	uint64_t b = sizeof(struct irdm_corr_clusters_header) +
		     4 * ((uint64_t)n_clusters + 1 + 2 * (uint64_t)n_cols);

	return (b + 7) / 8 * 8;
}

static uint32_t cl_cluster_of(const struct cl_layout *l, uint32_t col)
{
	uint32_t pos = l->n_cols - 1 - col, a = 0;

	while (l->start[a + 1] <= pos)
		a++;
	return a;
}

/* The factors of the cross pairs, by DoF 3 c + x in column order. */
static double cl_g(const struct cl_layout *l, uint64_t r, uint64_t t)
{
	uint64_t n = 3 * (uint64_t)l->n_cols;

	return img_fixture_value(IRDM_SEC_STATIC_CORR_CLUSTERS, n * n + r * l->rank + t);
}

static double cl_h(const struct cl_layout *l, uint64_t c, uint64_t t)
{
	uint64_t n = 3 * (uint64_t)l->n_cols;

	return img_fixture_value(IRDM_SEC_STATIC_CORR_CLUSTERS,
				 n * n + n * l->rank + c * l->rank + t);
}

/* S[r][c], summed in the order the loader's reader sums U V^T. */
static double cl_s(const struct cl_layout *l, uint64_t r, uint64_t c)
{
	uint32_t ar = cl_cluster_of(l, (uint32_t)(r / 3)), ac = cl_cluster_of(l, (uint32_t)(c / 3));
	uint64_t n = 3 * (uint64_t)l->n_cols, lo = r < c ? r : c, hi = r < c ? c : r;
	double s = 0;

	if (ar == ac || l->rank == IRDM_CORR_PAIR_DENSE)
		return img_fixture_value(IRDM_SEC_STATIC_CORR_CLUSTERS, lo * n + hi);
	lo = ar < ac ? r : c;
	hi = ar < ac ? c : r;
	for (uint64_t t = 0; t < l->rank; t++)
		s += cl_g(l, lo, t) * cl_h(l, hi, t);
	return s;
}

/* Column DoF of row i of cluster a's part of a pair. */
static uint64_t cl_dof(const struct cl_layout *l, uint32_t a, uint64_t i)
{
	return 3 * (uint64_t)l->members[l->start[a] + i / 3] + i % 3;
}

/* Pair (a, b)'s values at element o: dense, or U (G's rows) then V (H's). */
static void cl_put_pair(const struct cl_layout *l, uint32_t prec, uint32_t a, uint32_t b,
			bool dense, void *values, uint64_t o)
{
	uint64_t ra = 3 * (uint64_t)(l->start[a + 1] - l->start[a]);
	uint64_t rb = 3 * (uint64_t)(l->start[b + 1] - l->start[b]);

	if (a == b) { /* the upper triangle, row by row */
		for (uint64_t i = 0, k = 0; i < ra; i++)
			for (uint64_t j = i; j < rb; j++)
				irdm_elem_put(values, prec, o + k++,
					      cl_s(l, cl_dof(l, a, i), cl_dof(l, b, j)));
		return;
	}
	if (dense) {
		for (uint64_t i = 0; i < ra; i++)
			for (uint64_t j = 0; j < rb; j++)
				irdm_elem_put(values, prec, o + i * rb + j,
					      cl_s(l, cl_dof(l, a, i), cl_dof(l, b, j)));
		return;
	}
	for (uint64_t t = 0; t < l->rank; t++) {
		for (uint64_t i = 0; i < ra; i++)
			irdm_elem_put(values, prec, o + i * l->rank + t, cl_g(l, cl_dof(l, a, i), t));
		for (uint64_t j = 0; j < rb; j++)
			irdm_elem_put(values, prec, o + (ra + j) * l->rank + t,
				      cl_h(l, cl_dof(l, b, j), t));
	}
}

/* The pair table and values in table order; only counts if pairs is NULL. */
static uint64_t cl_fill_pairs(const struct cl_layout *l, uint32_t prec,
			      struct irdm_corr_pair *pairs, void *values)
{
	uint64_t next = 0, k = 0;

	for (uint32_t a = 0; a < l->n_clusters; a++)
		for (uint32_t b = a; b < l->n_clusters; b++, k++) {
			uint64_t ra = 3 * (uint64_t)(l->start[a + 1] - l->start[a]);
			uint64_t rb = 3 * (uint64_t)(l->start[b + 1] - l->start[b]);
			bool dense = a == b || l->rank == IRDM_CORR_PAIR_DENSE;

			if (pairs) {
				pairs[k].offset = next;
				pairs[k].rank = dense ? IRDM_CORR_PAIR_DENSE : l->rank;
				cl_put_pair(l, prec, a, b, dense, values, next);
			}
			next += a == b ? ra * (ra + 1) / 2 : dense ? ra * rb :
								     l->rank * (ra + rb);
		}
	return next;
}

int img_fixture_clusters(struct img_fixture *fx, uint32_t n_clusters, uint32_t rank,
			 double *s_out)
{
	uint32_t nc = fx->meta.n_cols, prec = fx->meta.precision;
	uint32_t *start = calloc((size_t)n_clusters + 1, 4), *members = calloc(nc, 4);
	struct cl_layout l = { nc, n_clusters, rank, start, members };
	struct irdm_corr_clusters_header h = { .n_clusters = n_clusters };
	uint64_t tb = img_fixture_clusters_tables(n_clusters, nc);
	uint64_t np = (uint64_t)n_clusters * (n_clusters + 1) / 2, bytes;
	uint8_t *p = NULL;

	if (!start || !members || n_clusters < 1 || n_clusters > nc)
		goto out;
	for (uint32_t a = 0; a <= n_clusters; a++)
		start[a] = (uint32_t)((uint64_t)a * nc / n_clusters);
	for (uint32_t i = 0; i < nc; i++)
		members[i] = nc - 1 - i;
	h.max_rank = rank == IRDM_CORR_PAIR_DENSE ? 0 : rank;
	h.n_values = cl_fill_pairs(&l, prec, NULL, NULL);
	bytes = tb + sizeof(struct irdm_corr_pair) * np + irdm_elem_size(prec) * h.n_values;
	p = calloc(1, bytes);
	if (!p)
		goto out;
	memcpy(p, &h, sizeof(h));
	memcpy(p + sizeof(h), start, 4 * ((size_t)n_clusters + 1));
	memcpy(p + sizeof(h) + 4 * ((size_t)n_clusters + 1), members, 4 * (size_t)nc);
	for (uint32_t i = 0; i < nc; i++) /* col_pos: reverse order is its own inverse */
		memcpy(p + sizeof(h) + 4 * ((size_t)n_clusters + 1 + nc + members[i]), &i, 4);
	cl_fill_pairs(&l, prec, (struct irdm_corr_pair *)(p + tb),
		      p + tb + sizeof(struct irdm_corr_pair) * np);
	for (uint64_t r = 0; s_out && r < 3 * (uint64_t)nc; r++)
		for (uint64_t c = 0; c < 3 * (uint64_t)nc; c++)
			s_out[r * 3 * nc + c] = cl_s(&l, r, c);
	free(fx->corr_clusters);
	fx->corr_clusters = p;
	fx->clusters_bytes = bytes;
out:
	free(start);
	free(members);
	return p ? 0 : -1;
}

void img_fixture_free(struct img_fixture *fx)
{
	free(fx->nodes);
	free(fx->columns);
	free(fx->tris);
	free(fx->fir);
	free(fx->modes);
	free(fx->mode_shapes);
	free(fx->static_corr);
	free(fx->corr_index);
	free(fx->corr_lowrank);
	free(fx->corr_clusters);
	free(fx->stability);
	memset(fx, 0, sizeof(*fx));
}

void img_fixture_add(const struct img_fixture *fx, struct irdm_image_writer *w)
{
	const struct irdm_meta *m = &fx->meta;

	irdm_iw_add(w, IRDM_SEC_META, IRDM_ELEM_BYTES, m, sizeof(*m));
	irdm_iw_add(w, IRDM_SEC_PROVENANCE, IRDM_ELEM_BYTES, fx->provenance,
		    fx->provenance_len);
	irdm_iw_add(w, IRDM_SEC_NODES, IRDM_ELEM_BYTES, fx->nodes,
		    fx->nodes_bytes);
	irdm_iw_add(w, IRDM_SEC_COLUMNS, IRDM_ELEM_U32, fx->columns,
		    fx->columns_bytes);
	irdm_iw_add(w, IRDM_SEC_SURFACE, IRDM_ELEM_U32, fx->tris,
		    fx->tris_bytes);
	if (fx->fir)
		irdm_iw_add(w, IRDM_SEC_FIR, m->precision, fx->fir, fx->fir_bytes);
	if (fx->modes)
		irdm_iw_add(w, IRDM_SEC_MODES, IRDM_ELEM_BYTES, fx->modes,
			    fx->modes_bytes);
	if (fx->mode_shapes)
		irdm_iw_add(w, IRDM_SEC_MODE_SHAPES, m->precision,
			    fx->mode_shapes, fx->shapes_bytes);
	if (fx->static_corr)
		irdm_iw_add(w, IRDM_SEC_STATIC_CORR, m->precision,
			    fx->static_corr, fx->corr_bytes);
	if (fx->corr_index)
		irdm_iw_add(w, IRDM_SEC_STATIC_CORR_INDEX, IRDM_ELEM_U32,
			    fx->corr_index, fx->corr_index_bytes);
	if (fx->corr_lowrank)
		irdm_iw_add(w, IRDM_SEC_STATIC_CORR_LOWRANK, IRDM_ELEM_BYTES,
			    fx->corr_lowrank, fx->lowrank_bytes);
	if (fx->corr_clusters)
		irdm_iw_add(w, IRDM_SEC_STATIC_CORR_CLUSTERS, IRDM_ELEM_BYTES,
			    fx->corr_clusters, fx->clusters_bytes);
	if (m->flags & IRDM_META_FLOATING)
		irdm_iw_add(w, IRDM_SEC_RIGID, IRDM_ELEM_BYTES, &fx->rigid,
			    sizeof(fx->rigid));
	irdm_iw_add(w, IRDM_SEC_STABILITY, IRDM_ELEM_BYTES, fx->stability,
		    fx->stability_bytes);
}

int img_fixture_buffer(const struct img_fixture *fx, void **buf, size_t *size)
{
	struct irdm_image_writer w;

	irdm_iw_init(&w);
	img_fixture_add(fx, &w);
	return irdm_iw_to_buffer(&w, buf, size);
}

int img_fixture_write(const struct img_fixture *fx, const char *path,
		      char *err, size_t errlen)
{
	struct irdm_image_writer w;

	irdm_iw_init(&w);
	img_fixture_add(fx, &w);
	return irdm_iw_write(&w, path, err, errlen);
}

void img_fixture_reseal(void *buf, size_t size)
{
	struct irdm_image_header h;
	struct irdm_image_section s;
	uint8_t *b = buf;
	uint64_t toff;

	if (size < sizeof(h))
		return;
	memcpy(&h, b, sizeof(h));
	toff = h.section_table_offset;
	if (h.section_count <= IRDM_IMAGE_MAX_SECTIONS &&
	    toff + (uint64_t)h.section_count * sizeof(s) <= size) {
		for (uint32_t i = 0; i < h.section_count; i++) {
			memcpy(&s, b + toff + i * sizeof(s), sizeof(s));
			if (s.offset <= size && s.size <= size - s.offset)
				s.crc32c = irdm_crc32c(b + s.offset, (size_t)s.size);
			memcpy(b + toff + i * sizeof(s), &s, sizeof(s));
		}
		h.table_crc32c = irdm_crc32c(b + toff, h.section_count * sizeof(s));
	}
	memcpy(b, &h, sizeof(h));
	h.header_crc32c = irdm_crc32c(b, offsetof(struct irdm_image_header,
						  header_crc32c));
	memcpy(b, &h, sizeof(h));
}

void *img_fixture_copy(const void *buf, size_t len)
{
	void *p = malloc(len ? len : 1); /* malloc is aligned for double */

	if (p && len)
		memcpy(p, buf, len);
	return p;
}
