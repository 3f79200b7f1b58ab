/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "engine_fixture.h"
#include "image/image_response.h"
#include "irdm/posix/image_map.h"
#include "irdm/rigid.h"
#include "stab_harness.h"
#include "test_files.h"

/* ---- image cache: one build per distinct key list per binary ---- */

#define STAB_MAX_IMAGES 32

static struct {
	char key[512];
	struct irdm_image img;
} cache[STAB_MAX_IMAGES];
static int n_cached;

static void image_key(const char *const *kv, char *key, size_t len)
{
	size_t n = 0;

	key[0] = 0;
	for (; *kv; kv++) {
		int w = snprintf(key + n, len - n, "%s%s", n ? " " : "", *kv);
		assert_true(w >= 0 && (size_t)w < len - n);
		n += (size_t)w;
	}
}

/* efx_image() takes its pairs as varargs; a case holds up to 16 pairs. */
static void build_image(struct irdm_image *img, const char *path, const char *const *kv)
{
	const char *p[33] = { NULL };
	int n = 0;

	while (kv[n]) {
		assert_true(n < 32);
		p[n] = kv[n];
		n++;
	}
	efx_image(img, path, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10],
		  p[11], p[12], p[13], p[14], p[15], p[16], p[17], p[18], p[19], p[20], p[21], p[22],
		  p[23], p[24], p[25], p[26], p[27], p[28], p[29], p[30], p[31], p[32]);
}

const struct irdm_image *stab_image(const char *dir, const char *const *kv)
{
	char key[512], path[256];

	image_key(kv, key, sizeof(key));
	for (int i = 0; i < n_cached; i++)
		if (!strcmp(cache[i].key, key))
			return &cache[i].img;
	assert_true(n_cached < STAB_MAX_IMAGES);
	snprintf(path, sizeof(path), "%s/stab%d.img", dir, n_cached);
	build_image(&cache[n_cached].img, path, kv);
	snprintf(cache[n_cached].key, sizeof(cache[n_cached].key), "%s", key);
	return &cache[n_cached++].img;
}

void stab_images_free(void)
{
	for (int i = 0; i < n_cached; i++)
		irdm_image_unmap(&cache[i].img);
	n_cached = 0;
}

/* ---- targets ---- */

void stab_step(const struct stab_case *c, unsigned long t, double dt_s,
	       struct irdm_contact_cmd *cmd)
{
	double ramp = fmin(1.0, (double)(t + 1) * dt_s / 0.05);
	int m = c->sites == STAB_ONE ? 1 : 2;

	for (int i = 0; i < m; i++) {
		cmd[i].mode = c->mode;
		cmd[i].target_m[2] = -c->depth_m[i] * ramp;
	}
}

void stab_poison(const struct stab_case *c, unsigned long t, double dt_s,
		 struct irdm_contact_cmd *cmd)
{
	stab_step(c, t, dt_s, cmd);
	if (t == c->poison_tick || (t > c->poison_tick && !c->reset_after_fault))
		cmd[0].target_m[2] = c->poison_m;
}

/* ---- the static force an independent sum of the responses predicts ---- */

/*
 * Static compliance between node sites: sum over s of R[s] (weighted by
 * the engine's FIR tail r^s, restated from docs/architecture.md: r =
 * 0.999 / rho when the image's largest recorded radius rho >= 1).  Modal images: the
 * sum runs until the slowest mode has decayed (rho^s < 1e-12).
 */
static void static_compliance(const struct irdm_image *img, uint32_t row, uint32_t col, double c[9])
{
	const struct irdm_meta *mt = img->meta;
	double rho = mt->max_spectral_radius, r = 1.0, w = 1.0;
	size_t n;

	if (mt->representation == IRDM_REPR_FIR) {
		n = mt->fir_length;
		if (rho >= 1.0)
			r = 0.999 / rho;
	} else {
		n = (size_t)fmin(2e5, ceil(log(1e-12) / log(fmin(rho, 1 - 1e-6))));
	}
	double *R = malloc(9 * n * sizeof(double));
	assert_non_null(R);
	assert_int_equal(irdm_image_response(img, col, row, n, R), 0);
	memset(c, 0, 9 * sizeof(double));
	for (size_t s = 0; s < n; s++, w *= r)
		for (int e = 0; e < 9; e++)
			c[e] += w * R[9 * s + (size_t)e];
	free(R);
}

/* |v| without overflow (forces of 1e303 N are among the cases) */
static double norm3(const double v[3])
{
	return hypot(hypot(v[0], v[1]), v[2]);
}

/* Sum over contacts of |F| at rest under the held targets (NAN if the
 * system is singular: two rigid contacts on one node). */
static double static_force(const struct irdm_image *img, const struct irdm_contact_site *st, int m,
			   double k, const double *target)
{
	double a[36], f[6], sum = 0;
	int n = 3 * m;

	for (int i = 0; i < m; i++)
		for (int j = 0; j < m; j++) {
			double c[9];
			static_compliance(img, st[i].row[0], st[j].col[0], c);
			for (int r = 0; r < 3; r++)
				for (int q = 0; q < 3; q++) {
					double v = k > 0 ? k * c[3 * r + q] : c[3 * r + q];
					if (k > 0 && i == j && r == q)
						v += 1.0;
					a[(3 * i + r) * n + 3 * j + q] = v;
				}
		}
	for (int i = 0; i < n; i++)
		f[i] = k > 0 ? k * target[i] : target[i];
	if (efx_dense_solve(a, f, n))
		return NAN;

	for (int i = 0; i < m; i++)
		sum += norm3(&f[3 * i]);
	return sum;
}

/* ---- the run ---- */

double stab_env(const char *name, double def)
{
	const char *v = getenv(name);

	return v && *v ? strtod(v, NULL) : def;
}

double stab_now_ns(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return 1e9 * (double)ts.tv_sec + (double)ts.tv_nsec;
}

static int sites_of(struct irdm_engine *e, const struct irdm_image *img, const struct stab_case *c,
		    struct irdm_contact_site *st)
{
	uint32_t r0 = efx_column_row_near(img, c->at_m);

	assert_int_equal(irdm_engine_site_node(e, r0, &st[0]), 0);
	if (c->sites == STAB_ONE)
		return 1;
	if (c->sites == STAB_SAME_NODE) {
		st[1] = st[0];
		return 2;
	}
	/* the nearest other column */
	double best = INFINITY;
	uint32_t r1 = r0;
	for (uint32_t k = 0; k < img->meta->n_cols; k++) {
		uint32_t r = img->columns[k];
		double d = 0;
		for (int a = 0; a < 3; a++)
			d += pow(img->nodes[r].pos_m[a] - img->nodes[r0].pos_m[a], 2);
		if (r != r0 && d < best) {
			best = d;
			r1 = r;
		}
	}
	assert_int_equal(irdm_engine_site_node(e, r1, &st[1]), 0);
	return 2;
}

/* soft: the tool is already inside (out of a fault), as the controller
 * engages it (irdm_engine_contact_soften()) */
static void begin_all(struct irdm_engine *e, const struct stab_case *c,
		      const struct irdm_contact_site *st, int m, double (*u_prev)[3], bool soft)
{
	for (int i = 0; i < m; i++) {
		assert_int_equal(irdm_engine_contact_begin(e, (unsigned)i, &st[i], c->mode), 0);
		if (soft)
			assert_int_equal(irdm_engine_contact_soften(e, (unsigned)i), 0);
		irdm_engine_node_disp(e, st[i].row[0], u_prev[i]);
	}
}

/* A released push comes back when the device is inside the free surface
 * again, as the proxy does (tests/test_stability.c). */
static void retouch(struct irdm_engine *e, const struct stab_case *c,
		    const struct irdm_contact_site *st, int m, const struct irdm_contact_cmd *cmd,
		    double (*u_prev)[3])
{
	for (int i = 0; i < m && c->mode == IRDM_CONTACT_PUSH; i++) {
		double uf[3];
		if (irdm_engine_contact(e, (unsigned)i)->mode != IRDM_CONTACT_OFF ||
		    cmd[i].mode == IRDM_CONTACT_OFF)
			continue;
		irdm_engine_node_disp(e, st[i].row[0], uf);
		if (cmd[i].target_m[2] < uf[2]) {
			assert_int_equal(irdm_engine_contact_begin(e, (unsigned)i, &st[i], c->mode), 0);
			memcpy(u_prev[i], uf, sizeof(uf));
		}
	}
}

/* What the re-engagement fade may hand the object: per contact |o|
 * (k |o| + b pi |o| / (2 T)), o the offset from the object at rest (after
 * the reset) to the target the case holds (irdm/engine.h). */
static double engage_work_limit(const struct irdm_engine_config *cfg, const struct stab_case *c,
				int m, double dt)
{
	double k = cfg->coupling_k_n_per_m, b = cfg->coupling_b_ns_per_m, lim = 0;
	double fade_s = ceil(cfg->engage_fade_s / dt - 1e-9) * dt;

	for (int i = 0; i < m; i++) {
		double o = fabs(c->depth_m[i]);
		lim += o * (k * o + b * M_PI * o / (2 * fade_s));
	}
	return lim;
}

/* Decimated trace for the plot: about 2000 points per case. */
static FILE *trace_open(const char *name)
{
	const char *out = getenv("IRDM_STAB_OUT");
	char path[512], slug[128];
	size_t i;

	if (!out || !*out)
		return NULL;
	for (i = 0; name[i] && i < sizeof(slug) - 1; i++)
		slug[i] = (char)((name[i] >= 'a' && name[i] <= 'z') || (name[i] >= '0' && name[i] <= '9') ||
						 (name[i] >= 'A' && name[i] <= 'Z') ?
					 name[i] :
					 '_');
	slug[i] = 0;
	snprintf(path, sizeof(path), "%s/trace-%s.tsv", out, slug);
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fprintf(f, "# %s\nt_s\tforce_n\twork_j\n", name);
	return f;
}

static void count_values(struct stab_record *rec, const double *v, int n)
{
	for (int i = 0; i < n; i++) {
		int k = fpclassify(v[i]);
		rec->nonfinite += k == FP_NAN || k == FP_INFINITE;
		rec->subnormal += k == FP_SUBNORMAL;
	}
}

void stab_run(const char *dir, const struct stab_case *c, struct stab_record *rec)
{
	const struct irdm_image *img = stab_image(dir, c->image);
	struct irdm_engine_config cfg;
	struct irdm_contact_site st[STAB_MAX_CONTACTS];
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	double u_prev[STAB_MAX_CONTACTS][3], work = 0, dt = img->meta->dt_s, t_ns = 0;
	unsigned long N = c->ticks, tail = N / 100 ? N / 100 : 1, win = N / 10 ? N / 10 : 1;
	unsigned long every = N / 2000 ? N / 2000 : 1, tail_n = 0;
	stab_target_fn target = c->target ? c->target : stab_step;
	double tail_sum = 0, tail_min = INFINITY, tail_max = -INFINITY;
	int reset_done = 0;
	unsigned long reset_tick = 0, fade_ticks = (unsigned long)ceil(IRDM_ENGINE_ENGAGE_FADE_S / dt - 1e-9);
	double reset_work0 = 0;

	memset(rec, 0, sizeof(*rec));
	rec->work_min_j = INFINITY;
	rec->work_max_j = -INFINITY;
	if (c->coupling == STAB_HAPTIC)
		irdm_engine_config_haptic(&cfg, dt, STAB_DEVICE_K, STAB_DEVICE_B, c->max_force_n);
	else {
		irdm_engine_config_default(&cfg);
		cfg.max_force_n = c->max_force_n;
	}
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;
	int m = sites_of(e, img, c, st);
	FILE *tr = trace_open(c->name);

	begin_all(e, c, st, m, u_prev, false);
	for (unsigned long t = 0; t < N; t++) {
		memset(cmd, 0, sizeof(cmd));
		target(c, t, dt, cmd);
		retouch(e, c, st, m, cmd, u_prev);
		double t0 = stab_now_ns();
		int rc = irdm_engine_tick(e, cmd);
		t_ns += stab_now_ns() - t0;
		if (t + 1 == win) {
			rec->ns_per_tick_first = t_ns / (double)win;
			t_ns = 0;
		}
		for (int i = 0; i < m; i++) {
			double uf[3];
			irdm_engine_node_disp(e, st[i].row[0], uf);
			count_values(rec, uf, 3);
		}
		if (rc && !rec->rc) {
			rec->rc = rc;
			rec->rc_tick = t;
			snprintf(rec->refusal, sizeof(rec->refusal), "%s", irdm_strerror(rc));
		}
		if (rc && c->reset_after_fault && !reset_done) {
			/* out of the fault, as the controller does: zero and touch again */
			irdm_engine_reset(e);
			begin_all(e, c, st, m, u_prev, true);
			reset_done = 1;
			reset_tick = t;
			reset_work0 = work;
			rec->reset_work_limit_j = engage_work_limit(&cfg, c, m, dt);
		}
		double fsum = 0;
		for (int i = 0; i < m; i++) {
			const struct irdm_contact_state *s = irdm_engine_contact(e, (unsigned)i);
			count_values(rec, s->force_n, 3);
			if (s->mode == IRDM_CONTACT_OFF)
				continue;
			count_values(rec, s->disp_m, 3);
			for (int a = 0; a < 3; a++) {
				work += s->force_n[a] * (s->disp_m[a] - u_prev[i][a]);
				u_prev[i][a] = s->disp_m[a];
			}
			fsum += norm3(s->force_n);
		}
		rec->max_f_n = fmax(rec->max_f_n, fsum);
		if (reset_done && t > reset_tick) {
			rec->reset_max_f_n = fmax(rec->reset_max_f_n, fsum);
			if (t <= reset_tick + fade_ticks)
				rec->reset_work_j = fmax(rec->reset_work_j, work - reset_work0);
		}
		if (t + 1 == win)
			rec->first_f_n = fsum;
		rec->work_min_j = fmin(rec->work_min_j, work);
		rec->work_max_j = fmax(rec->work_max_j, work);
		if (t >= N - tail) {
			tail_sum += fsum;
			tail_n++;
			tail_min = fmin(tail_min, fsum);
			tail_max = fmax(tail_max, fsum);
		}
		if (tr && t % every == 0)
			fprintf(tr, "%.6f\t%.9g\t%.9g\n", (double)(t + 1) * dt, fsum, work);
	}
	rec->ns_per_tick_last = t_ns / (double)(N - win ? N - win : 1);
	rec->ticks = N;
	rec->final_f_n = tail_sum / (double)tail_n;
	rec->final_spread_n = tail_max - tail_min;
	const struct irdm_rigid_body *rb = irdm_engine_rigid_body(e);
	if (rb) {
		rec->kinetic_j = irdm_rigid_kinetic_energy_j(rb);
		rec->spin_rad_s = norm3(rb->s.omega_body_rad_s);
	}
	rec->singular = irdm_engine_stats(e)->singular_solves;
	rec->releases = irdm_engine_stats(e)->releases;
	rec->static_f_n = NAN;
	if (c->static_rel_tol > 0) {
		double p[6] = { 0 };
		for (int i = 0; i < m; i++)
			p[3 * i + 2] = -c->depth_m[i];
		rec->static_f_n = static_force(img, st, m, c->coupling == STAB_HAPTIC ? cfg.coupling_k_n_per_m : 0,
					       p);
	}
	if (tr)
		fclose(tr);
	irdm_session_close(ses);
}

/* ---- checks and the table ---- */

void stab_report(const char *name, const struct stab_record *r, double max_f_limit_n,
		 double energy_tol_j, const char *note)
{
	const char *out = getenv("IRDM_STAB_OUT");

	print_message("%-34s max|F| %9.4g N (limit %8.3g) held %9.5g N static %9.5g W min %9.2e max %9.2e J "
		      "(tol %.1e) nonfinite %lu subnormal %lu %s%s\n",
		      name, r->max_f_n, max_f_limit_n, r->final_f_n, r->static_f_n, r->work_min_j,
		      r->work_max_j, energy_tol_j, r->nonfinite, r->subnormal, r->rc ? r->refusal : "",
		      note ? note : "");
	if (!out || !*out)
		return;
	char path[512];
	snprintf(path, sizeof(path), "%s/cases.tsv", out);
	FILE *f = fopen(path, "a");
	assert_non_null(f);
	fprintf(f, "%s\t%lu\t%.6g\t%.6g\t%.6g\t%.6g\t%.4g\t%.4g\t%.3g\t%lu\t%lu\t%s\t%lu\t%.4g\t%.4g\t%s\n",
		name, r->ticks, r->max_f_n, max_f_limit_n, r->final_f_n, r->static_f_n, r->work_min_j,
		r->work_max_j, energy_tol_j, r->nonfinite, r->subnormal, r->rc ? r->refusal : "-",
		r->rc ? r->rc_tick : 0, r->ns_per_tick_first, r->ns_per_tick_last, note && *note ? note : "-");
	fclose(f);
}

void stab_check(const struct stab_case *c, const struct stab_record *r)
{
	char note[64] = "";

	if (r->singular || r->releases)
		snprintf(note, sizeof(note), " singular %lu releases %lu", r->singular, r->releases);
	stab_report(c->name, r, c->max_f_limit_n, c->energy_tol_j, note);
	assert_int_equal(r->nonfinite, 0);
	assert_true(r->max_f_n <= c->max_f_limit_n);
	assert_true(r->work_min_j >= -c->energy_tol_j);
	assert_int_equal(r->rc, c->expect_rc);
	if (c->no_releases)
		assert_int_equal(r->releases, 0);
	if (c->reset_after_fault) {
		print_message("%-34s after the reset: max|F| %.4g N (limit %.4g), work over the fade %.3e J (limit %.3e)\n",
			      "", r->reset_max_f_n, c->reset_max_f_limit_n, r->reset_work_j,
			      r->reset_work_limit_j);
		assert_true(r->reset_max_f_n <= c->reset_max_f_limit_n);
		assert_true(r->reset_work_j <= r->reset_work_limit_j);
	}
	if (c->static_rel_tol > 0) {
		assert_true(isfinite(r->static_f_n));
		assert_true(fabs(r->final_f_n - r->static_f_n) <= c->static_rel_tol * r->static_f_n);
	}
}

char stab_dir[64];

int stab_setup(void **state)
{
	(void)state;
	return tf_tmpdir(stab_dir, sizeof(stab_dir), "stab");
}

int stab_teardown(void **state)
{
	(void)state;
	stab_images_free();
	return tf_rmdir(stab_dir);
}
