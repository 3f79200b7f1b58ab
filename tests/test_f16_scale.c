/* SPDX-License-Identifier: MIT */
/*
 * Scaled f16 (image section COLUMN_SCALE): a stiff object (E 2e9 Pa,
 * compliances ~1e-9 m/N, below binary16's smallest subnormal) stored as
 * f16, an FIR with a windowed tail and a hybrid (modal 100 + static
 * correction + exact head 128) on the 4 x 4 x 8 cuboid: both written by
 * the precompute, certified stable on every column, and within max_error
 * (1e-3) of the exact model as the precompute measured them.
 *
 * Then every reader of the scaled arrays against the same image with its
 * stored values doubled and its scales halved (the same numbers, exactly:
 * powers of two): the responses read back (irdm_image_response(), which
 * `irdm image export`/`verify`, the report and the error measurement
 * use), the static correction (irdm_image_corr_value()), the engine's
 * forces, free displacements and displacement bound over a push, a hold
 * and a release at two contacts (R[0], the force history with its
 * scale, the head), and the deformation worker's positions.  Each must
 * be bit-identical; a reader that skipped the scale sees values off by 2.
 *
 * Where f16's 11 bits are what misses, the image is refused naming
 * precision = f32: the paper's soft material (E 2e3) as fir:500, whose
 * held force cancels thousands of taps (0.02 off in f16), which f32 meets.
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
#include "irdm/posix/deform_worker.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/session.h"
#include "support/engine_fixture.h"
#include "support/image_fixture.h"
#include "precompute/precompute.h"

/* two touchable nodes at the top face's middle row */
#define TOUCH "box:0.02,0.035,0.199,0.065,0.065,0.201"
#define N_TICKS 400
#define PUSH_END 250
#define N_SAMPLES 40 /* response samples compared */

static char dir[64];
static struct irdm_image fir, hybrid;

static int setup(void **state)
{
	char p[128];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-f16scale-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p, sizeof(p), "%s/fir.img", dir);
	efx_image(&fir, p, "resolution", "4,4,8", "young", "2e9", "representation", "fir:60",
		  "fir_tail", "window:100", "precision", "f16", "touch", TOUCH, "max_error", "1e-3",
		  NULL);
	snprintf(p, sizeof(p), "%s/hybrid.img", dir);
	efx_image(&hybrid, p, "resolution", "4,4,8", "young", "2e9", "representation", "modal:100",
		  "static_correction", "yes", "exact_head", "128", "precision", "f16", "touch", TOUCH,
		  "max_error", "1e-3", NULL);
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&fir);
	irdm_image_unmap(&hybrid);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/* Written (setup), scaled, certified on every column, measured within 1e-3. */
static void check_written(const char *name, const struct irdm_image *img)
{
	const struct irdm_meta *m = img->meta;

	assert_int_equal(m->precision, IRDM_ELEM_F16);
	assert_true(m->flags & IRDM_META_COLUMN_SCALE);
	assert_non_null(img->col_scale);
	for (uint32_t c = 0; c < m->n_cols; c++) {
		/* compliances ~1e-9: the scale is far below 1 */
		assert_true(irdm_image_col_scale(img, c) < 0x1p-20);
		assert_true(img->stability[c].flags & IRDM_STAB_STABLE);
	}
	assert_true(m->max_spectral_radius < 1);
	assert_true(m->flags & IRDM_META_ERROR_MEASURED);
	printf("f16 E 2e9 %-7s %u columns, scales 2^%d, radius %.6f, measured error %.3g\n", name,
	       m->n_cols, ilogb(irdm_image_col_scale(img, 0)), m->max_spectral_radius,
	       (double)m->measured_error);
	assert_true(m->measured_error > 0 && m->measured_error <= 1e-3);
}

static void test_fir_written(void **state)
{
	(void)state;
	check_written("FIR", &fir);
}

static void test_hybrid_written(void **state)
{
	(void)state;
	check_written("hybrid", &hybrid);
	assert_non_null(hybrid.exact_head);
}

/* ---- the same image, stored values x 2 and scales / 2 ------------------ */

struct twin {
	void *buf;
	struct irdm_image img;
};

static void double_f16(uint8_t *p, uint64_t bytes)
{
	for (uint64_t i = 0; i + 1 < bytes; i += 2) {
		uint16_t h;
		memcpy(&h, p + i, 2);
		float f = irdm_f16_to_f32(h);
		assert_true(fabsf(f) <= 0x1p14f); /* the scale's headroom: x 2 is exact */
		h = irdm_f32_to_f16(2 * f);
		memcpy(p + i, &h, 2);
	}
}

static void twin_make(const struct irdm_image *src, struct twin *t)
{
	const uint32_t scaled[] = { IRDM_SEC_FIR, IRDM_SEC_STATIC_CORR, IRDM_SEC_EXACT_HEAD };
	const struct irdm_image_section *s;
	char err[256];
	uint8_t *b;

	t->buf = img_fixture_copy(src->base, src->size);
	assert_non_null(t->buf);
	b = t->buf;
	for (size_t k = 0; k < sizeof(scaled) / sizeof(scaled[0]); k++)
		if ((s = irdm_image_find(src, scaled[k])))
			double_f16(b + s->offset, s->size);
	s = irdm_image_find(src, IRDM_SEC_COLUMN_SCALE);
	assert_non_null(s);
	for (uint64_t c = 0; c < s->size / 4; c++) {
		float f;
		memcpy(&f, b + s->offset + 4 * c, 4);
		f /= 2;
		memcpy(b + s->offset + 4 * c, &f, 4);
	}
	img_fixture_reseal(t->buf, src->size);
	if (irdm_image_parse(t->buf, src->size, &t->img, err, sizeof(err)))
		fail_msg("the twin image: %s", err);
	assert_true(irdm_image_col_scale(&t->img, 0) == irdm_image_col_scale(src, 0) / 2);
}

/* irdm_image_response() and irdm_image_corr_value() at every column pair
 * and (responses) every row. */
static void same_reads(const struct irdm_image *a, const struct irdm_image *b)
{
	const struct irdm_meta *m = a->meta;
	double ra[9 * N_SAMPLES], rb[9 * N_SAMPLES], ca[9], cb[9];

	for (uint32_t c = 0; c < m->n_cols; c++) {
		for (uint32_t r = 0; r < m->n_nodes; r++) {
			assert_int_equal(irdm_image_response(a, c, r, N_SAMPLES, ra), 0);
			assert_int_equal(irdm_image_response(b, c, r, N_SAMPLES, rb), 0);
			assert_memory_equal(ra, rb, sizeof(ra));
		}
		for (uint32_t d = 0; a->corr_start && d < m->n_cols; d++) {
			irdm_image_corr_value(a, c, d, ca);
			irdm_image_corr_value(b, c, d, cb);
			assert_memory_equal(ca, cb, sizeof(ca));
		}
	}
	/* and they are not nothing */
	assert_int_equal(irdm_image_response(a, 0, a->columns[0], N_SAMPLES, ra), 0);
	assert_true(fabs(ra[8]) > 1e-11);
}

/* Contact i's imposed displacement at tick t (10 um: E 2e9 is stiff). */
static void target(unsigned i, size_t t, double u[3])
{
	double ramp = t < 50 ? (double)t / 50 : 1;

	u[0] = i ? 2e-6 * sin(0.05 * (double)t) : 0;
	u[1] = 0;
	u[2] = -(i ? 6e-6 : 1e-5) * ramp;
}

struct trace {
	double f[N_TICKS][2][3];
	double u[N_TICKS][3];
	double bound[N_TICKS];
	double *pos;
};

/* Two contacts pushed, held and released, every tick published to the
 * deformation worker, which updates once, while the contacts hold. */
static void run(const struct irdm_image *img, struct trace *tr)
{
	const double at[2][3] = { { 0.05, 0.05, 0.2 }, { 0.025, 0.05, 0.2 } };
	struct irdm_session_config sc = { .deform = true };
	struct irdm_contact_site site[2];
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_session *ses;
	char err[256];
	uint64_t tick;

	irdm_engine_config_default(&sc.engine);
	sc.engine.publish_every = 1;
	if (irdm_session_open_image(&ses, img, &sc, err, sizeof(err)) ||
	    irdm_session_deform_open(ses, err, sizeof(err)))
		fail_msg("session: %s", err);
	struct irdm_engine *e = ses->eng;
	for (unsigned i = 0; i < 2; i++)
		assert_int_equal(irdm_engine_site_node(e, efx_column_row_near(img, at[i]), &site[i]),
				 IRDM_OK);
	tr->pos = calloc(3 * (size_t)img->meta->n_nodes, sizeof(double));
	assert_non_null(tr->pos);
	for (size_t t = 0; t < N_TICKS; t++) {
		memset(cmd, 0, sizeof(cmd));
		for (unsigned i = 0; i < 2 && t < PUSH_END; i++) {
			if (irdm_engine_contact(e, i)->mode == IRDM_CONTACT_OFF)
				assert_int_equal(irdm_engine_contact_begin(e, i, &site[i],
									   IRDM_CONTACT_GRAB),
						 0);
			cmd[i].mode = IRDM_CONTACT_GRAB;
			target(i, t, cmd[i].target_m);
		}
		if (t == PUSH_END)
			for (unsigned i = 0; i < 2; i++)
				irdm_engine_contact_end(e, i);
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		for (unsigned i = 0; i < 2; i++)
			memcpy(tr->f[t][i], irdm_engine_contact(e, i)->force_n, sizeof(tr->f[t][i]));
		irdm_engine_node_disp(e, site[0].row[0], tr->u[t]);
		tr->bound[t] = irdm_engine_disp_bound(e);
		/* the display while held: the static correction needs a force */
		if (t == PUSH_END - 1)
			assert_true(irdm_deform_update(ses->worker, tr->pos, &tick));
	}
	irdm_session_close(ses);
}

static void same_runs(const struct irdm_image *a, const struct irdm_image *b)
{
	struct trace *ta = calloc(1, sizeof(*ta)), *tb = calloc(1, sizeof(*tb));
	double peak = 0;

	assert_non_null(ta);
	assert_non_null(tb);
	run(a, ta);
	run(b, tb);
	assert_memory_equal(ta->f, tb->f, sizeof(ta->f));
	assert_memory_equal(ta->u, tb->u, sizeof(ta->u));
	assert_memory_equal(ta->bound, tb->bound, sizeof(ta->bound));
	assert_memory_equal(ta->pos, tb->pos, 3 * (size_t)a->meta->n_nodes * sizeof(double));
	for (size_t t = 0; t < N_TICKS; t++)
		peak = fmax(peak, fabs(ta->f[t][0][2]));
	/* a force of newtons for micrometres: the stiff object was touched */
	assert_true(peak > 1);
	free(ta->pos);
	free(tb->pos);
	free(ta);
	free(tb);
}

static void check_twin(const struct irdm_image *img)
{
	struct twin t;

	twin_make(img, &t);
	same_reads(img, &t.img);
	same_runs(img, &t.img);
	free(t.buf);
}

static void test_fir_readers(void **state)
{
	(void)state;
	check_twin(&fir);
}

static void test_hybrid_readers(void **state)
{
	(void)state;
	check_twin(&hybrid);
}

/* The paper's material, fir:500 at 2 ms (window:1000, the default) in
 * precision p, measured; the precompute's return. */
static int soft_fir(const char *p, char *err, size_t errlen)
{
	static const char *const kv[] = { "resolution", "4,4,8", "dt", "0.002", "representation",
					  "fir:500", "modes", "all", "touch", TOUCH, "display", "touch",
					  NULL };
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	struct irdm_precompute_report rep;
	char path[128];
	int ret;

	irdm_scene_defaults(&sc);
	for (const char *const *k = kv; *k; k += 2)
		assert_int_equal(irdm_scene_set(&sc, k[0], k[1], "test", err, errlen), 0);
	assert_int_equal(irdm_scene_set(&sc, "precision", p, "test", err, errlen), 0);
	snprintf(path, sizeof(path), "%s/soft-%s.img", dir, p);
	o.out_path = path;
	ret = irdm_precompute(&sc, &o, &rep, err, errlen);
	if (!ret)
		assert_true(rep.error_measured && rep.measured_error <= 1e-3);
	return ret;
}

static void test_f16_refused_naming_f32(void **state)
{
	char err[1024];

	(void)state;
	assert_int_equal(soft_fir("f16", err, sizeof(err)), IRDM_ENUMERIC);
	printf("soft fir:500 f16: %s\n", err);
	assert_non_null(strstr(err, "above max_error = 0.001; try precision = f32"));
	if (soft_fir("f32", err, sizeof(err)))
		fail_msg("f32: %s", err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fir_written),
		cmocka_unit_test(test_hybrid_written),
		cmocka_unit_test(test_fir_readers),
		cmocka_unit_test(test_hybrid_readers),
		cmocka_unit_test(test_f16_refused_naming_f32),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
