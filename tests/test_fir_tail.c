/* SPDX-License-Identifier: MIT */
/*
 * An FIR that is stable and accurate (fir_tail = window:L,
 * tools/precompute/fir_tail.c) on the paper's setting at the tests'
 * resolution: its cuboid, material and damping, 4 x 4 x 8 cells, FIR
 * T = 500 at 2 ms, the top-centre node pushed 1 cm and held for 12 s.
 *
 * The FIR is synthesised from all modes (method = modal, modes = all), so
 * its first T samples are the exact response and "exact" has one meaning:
 * the exact force is the all-modes modal image run through the engine
 * (the modal recursion, a different code path from the FIR sum;
 * test_engine checks it against a direct convolution to 4e-13), and the
 * static force is S^-1 u with S = sum_k phi_k phi_k^T / omega_k^2 summed
 * here from that image's modes.  The old stabilisation (the whole tail
 * damped by r^s) runs on the same FIR without the window, for the figures.
 *
 * fir_tail = window, the FIR default, chooses L: the paper's fir:500 gets
 * window:1000 (the image fir_tail = window:1000 makes), fir:100 doubles to
 * window:800, fir:20 is refused after window:320 (16T); fir_tail = none
 * by name still makes the bare FIR.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "image/image_response.h"
#include "support/engine_fixture.h"
#include "irdm/posix/image_map.h"
#include "precompute/precompute.h"

#define T_HEAD 500  /* the paper's T */
#define L_TAIL 1000 /* fir_tail = window:1000 */
#define N_HOLD 6000 /* 12 s at 2 ms */

#define TOP_NODE "box:0.035,0.035,0.199,0.065,0.065,0.201"

static char dir[64];
static struct irdm_image exact, bare, win, win500;

/*
 * Limits, about 5x what was measured with gcc -O2 (2026-11-24) unless
 * said: first T ticks 3.0e-14 (the same f64 taps summed in double either
 * way: rounding); the whole 12 s 5.4e-3 (the window's own error once the
 * head has passed; limit 2x); held force 1e-5 of the static one (limit
 * 1e-4, against 5e-3 required); sum of taps vs S 1.1e-12 (floating cube
 * 4e-14); the engine vs the convolution with the stored taps 9.2e-14.
 */
#define TOL_HEAD 1.5e-13
#define TOL_HOLD_12S 1.1e-2
#define TOL_HELD 1e-4
#define TOL_SUM 1e-11
#define TOL_UNDAMPED 5e-13

static int setup(void **state)
{
	char p[4][128];
	const char *name[4] = { "exact", "bare", "win", "win500" };

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-firtail-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	for (int k = 0; k < 4; k++)
		snprintf(p[k], sizeof(p[k]), "%s/%s.img", dir, name[k]);
	efx_image(&exact, p[0], "resolution", "4,4,8", "representation", "modal:all", "dt", "0.002",
		  "precision", "f64", "touch", "z>=0.2", "display", "touch", NULL);
	/* the FIR images touch the top-centre node alone: the certificate of
	 * 1500 taps costs seconds a column (every column of the top face:
	 * make bench_fir_tail) */
	efx_image(&bare, p[1], "resolution", "4,4,8", "representation", "fir:500", "modes", "all",
		  "uncertified", "yes", "dt", "0.002", "precision", "f64", "touch", TOP_NODE, "display", "touch", NULL);
	efx_image(&win, p[2], "resolution", "4,4,8", "representation", "fir:500", "modes", "all",
		  "fir_tail", "window:1000", "dt", "0.002", "precision", "f64", "touch", TOP_NODE,
		  "display", "touch", NULL);
	efx_image(&win500, p[3], "resolution", "4,4,8", "representation", "fir:500", "modes", "all",
		  "uncertified", "yes", "fir_tail", "window:500", "dt", "0.002", "precision", "f64", "touch", TOP_NODE,
		  "display", "touch", NULL);
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&exact);
	irdm_image_unmap(&bare);
	irdm_image_unmap(&win);
	irdm_image_unmap(&win500);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

static const double top[3] = { 0.05, 0.05, 0.2 };

/* The top-centre node pushed 1 cm down at tick 0 and held for n ticks,
 * rigid coupling, default engine configuration. */
static void hold(const struct irdm_image *img, size_t n, double *F)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_site s;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = 1;
	struct irdm_session *ses = efx_session(img, &cfg);
	assert_int_equal(irdm_engine_site_node(ses->eng, efx_column_row_near(img, top), &s), 0);
	assert_int_equal(irdm_engine_contact_begin(ses->eng, 0, &s, IRDM_CONTACT_GRAB), 0);
	memset(cmd, 0, sizeof(cmd));
	cmd[0].mode = IRDM_CONTACT_GRAB;
	cmd[0].target_m[2] = -0.01;
	for (size_t t = 0; t < n; t++) {
		assert_int_equal(irdm_engine_tick(ses->eng, cmd), 0);
		memcpy(&F[3 * t], irdm_engine_contact(ses->eng, 0)->force_n, 3 * sizeof(double));
	}
	irdm_session_close(ses);
}

/* The static compliance at row `row` of an all-modes f64 modal image, from
 * its modes: S = sum_k phi_k phi_k^T / omega_k^2 (floating: the elastic
 * compliance, the rigid modes being no part of the image). */
static void static_compliance_of(const struct irdm_image *img, uint32_t row, double S[9])
{
	const struct irdm_meta *m = img->meta;
	const double *phi = img->mode_shapes; /* f64: [row][3][mode] */

	assert_int_equal(m->precision, IRDM_ELEM_F64);
	assert_int_equal(m->n_modes, m->n_modes_total);
	memset(S, 0, 9 * sizeof(double));
	for (uint32_t k = 0; k < m->n_modes; k++) {
		double w2 = img->modes[k].omega_rad_s * img->modes[k].omega_rad_s;
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				S[3 * i + j] += phi[((size_t)row * 3 + (size_t)i) * m->n_modes + k] *
						phi[((size_t)row * 3 + (size_t)j) * m->n_modes + k] / w2;
	}
}

/* z force for a held 1 cm: the z row of S^-1 times (0, 0, -0.01). */
static double static_force_z(const double S[9])
{
	double det = S[0] * (S[4] * S[8] - S[5] * S[7]) - S[1] * (S[3] * S[8] - S[5] * S[6]) +
		     S[2] * (S[3] * S[7] - S[4] * S[6]);

	return -0.01 * (S[0] * S[4] - S[1] * S[3]) / det;
}

struct figures {
	double head, second, all, held_pct, max_abs;
};

static struct figures measure(const double *F, const double *Fex, double f_static)
{
	struct figures g = { 0 };

	g.head = efx_rel_rms(F, Fex, 3 * T_HEAD);
	g.second = efx_rel_rms(F, Fex, 3 * 500); /* 1 s at 2 ms */
	g.all = efx_rel_rms(F, Fex, 3 * N_HOLD);
	g.held_pct = 100 * (F[3 * N_HOLD - 1] / f_static - 1);
	for (size_t i = 0; i < 3 * N_HOLD; i++)
		g.max_abs = fmax(g.max_abs, fabs(F[i]));
	return g;
}

static void print_figures(const char *what, const struct figures *g, double first100)
{
	print_message("%-28s first 100 ticks %.2e, first T %.2e, first 1 s %.2e, 12 s %.2e; "
		      "held %+.3f %% of static; max |F| %.3f N\n",
		      what, first100, g->head,
		      g->second, g->all, g->held_pct, g->max_abs);
}

/* The target: bounded over 12 s of a held step, the first T ticks exact,
 * the held force the static one; the old r^s beside it. */
static void test_window_hold(void **state)
{
	double *Fex = malloc(3 * N_HOLD * sizeof(double)), *F = malloc(3 * N_HOLD * sizeof(double));
	double S[9];

	(void)state;
	static_compliance_of(&exact, efx_column_row_near(&exact, top), S);
	double f_static = static_force_z(S);
	hold(&exact, N_HOLD, Fex);
	print_message("static force %.6f N; exact force at 12 s %.6f N\n", f_static,
		      Fex[3 * N_HOLD - 1]);
	assert_true(fabs(Fex[3 * N_HOLD - 1] / f_static - 1) < 1e-3); /* rung down */

	hold(&bare, N_HOLD, F); /* radius >= 1: the engine damps by r^s */
	struct figures old = measure(F, Fex, f_static);
	print_figures("old: tail damped by r^s", &old, efx_rel_rms(F, Fex, 300));
	hold(&win, N_HOLD, F);
	struct figures neu = measure(F, Fex, f_static);
	print_figures("new: window:1000", &neu, efx_rel_rms(F, Fex, 300));

	assert_true(neu.head <= TOL_HEAD);
	assert_true(neu.all <= TOL_HOLD_12S);
	assert_true(fabs(neu.held_pct) <= 100 * TOL_HELD);
	/* bounded: never above the exact peak (the first tick's) */
	double ex_max = measure(Fex, Fex, f_static).max_abs;
	assert_true(neu.max_abs <= ex_max * (1 + 1e-9));
	/* and rung down: the last second within 0.1 % of the static force */
	for (size_t t = N_HOLD - 500; t < N_HOLD; t++)
		assert_true(fabs(F[3 * t + 2] / f_static - 1) < 1e-3);
	/* the new one is better where the old one was worst */
	assert_true(old.head > 100 * TOL_HEAD && fabs(old.held_pct) > 1.0);
	free(Fex);
	free(F);
}

/* The largest |sum_s R[s] - S| / max |S| over the windowed image's
 * columns (each at its own row), S from the all-modes image ref. */
static double worst_sum_error(const struct irdm_image *w, const struct irdm_image *ref)
{
	size_t T = w->meta->fir_length;
	double *R = malloc(T * 9 * sizeof(double)), worst = 0;

	assert_non_null(R);
	for (uint32_t c = 0; c < w->meta->n_cols; c++) {
		uint32_t row = w->columns[c];
		double S[9], sum[9] = { 0 }, scale = 0, pos[3];
		assert_int_equal(irdm_image_response(w, c, row, T, R), 0);
		for (size_t s = 0; s < T; s++)
			for (int e = 0; e < 9; e++)
				sum[e] += R[9 * s + (size_t)e];
		for (int a = 0; a < 3; a++)
			pos[a] = w->nodes[row].pos_m[a];
		static_compliance_of(ref, efx_column_row_near(ref, pos), S);
		for (int e = 0; e < 9; e++)
			scale = fmax(scale, fabs(S[e]));
		for (int e = 0; e < 9; e++)
			worst = fmax(worst, fabs(sum[e] - S[e]) / scale);
	}
	free(R);
	return worst;
}

/* The image: flagged, certified, its head the bare FIR's bit for bit and
 * its taps summing to the static compliance at every touchable node. */
static void test_window_image(void **state)
{
	const struct irdm_meta *m = win.meta;
	size_t T = m->fir_length;
	double *Rw = malloc(T * 9 * sizeof(double)), *Rb = malloc(T_HEAD * 9 * sizeof(double));

	(void)state;
	assert_true(m->flags & IRDM_META_FIR_TAIL_WINDOW);
	assert_int_equal(m->fir_exact, T_HEAD);
	assert_int_equal(T, T_HEAD + L_TAIL);
	assert_true(bare.meta->max_spectral_radius >= 1.0);
	print_message("radius: bare FIR %.6f, windowed %.6f\n", bare.meta->max_spectral_radius,
		      m->max_spectral_radius);
	assert_true(m->max_spectral_radius < 1.0);
	for (uint32_t c = 0; c < m->n_cols; c++)
		assert_true(win.stability[c].flags & IRDM_STAB_STABLE);
	for (uint32_t c = 0; c < m->n_cols; c++) {
		assert_int_equal(irdm_image_response(&win, c, win.columns[c], T, Rw), 0);
		assert_int_equal(irdm_image_response(&bare, c, win.columns[c], T_HEAD, Rb), 0);
		assert_memory_equal(Rw, Rb, T_HEAD * 9 * sizeof(double));
	}
	double worst = worst_sum_error(&win, &exact);
	print_message("sum of taps vs static compliance, worst of %u nodes: %.2e\n", m->n_cols, worst);
	assert_true(worst <= TOL_SUM);
	free(Rw);
	free(Rb);
}

/*
 * The engine runs a certified image undamped: its forces are the plain
 * convolution with the stored taps (w[s] = 1), over two wraps of the
 * ring.  window:500 certifies the top-centre node at a radius between the
 * engine's stable_radius (0.999) and 1: damped as before, it would lose
 * its exact head.
 */
static void test_window_undamped(void **state)
{
	const size_t n = 2 * T_HEAD + 2 * 500 + 100;
	double *F = malloc(3 * n * sizeof(double)), *R = malloc(3 * n * sizeof(double));
	double *u = calloc(3 * n, sizeof(double));
	struct irdm_contact_site s;
	struct irdm_engine_config cfg;

	(void)state;
	print_message("window:500 radius %.6f\n", win500.meta->max_spectral_radius);
	assert_true(win500.meta->max_spectral_radius >= 0.999 &&
		    win500.meta->max_spectral_radius < 1.0);
	for (size_t t = 0; t < n; t++)
		u[3 * t + 2] = -0.01;
	hold(&win500, n, F);
	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(&win500, &cfg);
	assert_int_equal(irdm_engine_site_node(ses->eng, efx_column_row_near(&win500, top), &s), 0);
	irdm_session_close(ses);
	efx_reference_tail(&win500, &s, 1, n, u, 1.0, R);
	double err = efx_rel_rms(F, R, 3 * n);
	print_message("engine vs convolution with the stored taps: %.2e\n", err);
	assert_true(err <= TOL_UNDAMPED);
	free(F);
	free(R);
	free(u);
}

/*
 * A floating object: the window restores the elastic compliance (the
 * compliance solve with the rigid part of the load removed), which is
 * the all-modes sum of the same model.  The 12 cm cube, 3 x 3 x 3 cells,
 * every surface node touchable; FIR 20 + window:40 at 1 ms.
 */
static void test_window_floating(void **state)
{
	struct irdm_image ref, w;
	char p[2][128];

	(void)state;
	snprintf(p[0], sizeof(p[0]), "%s/cube-ref.img", dir);
	snprintf(p[1], sizeof(p[1]), "%s/cube-win.img", dir);
	efx_image(&ref, p[0], "mesh", "cube", "resolution", "3,3,3", "floating", "yes",
		  "representation", "modal:all", "precision", "f64", "touch", "surface",
		  "display", "touch", NULL);
	efx_image(&w, p[1], "mesh", "cube", "resolution", "3,3,3", "floating", "yes",
		  "representation", "fir:20", "modes", "all", "fir_tail", "window:40",
		  "precision", "f64", "touch", "surface", "display", "touch",
		  /* 52 of 56 columns above radius 1: the sums are what is tested */
		  "uncertified", "yes", NULL);
	double worst = worst_sum_error(&w, &ref);
	print_message("floating cube: sum of taps vs elastic compliance, worst of %u nodes: %.2e\n",
		      w.meta->n_cols, worst);
	assert_true(worst <= TOL_SUM);
	irdm_image_unmap(&ref);
	irdm_image_unmap(&w);
}

/* ---- fir_tail = window: the FIR default, its length chosen ---------- */

/* A scene from the defaults and pairs (NULL-terminated), precomputed into
 * dir/name; mapped into img (if not NULL) when written. */
static int scene_image(const char *name, const char *const *kv, struct irdm_image *img, char *err,
		       size_t errlen)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	struct irdm_precompute_report rep;
	char path[128];
	int ret;

	irdm_scene_defaults(&sc);
	for (; *kv; kv += 2)
		if (irdm_scene_set(&sc, kv[0], kv[1], "test", err, errlen))
			return -1;
	if (irdm_scene_check(&sc, err, errlen))
		return -1;
	snprintf(path, sizeof(path), "%s/%s.img", dir, name);
	o.out_path = path;
	ret = irdm_precompute(&sc, &o, &rep, err, errlen);
	if (!ret && img)
		ret = irdm_image_map(path, 0, img, err, errlen);
	return ret;
}

/* The image's provenance has the line text. */
static bool has_line(const struct irdm_image *img, const char *text)
{
	char *p = malloc(img->provenance_len + 2), line[128];
	bool found;

	assert_non_null(p);
	p[0] = '\n';
	memcpy(p + 1, img->provenance, img->provenance_len);
	p[img->provenance_len + 1] = '\0';
	snprintf(line, sizeof(line), "\n%s\n", text);
	found = strstr(p, line) != NULL;
	free(p);
	return found;
}

#define PAPER_FIR(T) \
	"resolution", "4,4,8", "representation", T, "modes", "all", "dt", "0.002", "precision", "f64", \
		"touch", TOP_NODE, "display", "touch"

/* The paper's fir:500 with no fir_tail key: window:2T certifies, and the
 * image is the one fir_tail = window:1000 makes, measured within the
 * default max_error. */
static void test_default_is_window(void **state)
{
	static const char *const kv[] = { PAPER_FIR("fir:500"), NULL };
	const struct irdm_image_section *a, *b;
	struct irdm_image img;
	char err[1024];

	(void)state;
	if (scene_image("default", kv, &img, err, sizeof(err)))
		fail_msg("%s", err);
	assert_true(img.meta->flags & IRDM_META_FIR_TAIL_WINDOW);
	assert_int_equal(img.meta->fir_exact, T_HEAD);
	assert_int_equal(img.meta->fir_length, T_HEAD + L_TAIL);
	assert_true(img.meta->max_spectral_radius < 1);
	assert_true(img.meta->flags & IRDM_META_ERROR_MEASURED);
	assert_true(img.meta->measured_error <= 1e-3);
	assert_true(has_line(&img, "fir_tail=window:1000"));
	a = irdm_image_find(&img, IRDM_SEC_FIR);
	b = irdm_image_find(&win, IRDM_SEC_FIR);
	assert_int_equal(a->size, b->size);
	assert_memory_equal(img.base + a->offset, win.base + b->offset, a->size);
	irdm_image_unmap(&img);
}

/* fir:100: window:200 and window:400 do not certify, window:800 does. */
static void test_window_doubles(void **state)
{
	static const char *const kv[] = { PAPER_FIR("fir:100"), "max_error", "none", NULL };
	struct irdm_image img;
	char err[1024];

	(void)state;
	if (scene_image("doubled", kv, &img, err, sizeof(err)))
		fail_msg("%s", err);
	assert_int_equal(img.meta->fir_exact, 100);
	assert_int_equal(img.meta->fir_length, 100 + 800);
	assert_true(img.meta->max_spectral_radius < 1);
	assert_true(has_line(&img, "fir_tail=window:800"));
	irdm_image_unmap(&img);
}

/* fir:20: no window up to 16T certifies: refused, with what was tried. */
static void test_window_refused(void **state)
{
	static const char *const kv[] = { PAPER_FIR("fir:20"), "max_error", "none", NULL };
	char err[1024];

	(void)state;
	assert_int_equal(scene_image("refused", kv, NULL, err, sizeof(err)), IRDM_ENUMERIC);
	assert_non_null(strstr(err, "fir:20 with fir_tail = window:320 is not certified stable"));
	assert_non_null(strstr(err, "(fir_tail = window tried window:40 to window:320)"));
}

/* fir_tail = none by name: the bare FIR, as before the window was the
 * default (the engine damps its tail). */
static void test_none_by_name(void **state)
{
	static const char *const kv[] = { PAPER_FIR("fir:100"), "fir_tail", "none", "uncertified", "yes",
					  "max_error", "none", NULL };
	struct irdm_image img;
	char err[1024];

	(void)state;
	if (scene_image("none", kv, &img, err, sizeof(err)))
		fail_msg("%s", err);
	assert_false(img.meta->flags & IRDM_META_FIR_TAIL_WINDOW);
	assert_int_equal(img.meta->fir_length, 100);
	assert_true(img.meta->max_spectral_radius >= 1);
	assert_true(has_line(&img, "fir_tail=none"));
	irdm_image_unmap(&img);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_window_image),
		cmocka_unit_test(test_window_hold),
		cmocka_unit_test(test_window_undamped),
		cmocka_unit_test(test_window_floating),
		cmocka_unit_test(test_default_is_window),
		cmocka_unit_test(test_window_doubles),
		cmocka_unit_test(test_window_refused),
		cmocka_unit_test(test_none_by_name),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
