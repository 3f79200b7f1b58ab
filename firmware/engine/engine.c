/* SPDX-License-Identifier: MIT */
/*
 * The force engine: memory layout and initialisation, contact sites, and
 * the tick (eq. 3-8 with a virtual coupling, unilateral release, passivity
 * control, fault on a bad input or an excessive force).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine_priv.h"

#define ALIGN 64u

static size_t up(size_t n)
{
	return (n + ALIGN - 1) & ~(size_t)(ALIGN - 1);
}

struct layout {
	size_t engine, col_of_row, phi, x, y, coef, ring, tail, bound, head_bound, lanes, zeros,
		total;
};

/* K modes padded to whole groups of MODE_LANES (engine_priv.h) */
static size_t padded_modes(size_t K)
{
	return (K + MODE_LANES - 1) / MODE_LANES * MODE_LANES;
}

static int plan(const struct irdm_image *img, const struct irdm_engine_config *cfg,
		struct layout *l)
{
	const struct irdm_meta *m = img->meta;
	bool modal = m->representation == IRDM_REPR_MODAL;
	size_t K = modal ? m->n_modes : 0, T = modal ? 0 : m->fir_length, Kp = padded_modes(K);
	size_t H = modal ? m->head_samples : 0;

	if (!cfg || cfg->max_contacts < 1 || cfg->max_contacts > IRDM_MAX_CONTACTS ||
	    !(cfg->coupling_k_n_per_m >= 0) || !(cfg->coupling_b_ns_per_m >= 0) ||
	    !(cfg->stable_radius >= 0 && cfg->stable_radius < 1) || !(cfg->max_force_n >= 0) ||
	    !(cfg->engage_fade_s >= 0 && cfg->engage_fade_s <= IRDM_ENGINE_ENGAGE_FADE_MAX_S) ||
	    (cfg->solve != IRDM_SOLVE_COUPLED && cfg->solve != IRDM_SOLVE_PER_VERTEX))
		return -1;
	l->engine = 0;
	l->col_of_row = up(sizeof(struct irdm_engine));
	l->phi = l->col_of_row + up(m->n_nodes * sizeof(uint32_t));
	l->x = l->phi + up((size_t)m->n_cols * 3 * Kp * sizeof(double));
	l->y = l->x + up(2 * Kp * sizeof(double));
	l->coef = l->y + up(2 * Kp * sizeof(double));
	l->ring = l->coef + up(Kp / 2 * sizeof(struct mode_coef));
	l->tail = l->ring + up((T + H) * sizeof(struct irdm_force_tick));
	l->bound = l->tail + up(T * sizeof(double));
	l->head_bound = l->bound + up((K + T) * sizeof(double));
	l->lanes = l->head_bound + up(2 * H * sizeof(double)); /* bound weights, slot norms */
	l->zeros = l->lanes + up((H > 1 ? HEAD_LANES : 0) * H * HEAD_SAMPLE * sizeof(double));
	l->total = l->zeros + up(H * 9 * sizeof(double)); /* H blocks at most f64 */
	return 0;
}

size_t irdm_engine_mem_size(const struct irdm_image *img, const struct irdm_engine_config *cfg)
{
	struct layout l;

	return plan(img, cfg, &l) ? 0 : l.total;
}

void irdm_engine_config_default(struct irdm_engine_config *cfg)
{
	memset(cfg, 0, sizeof(*cfg));
	cfg->max_contacts = 2;
	cfg->solve = IRDM_SOLVE_COUPLED;
	cfg->stable_radius = IRDM_ENGINE_STABLE_RADIUS;
	cfg->engage_fade_s = IRDM_ENGINE_ENGAGE_FADE_S;
}

void irdm_engine_coupling_for_device(double k_max, double b_device, double dt,
				     double *k, double *b)
{
	/* b_device > K dt / 2 + |B|: spend half the margin on K, half on B */
	double k_pass = b_device / dt; /* K dt / 2 = b_device / 2 */

	*k = fmin(k_max, k_pass);
	*b = fmax(0.0, 0.5 * (b_device - *k * dt / 2));
}

void irdm_engine_config_haptic(struct irdm_engine_config *cfg, double dt, double k_max,
			       double b_device, double max_force)
{
	irdm_engine_config_default(cfg);
	irdm_engine_coupling_for_device(k_max, b_device, dt, &cfg->coupling_k_n_per_m,
					&cfg->coupling_b_ns_per_m);
	cfg->passivity_control = true;
	/* b_device > K dt / 2 + B + alpha: what the coupling left */
	cfg->passivity_max_damping_ns_per_m =
		fmax(0.0, b_device - cfg->coupling_k_n_per_m * dt / 2 - cfg->coupling_b_ns_per_m);
	cfg->max_force_n = max_force;
}

/*
 * FIR tail damping, the fallback for an image whose certificate failed:
 * r = stable_radius / (the image's largest recorded radius) when that
 * radius is >= 1, on every column alike; r = 1 for a certified image (a
 * windowed tail, fir_tail = window:L, is certified as it is and must run
 * undamped, or its head and static compliance would be lost again).
 */
static void fir_tail(struct irdm_engine *e, double *w)
{
	/* from the table itself: the meta's copy is a summary for people */
	double rho = irdm_image_max_radius(e->img), r = 1.0, stable = e->cfg.stable_radius;

	if (stable == 0)
		stable = IRDM_ENGINE_STABLE_RADIUS;
	if (rho >= 1.0)
		r = stable / rho;
	w[0] = 1.0;
	for (uint32_t s = 1; s < e->T; s++)
		w[s] = w[s - 1] * r;
}

static void convert_shapes(struct irdm_engine *e, double *phi)
{
	const struct irdm_image *img = e->img;

	for (uint32_t c = 0; c < e->n_cols; c++) {
		size_t row = img->columns[c];
		for (size_t a = 0; a < 3; a++)
			for (size_t k = 0; k < e->K; k++)
				phi[((size_t)c * 3 + a) * e->Kp + k] =
					irdm_elem_get(img->mode_shapes, img->meta->precision,
						      (row * 3 + a) * e->K + k);
	}
}

/* The recursion's coefficients by pairs of modes (struct mode_coef); the
 * padding modes' stay zero. */
static void mode_coefs(struct irdm_engine *e, struct mode_coef *c)
{
	for (uint32_t k = 0; k < e->K; k++) {
		const struct irdm_mode *m = &e->img->modes[k];
		struct mode_coef *p = &c[k / 2];
		uint32_t i = 2 * (k % 2);

		p->b[i] = m->b[0], p->b[i + 1] = m->b[1];
		p->aq[i] = m->a[0], p->aq[i + 1] = m->a[2];
		p->av[i] = m->a[1], p->av[i + 1] = m->a[3];
	}
}

#if IRDM_CONFIG_FLOATING
/* A floating object starts at rest with its object frame on the world frame. */
static int start_rigid(struct irdm_engine *e)
{
	struct irdm_rigid_params p;
	struct irdm_rigid_state s0;

	memset(&s0, 0, sizeof(s0));
	irdm_rigid_params_from_image(e->img->rigid, &p);
	for (int a = 0; a < 3; a++)
		e->com_rest_m[a] = s0.com_m[a] = e->img->rigid->com_m[a];
	s0.q[0] = 1.0;
	e->floating = true;
	return irdm_rigid_init(&e->rb, &p, &s0);
}
#else
static int start_rigid(struct irdm_engine *e)
{
	(void)e;
	return IRDM_ENOTSUP; /* refused before, by unsupported() */
}
#endif

/*
 * An image this build cannot run (irdm/build_config.h): say which feature
 * it needs.  Return: 0, or IRDM_ENOTSUP with the message.
 */
static int unsupported(const struct irdm_image *img, char *err, size_t errlen)
{
	const char *need = NULL, *config = NULL;

	if (!IRDM_CONFIG_FIR && img->meta->representation == IRDM_REPR_FIR)
		need = "FIR responses", config = "CONFIG_IRDM_FIR";
	else if (!IRDM_CONFIG_MODAL && img->meta->representation == IRDM_REPR_MODAL)
		need = "modal responses", config = "CONFIG_IRDM_MODAL";
	else if (!IRDM_CONFIG_FLOATING && img->rigid)
		need = "a floating object", config = "CONFIG_IRDM_FLOATING";
	if (!need)
		return 0;
	snprintf(err, errlen, "engine: the image holds %s; this build has %s off "
			      "(docs/build-config.md)",
		 need, config);
	return IRDM_ENOTSUP;
}

int irdm_engine_init(struct irdm_engine **out, const struct irdm_image *img,
		     const struct irdm_engine_config *cfg, void *mem, size_t mem_size,
		     char *err, size_t errlen)
{
	struct layout l;
	struct irdm_engine *e = mem;
	uint8_t *base = mem;

	*out = NULL;
	if (img && img->meta && unsupported(img, err, errlen))
		return IRDM_ENOTSUP;
	if (!img || !img->meta || plan(img, cfg, &l)) {
		snprintf(err, errlen, "engine: invalid configuration (contacts 1..%d, coupling >= 0, stable radius in [0, 1), force limit >= 0, engage fade 0..%g s)",
			 IRDM_MAX_CONTACTS, IRDM_ENGINE_ENGAGE_FADE_MAX_S);
		return IRDM_EINVAL;
	}
	if (!mem || ((uintptr_t)mem & 15) || mem_size < l.total) {
		snprintf(err, errlen, "engine: needs %zu bytes of 16-byte aligned memory, got %zu",
			 l.total, mem_size);
		return IRDM_ENOMEM;
	}
	memset(mem, 0, l.total); /* also pre-faults every page */
	e->img = img;
	e->cfg = *cfg;
	e->dt_s = img->meta->dt_s;
	/* whole ticks; the 1e-9 keeps 0.25 s at 1 ms from rounding up to 251 */
	e->engage_ticks = (uint32_t)ceil(cfg->engage_fade_s / e->dt_s - 1e-9);
	e->repr = img->meta->representation;
	e->n_nodes = img->meta->n_nodes;
	e->n_cols = img->meta->n_cols;
	e->K = e->repr == IRDM_REPR_MODAL ? img->meta->n_modes : 0;
	e->Kp = (uint32_t)padded_modes(e->K);
	e->T = e->repr == IRDM_REPR_FIR ? img->meta->fir_length : 0;
	e->H = e->repr == IRDM_REPR_MODAL ? img->meta->head_samples : 0;
	uint32_t *cor = (uint32_t *)(base + l.col_of_row);
	for (uint32_t r = 0; r < e->n_nodes; r++)
		cor[r] = NO_COL;
	for (uint32_t c = 0; c < e->n_cols; c++)
		cor[img->columns[c]] = c;
	e->col_of_row = cor;
	e->x = (double *)(base + l.x);
	e->y = (double *)(base + l.y);
	if (e->K) {
		convert_shapes(e, (double *)(base + l.phi));
		mode_coefs(e, (struct mode_coef *)(base + l.coef));
	}
	e->phi = (const double *)(base + l.phi);
	e->coef = (const struct mode_coef *)(base + l.coef);
	e->modal_wide = e->K && !cfg->fir_portable_sum && irdm_wide_usable();
	e->ring.T = e->T + e->H; /* one of the two is 0 */
	e->ring.tick = (struct irdm_force_tick *)(base + l.ring);
	if (e->T)
		fir_tail(e, (double *)(base + l.tail));
#if IRDM_CONFIG_FIR
	e->fir_wide = e->T && !cfg->fir_portable_sum && irdm_wide_usable();
#endif
	e->head_wide = e->H && !cfg->fir_portable_sum && irdm_wide_usable();
	e->tail_w = (const double *)(base + l.tail);
	irdm_bound_init(e, (double *)(base + l.bound));
	e->bound_w = (const double *)(base + l.bound);
	if (e->H)
		irdm_head_bound_init(e, (double *)(base + l.head_bound));
	e->head_bound_w = (const double *)(base + l.head_bound);
	e->head_norm = (double *)(base + l.head_bound) + e->H;
	irdm_head_lanes_init(e, (double *)(base + l.lanes), base + l.zeros);
	if (img->rigid && start_rigid(e)) {
		snprintf(err, errlen, "engine: the image's rigid-body data is not usable (mass %g kg)",
			 img->rigid->mass_kg);
		return IRDM_EINVAL;
	}
	*out = e;
	return IRDM_OK;
}

void irdm_engine_reset(struct irdm_engine *e)
{
	if (e->floating)
		start_rigid(e);
	for (uint32_t k = 0; k < 2 * e->Kp; k++)
		e->x[k] = e->y[k] = 0;
	memset(e->free_memo, 0, sizeof(e->free_memo));
	for (uint32_t s = 0; s < e->ring.T; s++)
		e->ring.tick[s].n = 0;
	for (uint32_t s = 0; s < e->H; s++)
		e->head_norm[s] = 0;
	irdm_head_lanes_reset(e);
	for (unsigned i = 0; i < IRDM_MAX_CONTACTS; i++)
		irdm_engine_contact_end(e, i);
	e->port_energy_left_j = 0;
	e->faulted = false;
	e->fault_why = NULL;
}

/* ---- contact sites ---- */

static void rest_pos(const struct irdm_image *img, uint32_t row, double p[3])
{
	for (int a = 0; a < 3; a++)
		p[a] = img->nodes[row].pos_m[a];
}

int irdm_engine_site_node(const struct irdm_engine *e, uint32_t row, struct irdm_contact_site *s)
{
	double n[3] = { 0, 0, 0 };

	if (row >= e->n_nodes || e->col_of_row[row] == NO_COL)
		return IRDM_ECONTACT;
	memset(s, 0, sizeof(*s));
	s->n_nodes = 1;
	s->row[0] = row;
	s->col[0] = e->col_of_row[row];
	s->weight[0] = 1.0;
	rest_pos(e->img, row, s->rest_m);
	/* area-weighted normal of the surface triangles around the node */
	for (uint32_t t = 0; t < e->img->meta->n_tris; t++) {
		const uint32_t *v = &e->img->tris[3 * t];
		if (v[0] != row && v[1] != row && v[2] != row)
			continue;
		double a[3], b[3], c[3];
		rest_pos(e->img, v[0], a);
		rest_pos(e->img, v[1], b);
		rest_pos(e->img, v[2], c);
		double u[3], w[3], nt[3];
		irdm_v3_sub(u, b, a);
		irdm_v3_sub(w, c, a);
		irdm_v3_cross(nt, u, w);
		irdm_v3_add(n, n, nt);
	}
	double len = irdm_v3_norm(n);
	for (int a = 0; a < 3; a++)
		s->normal[a] = len > 0 ? n[a] / len : 0;
	return IRDM_OK;
}

int irdm_engine_site_point(const struct irdm_engine *e, uint32_t tri, const double bary[3],
			   struct irdm_contact_site *s)
{
	const struct irdm_image *img = e->img;
	double p[3][3];

	if (tri >= img->meta->n_tris)
		return IRDM_ECONTACT;
	double sum = bary[0] + bary[1] + bary[2];
	if (!(fabs(sum - 1) < 1e-9) || !(bary[0] >= -1e-12 && bary[1] >= -1e-12 && bary[2] >= -1e-12))
		return IRDM_EINVAL;
	memset(s, 0, sizeof(*s));
	s->n_nodes = 3;
	for (int k = 0; k < 3; k++) {
		uint32_t row = img->tris[3 * tri + (uint32_t)k];
		s->row[k] = row;
		s->col[k] = e->col_of_row[row];
		s->weight[k] = bary[k];
		rest_pos(img, row, p[k]);
		irdm_v3_axpy(s->rest_m, bary[k], p[k]);
	}
	/* every vertex must move with a response, or be fixed (zero response) */
	for (int k = 0; k < 3; k++)
		if (s->col[k] == NO_COL && bary[k] > 0 && e->repr == IRDM_REPR_MODAL) {
			const struct irdm_meta *m = img->meta;
			for (size_t i = 0; i < 3 * (size_t)m->n_modes; i++)
				if (irdm_elem_get(img->mode_shapes, m->precision, s->row[k] * 3 * (size_t)m->n_modes + i) != 0)
					return IRDM_ECONTACT;
		}
	double u[3], w[3], n[3];
	irdm_v3_sub(u, p[1], p[0]);
	irdm_v3_sub(w, p[2], p[0]);
	irdm_v3_cross(n, u, w);
	double len = irdm_v3_norm(n);
	if (!(len > 0))
		return IRDM_ECONTACT; /* degenerate triangle */
	for (int a = 0; a < 3; a++)
		s->normal[a] = n[a] / len;
	return IRDM_OK;
}

int irdm_engine_contact_begin(struct irdm_engine *e, unsigned i, const struct irdm_contact_site *site,
			      enum irdm_contact_mode mode)
{
	if (i >= e->cfg.max_contacts || !site || site->n_nodes < 1 || site->n_nodes > 3 ||
	    (mode != IRDM_CONTACT_PUSH && mode != IRDM_CONTACT_GRAB))
		return IRDM_EINVAL;
	struct irdm_contact_state *c = &e->c[i];
	/* a contact that moves to a new site (sliding) keeps its past target,
	 * displacement and port energy; a new one starts from rest */
	if (c->mode == IRDM_CONTACT_OFF) {
		memset(c, 0, sizeof(*c));
		c->fresh = 1;
	}
	c->mode = mode;
	c->site = *site;
	return IRDM_OK;
}

int irdm_engine_contact_soften(struct irdm_engine *e, unsigned i)
{
	struct irdm_contact_state *c;

	if (i >= e->cfg.max_contacts || e->c[i].mode == IRDM_CONTACT_OFF || !e->c[i].fresh)
		return IRDM_EINVAL;
	c = &e->c[i];
	if (e->cfg.coupling_k_n_per_m > 0)
		c->engage_ticks = e->engage_ticks;
	return IRDM_OK;
}

void irdm_engine_contact_end(struct irdm_engine *e, unsigned i)
{
	if (i >= IRDM_MAX_CONTACTS)
		return;
	tick_port_end(e, &e->c[i]);
	memset(&e->c[i], 0, sizeof(e->c[i]));
}

const struct irdm_contact_state *irdm_engine_contact(const struct irdm_engine *e, unsigned i)
{
	return i < IRDM_MAX_CONTACTS ? &e->c[i] : NULL;
}

const char *irdm_engine_fault_reason(const struct irdm_engine *e)
{
	return e->faulted ? e->fault_why : NULL;
}

const char *irdm_engine_fir_sum_name(const struct irdm_engine *e)
{
	bool wide = e->T ? e->fir_wide : e->modal_wide;

	return !e->T && !e->K ? "none" : wide ? "avx2" :
						"portable";
}

const struct irdm_engine_stats *irdm_engine_stats(const struct irdm_engine *e)
{
	return &e->stats;
}

void irdm_engine_attach_deform(struct irdm_engine *e, struct irdm_deform *d)
{
	e->deform = d;
}

/* ---- frames (irdm/engine.h) ---- */

const struct irdm_rigid_body *irdm_engine_rigid_body(const struct irdm_engine *e)
{
#if IRDM_CONFIG_FLOATING
	if (e->floating)
		return &e->rb;
#endif
	(void)e;
	return NULL;
}

void irdm_engine_world_to_object(const struct irdm_engine *e, const double x[3], double p[3])
{
	double b[3];

	(void)e;
#if IRDM_CONFIG_FLOATING
	if (e->floating) {
		irdm_rigid_world_to_body(&e->rb, x, b);
		irdm_v3_add(p, b, e->com_rest_m);
		return;
	}
#endif
	memcpy(p, x, sizeof(b));
}

void irdm_engine_object_to_world(const struct irdm_engine *e, const double p[3], double x[3])
{
	double b[3];

	(void)e;
#if IRDM_CONFIG_FLOATING
	if (e->floating) {
		irdm_v3_sub(b, p, e->com_rest_m);
		irdm_rigid_body_to_world(&e->rb, b, x);
		return;
	}
#endif
	memcpy(x, p, sizeof(b));
}
