/* SPDX-License-Identifier: MIT */
/*
 * The layers keep their direction (docs/architecture.md, "Layers"):
 *  - the force tick's objects need neither BLAS nor threads: no undefined
 *    cblas_* / openblas_* / pthread_* / sem_* symbol in any of them, and the
 *    tick-only test binary links without -lopenblas and -lpthread (the
 *    Makefile links tests/test_tick_*.c against the firmware library alone;
 *    its NEEDED entries are checked here too);
 *  - no source under firmware/, hal/ or sim/ reaches outside its layer by a
 *    relative include (the include paths of the Makefile do the rest: a
 *    firmware file that includes a tools header does not compile).
 * Needs IRDM_BUILD (the build directory; `make test` sets it) and runs from
 * the repository root.
 */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

static const char *build_dir(void)
{
	const char *b = getenv("IRDM_BUILD");

	return b ? b : "build";
}

/* Objects of the force tick: everything the tick calls, nothing else.  The
 * deformation worker (BLAS), its thread and the real-time set-up (pthread)
 * are left out on purpose: they run beside the tick, never in it. */
static const char *const tick_globs[] = {
	"firmware/common/*.o",
	"firmware/engine/*.o",
	"firmware/contact/*.o",
	"firmware/image/*.o",
	"firmware/rigid/*.o",
	"firmware/session/session.o",
	"firmware/deform/deform_channel.o",
	"firmware/device/*.o",
	"firmware/board/board_frame.o",
	"firmware/runtime/*.o",
	"firmware/telemetry/telemetry_ring.o",
	"firmware/telemetry/telemetry_hist.o",
};

static const char *const forbidden[] = { "cblas_", "openblas_", "pthread_", "sem_", NULL };

/* Run cmd; every output line goes through check(line); returns the number
 * of lines read and fails on a non-zero exit. */
static size_t each_line(const char *cmd, void (*check)(const char *line, void *ctx), void *ctx)
{
	char line[1024];
	size_t n = 0;
	FILE *p = popen(cmd, "r");

	assert_non_null(p);
	while (fgets(line, sizeof(line), p)) {
		line[strcspn(line, "\n")] = 0;
		check(line, ctx);
		n++;
	}
	assert_int_equal(pclose(p), 0);
	return n;
}

static void no_forbidden_symbol(const char *line, void *ctx)
{
	const char *obj = ctx;

	for (const char *const *f = forbidden; *f; f++)
		if (strstr(line, *f))
			fail_msg("%s: the force tick must not need '%s' (BLAS/threads): %s",
				 obj, *f, line);
}

static void count_line(const char *line, void *ctx)
{
	(void)line;
	(*(size_t *)ctx)++;
}

static void test_tick_objects_need_no_blas_or_threads(void **state)
{
	char cmd[512];
	size_t objects = 0;

	(void)state;
	for (size_t i = 0; i < sizeof(tick_globs) / sizeof(tick_globs[0]); i++) {
		size_t found = 0;

		snprintf(cmd, sizeof(cmd), "ls %s/obj/%s 2>/dev/null", build_dir(), tick_globs[i]);
		each_line(cmd, count_line, &found);
		if (!found)
			fail_msg("no object matches %s/obj/%s: build first", build_dir(), tick_globs[i]);
		snprintf(cmd, sizeof(cmd), "for o in %s/obj/%s; do nm -u \"$o\" | sed \"s|^|$o: |\"; done",
			 build_dir(), tick_globs[i]);
		each_line(cmd, no_forbidden_symbol, (void *)tick_globs[i]);
		objects += found;
	}
	assert_true(objects >= 10);
}

/* Control: the deformation worker does need BLAS, so the check above can
 * see such a symbol when it is there. */
static void test_control_worker_needs_blas(void **state)
{
	char cmd[512];
	size_t hits = 0;

	(void)state;
	snprintf(cmd, sizeof(cmd), "nm -u %s/obj/firmware/deform/*.o | grep 'cblas_'", build_dir());
	each_line(cmd, count_line, &hits);
	assert_true(hits >= 1);
}

static void no_blas_or_thread_library(const char *line, void *ctx)
{
	(void)ctx;
	if (strstr(line, "openblas") || strstr(line, "libblas") || strstr(line, "pthread") ||
	    strstr(line, "cholmod") || strstr(line, "arpack"))
		fail_msg("the tick-only binary depends on %s", line);
}

static void test_tick_binary_links_firmware_alone(void **state)
{
	char cmd[512];
	size_t needed = 0;

	(void)state;
	snprintf(cmd, sizeof(cmd), "ls %s/tests/test_tick_* 2>/dev/null", build_dir());
	each_line(cmd, count_line, &needed);
	if (!needed)
		fail_msg("no %s/tests/test_tick_* binary: build it first", build_dir());
	snprintf(cmd, sizeof(cmd),
		 "for b in %s/tests/test_tick_*; do readelf -d \"$b\" | grep NEEDED; done", build_dir());
	needed = each_line(cmd, no_blas_or_thread_library, NULL);
	assert_true(needed >= 1);       /* libc at least: the check saw the list */
	snprintf(cmd, sizeof(cmd),
		 "for b in %s/tests/test_tick_*; do nm -u \"$b\"; done", build_dir());
	each_line(cmd, no_forbidden_symbol, "test_tick_*");
}

static void no_relative_include(const char *line, void *ctx)
{
	(void)ctx;
	fail_msg("include escapes its layer: %s", line);
}

static void test_no_relative_include_out_of_a_layer(void **state)
{
	(void)state;
	each_line("grep -rn '#include \"\\.\\./' firmware hal sim 2>/dev/null || true",
		  no_relative_include, NULL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_tick_objects_need_no_blas_or_threads),
		cmocka_unit_test(test_control_worker_needs_blas),
		cmocka_unit_test(test_tick_binary_links_firmware_alone),
		cmocka_unit_test(test_no_relative_include_out_of_a_layer),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
