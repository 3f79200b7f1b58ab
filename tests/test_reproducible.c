/* SPDX-License-Identifier: MIT */
/*
 * Precomputing the same scene twice gives the same bytes: for every
 * representation, precision, eigensolver and method, with threads.  An image
 * is a build artefact that users compare, cache and sign; a timestamp, an
 * uninitialised padding byte or a thread-order-dependent sum would each
 * break this (and, for the last, the responses themselves).
 */
#define _GNU_SOURCE
#include <fcntl.h>
#include <setjmp.h>
#include <spawn.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "support/test_files.h"

extern char **environ;

static char dir[256];

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

/* Run irdm with argv (NULL-terminated), output to /dev/null; exit status. */
static int run_irdm(const char *const *args)
{
	const char *argv[48];
	posix_spawn_file_actions_t fa;
	int n = 0, status = 0;
	pid_t pid;

	argv[n++] = irdm_path();
	for (; *args && n < 47; args++)
		argv[n++] = *args;
	argv[n] = NULL;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
	posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
	assert_int_equal(posix_spawn(&pid, argv[0], &fa, NULL, (char *const *)argv, environ), 0);
	posix_spawn_file_actions_destroy(&fa);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* Precompute `scene` (options, NULL-terminated) twice; the files must match
 * byte for byte and verify. */
static void precompute_twice(const char *name, const char *const *scene)
{
	const char *args[40];
	char path[2][320];
	unsigned char *img[2];
	size_t len[2], first_diff;
	int n, k;

	for (k = 0; k < 2; k++) {
		snprintf(path[k], sizeof(path[k]), "%s/%s-%d.img", dir, name, k);
		n = 0;
		args[n++] = "precompute";
		args[n++] = "--max_error";
		args[n++] = "none";
		for (const char *const *s = scene; *s; s++)
			args[n++] = *s;
		args[n++] = "-o";
		args[n++] = path[k];
		args[n] = NULL;
		assert_int_equal(run_irdm(args), 0);
		img[k] = (unsigned char *)tf_load(path[k], &len[k]);
	}
	assert_int_equal(len[0], len[1]);
	for (first_diff = 0; first_diff < len[0] && img[0][first_diff] == img[1][first_diff]; first_diff++)
		;
	if (first_diff != len[0])
		fail_msg("%s: images differ first at byte %zu of %zu", name, first_diff, len[0]);
	assert_int_equal(run_irdm((const char *const[]){ "image", "verify", path[0], NULL }), 0);
	free(img[0]);
	free(img[1]);
}

#define BOX "--mesh", "box:0.04,0.04,0.08", "--resolution", "2,2,4", "--fixed", "z<=0", \
	    "--touch", "z>=0.08", "--display", "surface"

static void test_modal_dense_f64(void **state)
{
	(void)state;
	precompute_twice("modal-dense", (const char *const[]){
						BOX, "--representation", "modal:all", "--eigensolver", "dense", NULL });
}

static void test_modal_lanczos_static_f32(void **state)
{
	(void)state;
	precompute_twice("modal-lanczos", (const char *const[]){
						  BOX, "--representation", "modal:12", "--eigensolver", "lanczos",
						  "--static_correction", "yes", "--precision", "f32", NULL });
}

static void test_fir_modal_f16(void **state)
{
	(void)state;
	precompute_twice("fir-f16", (const char *const[]){
					    BOX, "--representation", "fir:50", "--precision", "f16", "--uncertified", "yes",
					    "--fir_tail", "none", NULL });
}

/* Threads split the inputs of the time-domain method: their order must not
 * reach the image. */
static void test_fir_time_domain_threads(void **state)
{
	(void)state;
	precompute_twice("fir-td", (const char *const[]){
					   BOX, "--representation", "fir:40", "--method", "time-domain",
					   "--substeps", "4", "--threads", "2", "--uncertified", "yes", "--fir_tail", "none", NULL });
}

static void test_floating_modal(void **state)
{
	(void)state;
	precompute_twice("floating", (const char *const[]){
					     "--mesh", "cube", "--resolution", "3,3,3", "--floating", "yes",
					     "--touch", "surface", "--display", "surface",
					     "--representation", "modal:20", "--precision", "f32", NULL });
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "repro");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_modal_dense_f64),
		cmocka_unit_test(test_modal_lanczos_static_f32),
		cmocka_unit_test(test_fir_modal_f16),
		cmocka_unit_test(test_fir_time_domain_threads),
		cmocka_unit_test(test_floating_modal),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
