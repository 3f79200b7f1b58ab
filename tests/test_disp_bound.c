/* SPDX-License-Identifier: MIT */
/*
 * irdm_engine_disp_bound() against brute force: over 2000 ticks of a push,
 * hold and release (two contacts, one of them stroking sideways), the bound
 * is >= max over every image node of |irdm_engine_node_disp()| each tick,
 * on modal (all modes f64, 40 modes f32) and FIR images; the ratio bound /
 * max is printed and must stay below a looseness limit.
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

#include "support/engine_fixture.h"
#include "irdm/posix/image_map.h"

#define N_TICKS 2000
#define PUSH_END 700
/* bound / max |u|: the bound adds the modes' (or lags') worst nodes, which
 * are not one node; far looser than this means it is useless for pruning */
#define LOOSE_MAX 50.0

static char dir[64];
static struct irdm_image modal64, modal32, fir, mode1, hybrid;

static int setup(void **state)
{
	char p[128];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-dbound-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p, sizeof(p), "%s/m64.img", dir);
	efx_image(&modal64, p, "resolution", "4,4,8", "representation", "modal:all",
		  "precision", "f64", "touch", "z>=0.2", NULL);
	snprintf(p, sizeof(p), "%s/m32.img", dir);
	efx_image(&modal32, p, "resolution", "4,4,8", "representation", "modal:40",
		  "precision", "f32", "touch", "z>=0.2", NULL);
	snprintf(p, sizeof(p), "%s/mode1.img", dir);
	efx_image(&mode1, p, "resolution", "4,4,8", "representation", "modal:1",
		  "precision", "f64", "touch", "z>=0.2", NULL);
	/* the hybrid: its head's past forces add to the free displacement */
	snprintf(p, sizeof(p), "%s/hybrid.img", dir);
	efx_image(&hybrid, p, "resolution", "4,4,8", "representation", "modal:300",
		  "exact_head", "32", "precision", "f32", "touch", "z>=0.2", NULL);
	snprintf(p, sizeof(p), "%s/fir.img", dir);
	efx_image(&fir, p, "resolution", "4,4,8", "representation", "fir:100", "uncertified", "yes",
		  "touch", "z>=0.2", NULL);
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	irdm_image_unmap(&modal64);
	irdm_image_unmap(&modal32);
	irdm_image_unmap(&hybrid);
	irdm_image_unmap(&fir);
	irdm_image_unmap(&mode1);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

/* max over every image node of |free displacement| (non-columns are 0) */
static double brute_max(const struct irdm_engine *e, uint32_t n_nodes)
{
	double mx = 0, u[3];

	for (uint32_t r = 0; r < n_nodes; r++) {
		irdm_engine_node_disp(e, r, u);
		mx = fmax(mx, sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
	}
	return mx;
}

/* Contact i's imposed displacement at tick t: pushed in over 200 ticks,
 * held (contact 1 strokes sideways), released at PUSH_END. */
static void target(unsigned i, size_t t, double u[3])
{
	double ramp = t < 200 ? (double)t / 200 : 1;

	u[0] = i ? 0.004 * sin(0.01 * (double)t) : 0;
	u[1] = 0;
	u[2] = -(i ? 0.006 : 0.01) * ramp;
}

/* Ratio statistics of one run: worst (largest), best (smallest), mean over
 * ticks with motion. */
struct ratio {
	double worst, best, sum;
	size_t n;
};

static struct ratio run(const char *name, const struct irdm_image *img)
{
	const double at[2][3] = { { 0.05, 0.05, 0.2 }, { 0.025, 0.075, 0.2 } };
	struct irdm_contact_site site[2];
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_engine_config cfg;
	struct ratio q = { 0, INFINITY, 0, 0 };
	double peak = 0;

	irdm_engine_config_default(&cfg);
	struct irdm_session *ses = efx_session(img, &cfg);
	struct irdm_engine *e = ses->eng;

	for (unsigned i = 0; i < 2; i++)
		assert_int_equal(irdm_engine_site_node(e, efx_column_row_near(img, at[i]), &site[i]),
				 IRDM_OK);
	assert_true(irdm_engine_disp_bound(e) == 0); /* at rest */
	for (size_t t = 0; t < N_TICKS; t++) {
		double b = irdm_engine_disp_bound(e), mx = brute_max(e, img->meta->n_nodes);

		if (!(b >= mx))
			fail_msg("%s: tick %zu: bound %.17g < max |u| %.17g", name, t, b, mx);
		if (mx > 1e-9) {
			q.worst = fmax(q.worst, b / mx);
			q.best = fmin(q.best, b / mx);
			q.sum += b / mx;
			q.n++;
		}
		peak = fmax(peak, mx);
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
	}
	printf("disp bound %-24s peak max|u| %.3e m, bound/max: mean %.2f, worst %.2f, best %.9f (%zu ticks)\n",
	       name, peak, q.n ? q.sum / (double)q.n : 0, q.worst, q.best, q.n);
	assert_true(peak > 1e-4); /* the scenario did move the surface */
	assert_true(q.n > 0 && q.worst < LOOSE_MAX);
	irdm_session_close(ses);
	return q;
}

static void test_modal_f64(void **state)
{
	(void)state;
	run("modal all f64", &modal64);
}

static void test_modal_f32(void **state)
{
	(void)state;
	run("modal 40 f32", &modal32);
}

/* One mode: u_v = phi_v yq exactly, so the bound is attained at the node
 * of largest |phi|: a bound off by any factor or node shows here. */
static void test_one_mode_is_tight(void **state)
{
	(void)state;
	struct ratio q = run("modal 1 f64", &mode1);

	assert_true(q.best < 1 + 1e-9);
}

static void test_hybrid(void **state)
{
	(void)state;
	run("hybrid 300 + head 32 f32", &hybrid);
}

static void test_fir(void **state)
{
	(void)state;
	run("fir 100", &fir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_modal_f64),
		cmocka_unit_test(test_modal_f32),
		cmocka_unit_test(test_one_mode_is_tight),
		cmocka_unit_test(test_fir),
		cmocka_unit_test(test_hybrid),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
