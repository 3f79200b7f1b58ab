/* SPDX-License-Identifier: MIT */
/*
 * The force tick alone, as the controller will run it: open a session on an
 * image, begin a contact, tick, close.  This binary links the firmware core
 * library, libm and cmocka only (Makefile: tests/core/): that it links at
 * all shows the session and the tick need no platform service (no file
 * mapping, BLAS or threads).  The image file is read here, with stdio, and
 * handed to the core's session as the platform's mapping would be
 * (irdm_session_open_with()).
 *
 * The image comes from the environment, IRDM_TICK_IMAGE (a test without it
 * fails: it must not pass by skipping).  make test makes it with
 *   irdm precompute --mesh box:0.04,0.04,0.08 --resolution 2,2,4 \
 *     --fixed 'z<=0' --touch 'z>=0.08' --display surface \
 *     --representation modal:all -o IMAGE
 *
 * The first tick of a step is checked against the image's own data by a
 * second method: with no history, the displacement imposed at a node is
 * R[0] f, so f = R[0]^-1 u, R[0] read here from the raw sections
 * (modal: sum_k phi_k phi_k^T b_k[0] + the static correction block; FIR:
 * the first tap) and solved by Cramer's rule.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support/tick_image.h"

#include "irdm/engine.h"
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/precision.h"
#include "irdm/session.h"

#define N_TICKS 1000
#define STEP_M 0.001
#define IMAGE_MAX_BYTES (64u << 20)

/* The platform's part, done by the test: the file into aligned memory,
 * then the core's parser.  unmaps counts the releases. */
static int unmaps;

static int test_map(const char *path, unsigned flags, struct irdm_image *img, char *err,
		    size_t errlen)
{
	FILE *f = fopen(path, "rb");
	void *buf = NULL;
	long n = -1;
	int rc;

	(void)flags;
	memset(img, 0, sizeof(*img));
	if (f && !fseek(f, 0, SEEK_END))
		n = ftell(f);
	if (n > 0 && n <= (long)IMAGE_MAX_BYTES && !fseek(f, 0, SEEK_SET))
		buf = aligned_alloc(64, ((size_t)n + 63) & ~(size_t)63);
	if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
		snprintf(err, errlen, "%s: cannot read", path);
		free(buf);
		if (f)
			fclose(f);
		return IRDM_EIO;
	}
	fclose(f);
	rc = irdm_image_parse(buf, (size_t)n, img, err, errlen);
	if (rc)
		free(buf);
	return rc;
}

static void test_unmap(struct irdm_image *img)
{
	free((void *)img->base);
	memset(img, 0, sizeof(*img));
	unmaps++;
}

/* Mode shape k at image node row, axis i. */
static double phi(const struct irdm_image *img, uint32_t row, int i, size_t k)
{
	size_t K = img->meta->n_modes;

	return irdm_elem_get(img->mode_shapes, img->meta->precision,
			     ((size_t)row * 3 + (size_t)i) * K + k);
}

/* R[0] block of column col on itself: displacement per force (m/N). */
static void r0_self(const struct irdm_image *img, uint32_t col, double R[9])
{
	const struct irdm_meta *m = img->meta;
	uint32_t row = img->columns[col], prec = m->precision;
	double S[9];

	memset(R, 0, 9 * sizeof(double));
	if (m->representation == IRDM_REPR_FIR) {
		size_t b = ((size_t)col * m->n_nodes + row) * m->fir_length * 9;
		for (int i = 0; i < 9; i++)
			R[i] = irdm_elem_get(img->fir, prec, b + (size_t)i);
		return;
	}
	/* kept block + far field (none in the tick image: modal:all) */
	irdm_image_corr_value(img, col, col, S);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) {
			for (size_t k = 0; k < m->n_modes; k++)
				R[3 * i + j] += phi(img, row, i, k) * phi(img, row, j, k) *
						img->modes[k].b[0];
			R[3 * i + j] += S[3 * i + j];
		}
}

static double det3(const double a[9])
{
	return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
	       a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* x = a^-1 b by Cramer's rule: a method the engine does not use. */
static void solve3(const double a[9], const double b[3], double x[3])
{
	double d = det3(a);

	assert_true(fabs(d) > 0);
	for (int c = 0; c < 3; c++) {
		double ac[9];
		memcpy(ac, a, sizeof(ac));
		for (int r = 0; r < 3; r++)
			ac[3 * r + c] = b[r];
		x[c] = det3(ac) / d;
	}
}

static double norm3(const double v[3])
{
	return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static void test_step_at_a_node(void **state)
{
	struct irdm_session_config sc = { .deform = false };
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_contact_site site;
	struct irdm_session *s;
	double R[9], f_ref[3];
	char err[512];
	uint32_t col;

	(void)state;
	irdm_engine_config_default(&sc.engine);
	sc.engine.max_contacts = 1;
	if (irdm_session_open_with(&s, tick_image_path(), &sc, test_map, test_unmap, err,
				   sizeof(err)))
		fail_msg("session: %s", err);
	assert_null(s->deform);
	assert_true(s->img->meta->n_cols > 0);
	col = s->img->meta->n_cols / 2;
	assert_int_equal(irdm_engine_site_node(s->eng, s->img->columns[col], &site), 0);
	assert_int_equal(irdm_engine_contact_begin(s->eng, 0, &site, IRDM_CONTACT_GRAB), 0);

	/* 1 mm into the surface, held */
	memset(cmd, 0, sizeof(cmd));
	cmd[0].mode = IRDM_CONTACT_GRAB;
	for (int a = 0; a < 3; a++)
		cmd[0].target_m[a] = -STEP_M * site.normal[a];
	if (norm3(site.normal) == 0)
		cmd[0].target_m[2] = -STEP_M;
	r0_self(s->img, col, R);
	solve3(R, cmd[0].target_m, f_ref);

	for (int t = 0; t < N_TICKS; t++) {
		const struct irdm_contact_state *c;
		assert_int_equal(irdm_engine_tick(s->eng, cmd), 0);
		c = irdm_engine_contact(s->eng, 0);
		assert_int_equal(c->mode, IRDM_CONTACT_GRAB);
		/* rigid coupling: the point is where it was put */
		for (int a = 0; a < 3; a++) {
			assert_true(isfinite(c->force_n[a]));
			assert_true(fabs(c->disp_m[a] - cmd[0].target_m[a]) <= 1e-9 * STEP_M);
		}
		if (t == 0) {
			double d[3] = { c->force_n[0] - f_ref[0], c->force_n[1] - f_ref[1],
					c->force_n[2] - f_ref[2] };
			print_message("first tick: F = (%.9g, %.9g, %.9g) N, R[0]^-1 u = (%.9g, %.9g, %.9g) N\n",
				      c->force_n[0], c->force_n[1], c->force_n[2], f_ref[0],
				      f_ref[1], f_ref[2]);
			assert_true(norm3(f_ref) > 0);
			assert_true(norm3(d) <= 1e-9 * norm3(f_ref));
		}
	}
	assert_int_equal(irdm_engine_stats(s->eng)->ticks, N_TICKS);
	unmaps = 0;
	irdm_session_close(s);
	assert_int_equal(unmaps, 1); /* the session gave its image back */
}

static void test_open_errors(void **state)
{
	struct irdm_session_config sc = { .deform = false };
	struct irdm_session *s = (struct irdm_session *)&sc;
	char err[512] = "";

	(void)state;
	irdm_engine_config_default(&sc.engine);
	/* no such file: the loader's error, nothing left behind */
	assert_int_equal(irdm_session_open_with(&s, "/nonexistent/irdm-tick.img", &sc, test_map,
						test_unmap, err, sizeof(err)),
			 IRDM_EIO);
	assert_null(s);
	assert_true(err[0] != '\0');
	/* a configuration the engine refuses: the image goes back too */
	sc.engine.max_contacts = IRDM_MAX_CONTACTS + 1;
	unmaps = 0;
	assert_int_equal(irdm_session_open_with(&s, tick_image_path(), &sc, test_map, test_unmap,
						err, sizeof(err)),
			 IRDM_EINVAL);
	assert_null(s);
	assert_int_equal(unmaps, 1);
	irdm_session_close(NULL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_step_at_a_node),
		cmocka_unit_test(test_open_errors),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
