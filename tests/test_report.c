/* SPDX-License-Identifier: MIT */
/*
 * irdm report on its tiny configuration (2x2x4 cuboid, 2 ms, the step):
 * the figures it writes checked against expectations it does not compute.
 *   - modal:all f64 is the reference's own model run by the engine's
 *     recursion: its force error is rounding (1.2e-12 measured) and its
 *     surface error too (7.8e-15);
 *   - fir:100 (all modes, f64) is a truncated FIR: its recorded recursion
 *     is unstable (the image's certificate, radius > 1), and the raw
 *     recursion the report runs for 20 s grows like radius^ticks: the
 *     growth's per-tick rate matches the certificate's radius (to 2.5e-4
 *     in log, measured);
 *   - every row's bytes are its image file's size;
 *   - the force errors of the truncated representations, recomputed here
 *     from the kept images with the engine tests' own brute-force
 *     reference (tests/support/engine_fixture.c) and their own engine
 *     loop, agree with the report's to 1e-6.
 */
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "irdm/session.h"
#include "support/engine_fixture.h"
#include "support/report_fixture.h"
#include "support/run_prog.h"
#include "support/test_files.h"

static char dir[256];
static struct rfx_row rows[8];
static int n_rows;
static struct rfx_row rows_again[8];

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

static int setup(void **state)
{
	(void)state;
	if (rfx_run(dir, sizeof(dir), "tiny"))
		return -1;
	n_rows = rfx_read_csv(dir, "tiny", rows, 8);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	return rfx_remove(dir);
}

static const struct rfx_row *row_of(const char *repr)
{
	return rfx_row_of(rows, n_rows, repr, NULL);
}

static void test_rows(void **state)
{
	(void)state;
	assert_int_equal(n_rows, 3);
	for (int i = 0; i < n_rows; i++) {
		assert_float_equal(rows[i].dt_ms, 2.0, 0);
		assert_string_equal(rows[i].scenario, "step");
		assert_int_equal(rows[i].ticks, 1500); /* 3 s at 2 ms */
		assert_true(rows[i].median_us > 0 && rows[i].p99_us >= rows[i].median_us);
	}
}

/* The exact model run by the engine agrees with the reference's convolution. */
static void test_exact_model_is_rounding(void **state)
{
	const struct rfx_row *r = row_of("modal:all/f64");

	(void)state;
	printf("modal:all f64 against the reference: force %.2e, surface %.2e\n", r->force_err,
	       r->disp_err);
	assert_true(r->force_err < 1e-11);
	assert_true(r->disp_err < 1e-13);
	assert_true(r->cert_stable && r->bounded);
	assert_true(r->radius < 1.0);
	assert_true(isnan(r->growth)); /* modal: no raw FIR run */
}

/* A truncated FIR: unstable by the certificate, and its raw recursion grows
 * at the certificate's rate (our own convolution, not the certificate). */
static void test_truncated_fir_unstable(void **state)
{
	const struct rfx_row *r = row_of("fir:100");
	double ticks = 20.0 / 0.002, rate = log(r->growth) / ticks;

	(void)state;
	printf("fir:100: radius %.6f, raw growth %.3e (rate %.6f per tick, log radius %.6f), force error %.3g\n",
	       r->radius, r->growth, rate, log(r->radius), r->force_err);
	assert_int_equal(r->paper, 1);
	assert_int_equal(r->cert_stable, 0);
	assert_true(r->radius > 1.01);
	assert_true(isfinite(r->growth) && r->growth > 1e50);
	assert_true(fabs(rate - log(r->radius)) < 2.5e-3);
	/* the engine's tail damping keeps the run bounded, at a cost */
	assert_true(r->bounded);
	assert_true(r->force_err > 0.1);
}

/* Truncated modes with a static correction: the held force is exact
 * (the correction is K^-1's residual), the first ticks are not. */
static void test_truncated_modal(void **state)
{
	const struct rfx_row *r = row_of("modal:20+sc");

	(void)state;
	assert_true(r->cert_stable && r->bounded);
	assert_true(r->first10 > 0.1);
}

static void test_bytes_are_file_sizes(void **state)
{
	static const char *const files[][2] = {
		{ "modal:all/f64", "tiny-modal_all_f64-2ms.img" },
		{ "fir:100", "tiny-fir_100-2ms.img" },
		{ "modal:20+sc", "tiny-modal_20+sc-2ms.img" },
	};

	(void)state;
	for (size_t i = 0; i < sizeof(files) / sizeof(files[0]); i++) {
		char path[512];
		struct stat st;

		snprintf(path, sizeof(path), "%s/%s", dir, files[i][1]);
		assert_int_equal(stat(path, &st), 0);
		assert_int_equal(row_of(files[i][0])->bytes, (size_t)st.st_size);
	}
}

/* The report's error figures against the same figures computed here. */
static void test_errors_recomputed(void **state)
{
	static const char *const reprs[][2] = {
		{ "modal:20+sc", "tiny-modal_20+sc-2ms.img" },
		{ "fir:100", "tiny-fir_100-2ms.img" },
	};
	const size_t N = 1500;
	const double top[3] = { 0.05, 0.05, 0.2 };
	double *F = malloc(N * 3 * sizeof(double)), *Fref = malloc(N * 3 * sizeof(double));
	double *target = malloc(N * 3 * sizeof(double));
	struct irdm_image ref, img;
	struct irdm_contact_site site;
	struct irdm_engine_config cfg;
	struct irdm_session *ses;
	char path[512], err[512];

	(void)state;
	assert_non_null(F);
	assert_non_null(Fref);
	assert_non_null(target);
	for (size_t t = 0; t < N; t++) {
		target[3 * t] = target[3 * t + 1] = 0;
		target[3 * t + 2] = -0.01;
	}
	snprintf(path, sizeof(path), "%s/tiny-reference-2ms.img", dir);
	assert_int_equal(irdm_image_map(path, 0, &ref, err, sizeof(err)), 0);
	irdm_engine_config_default(&cfg);
	ses = efx_session(&ref, &cfg);
	assert_int_equal(irdm_engine_site_node(ses->eng, efx_column_row_near(&ref, top), &site), 0);
	irdm_session_close(ses);
	efx_reference(&ref, &site, 1, N, target, Fref);
	for (size_t i = 0; i < sizeof(reprs) / sizeof(reprs[0]); i++) {
		const struct rfx_row *r = row_of(reprs[i][0]);
		double whole, first, after;

		snprintf(path, sizeof(path), "%s/%s", dir, reprs[i][1]);
		assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
		rfx_engine_grab(&img, top, target, N, F);
		irdm_image_unmap(&img);
		whole = efx_rel_rms(F, Fref, 3 * N);
		first = efx_rel_rms(F, Fref, 30);
		after = efx_rel_rms(F + 300, Fref + 300, 3 * (N - 100));
		printf("%s: force error %.6e (report %.6e), first 10 %.6e (%.6e), from 100 %.6e (%.6e)\n",
		       reprs[i][0], whole, r->force_err, first, r->first10, after, r->after100);
		assert_true(fabs(whole / r->force_err - 1) < 1e-6);
		assert_true(fabs(first / r->first10 - 1) < 1e-6);
		assert_true(fabs(after / r->after100 - 1) < 1e-6);
	}
	irdm_image_unmap(&ref);
	free(F);
	free(Fref);
	free(target);
}

/* The Markdown names the paper's setting of this configuration unstable,
 * and points to the error-target view. */
static void test_markdown(void **state)
{
	char path[512], text[65536];

	(void)state;
	snprintf(path, sizeof(path), "%s/report.md", dir);
	tf_read_text(path, text, sizeof(text));
	assert_non_null(strstr(text, "**The paper's setting** (fir:100 at 2 ms)"));
	assert_non_null(strstr(text, "(**unstable**)"));
	assert_non_null(strstr(text, "| **fir:100 (paper)** | 2 ms | **no**"));
	assert_non_null(strstr(text, "(measurements/error-targets.md)"));
}

/* How many entries of d begin with prefix. */
static int entries(const char *d, const char *prefix)
{
	DIR *dp = opendir(d);
	struct dirent *e;
	int n = 0;

	assert_non_null(dp);
	while ((e = readdir(dp)))
		n += !strncmp(e->d_name, prefix, strlen(prefix));
	closedir(dp);
	return n;
}

/* irdm report -o DIR: a directory it did not write is refused, untouched,
 * unless --force; what it wrote before is replaced; nothing beside DIR
 * is touched.  --repr keeps the runs short. */
static void test_output_dir(void **state)
{
	char base[320], foreign[400], mine[420], sibling[400], marker[420], csv[420], err[4096];
	char text[64];
	const char *args[] = { "report", "--config", "tiny", "--repr", "modal:20+sc", "-o", foreign,
			       "-q", NULL, NULL };
	struct stat st;

	(void)state;
	snprintf(base, sizeof(base), "%s", dir);
	*strrchr(base, '/') = '\0';
	snprintf(foreign, sizeof(foreign), "%s/foreign", base);
	snprintf(mine, sizeof(mine), "%s/mine.txt", foreign);
	snprintf(sibling, sizeof(sibling), "%s/sibling.txt", base);
	snprintf(marker, sizeof(marker), "%s/.irdm-output", foreign);
	snprintf(csv, sizeof(csv), "%s/report-tiny.csv", foreign);
	assert_int_equal(mkdir(foreign, 0755), 0);
	tf_write_text(mine, "a user's notes\n");
	tf_write_text(sibling, "beside\n");
	/* not irdm report's: refused before any work, naming the file */
	assert_int_equal(rp_run(base, irdm_path(), args, NULL, 0, err, sizeof(err)), 1);
	assert_non_null(strstr(err, "foreign/mine.txt: not written by irdm report"));
	assert_ptr_equal(strchr(err, '\n'), err + strlen(err) - 1);
	tf_read_text(mine, text, sizeof(text));
	assert_string_equal(text, "a user's notes\n");
	assert_int_not_equal(stat(csv, &st), 0);
	assert_int_equal(entries(base, "foreign."), 0);
	/* --force: replaced whole, the sibling kept */
	args[8] = "--force";
	if (rp_run(base, irdm_path(), args, NULL, 0, err, sizeof(err)))
		fail_msg("irdm report --force: %s", err);
	assert_int_not_equal(stat(mine, &st), 0);
	assert_int_equal(stat(marker, &st), 0);
	assert_int_equal(stat(csv, &st), 0);
	tf_read_text(sibling, text, sizeof(text));
	assert_string_equal(text, "beside\n");
	/* its own output, again without --force: replaced */
	args[8] = NULL;
	tf_write_text(csv, "stale\n");
	if (rp_run(base, irdm_path(), args, NULL, 0, err, sizeof(err)))
		fail_msg("irdm report over its own output: %s", err);
	assert_int_equal(rfx_read_csv(foreign, "tiny", rows_again, 8), 1);
	assert_string_equal(rows_again[0].repr, "modal:20+sc");
	tf_read_text(sibling, text, sizeof(text));
	assert_string_equal(text, "beside\n");
	assert_int_equal(entries(base, "foreign."), 0);
}

static void test_bad_config(void **state)
{
	const char *args[] = { "report", "--config", "nope", "-o", dir, NULL };
	char err[1024];

	(void)state;
	assert_int_equal(rp_run(dir, irdm_path(), args, NULL, 0, err, sizeof(err)), 2);
	assert_non_null(strstr(err, "--config nope: not one of sweep, paper, floating, tiny, tiny-floating"));
}

static void test_bad_repr(void **state)
{
	const char *args[] = { "report", "--config", "tiny", "--repr", "fir:7", "-o", dir, NULL };
	char err[1024];

	(void)state;
	assert_int_equal(rp_run(dir, irdm_path(), args, NULL, 0, err, sizeof(err)), 2);
	assert_non_null(strstr(err, "--repr fir:7: not a representation of configuration tiny"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rows),
		cmocka_unit_test(test_exact_model_is_rounding),
		cmocka_unit_test(test_truncated_fir_unstable),
		cmocka_unit_test(test_truncated_modal),
		cmocka_unit_test(test_bytes_are_file_sizes),
		cmocka_unit_test(test_errors_recomputed),
		cmocka_unit_test(test_markdown),
		cmocka_unit_test(test_output_dir),
		cmocka_unit_test(test_bad_config),
		cmocka_unit_test(test_bad_repr),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
