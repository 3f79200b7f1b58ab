/* SPDX-License-Identifier: MIT */
/*
 * Build configurations (docs/build-config.md): make test builds irdm-fw
 * with configs/default.config, configs/minimal.config and configs/can.config
 * beside the full build.  For each, against what its config file says:
 *  - the features it leaves out are not in the binary (nm: the entry point
 *    of each feature's file), the ones it keeps are;
 *  - it refuses an image or board needing a feature it lacks, at set-up,
 *    exit 3, one line naming the CONFIG_ switch; BLAS is not even linked
 *    without the deformed surface;
 *  - what it runs, it runs as the full build does: the same press on the
 *    same image and board gives a byte-identical log;
 *  - the HAL back-ends it leaves out are not registered, and without a
 *    simulated one (sim, canemu) the simulator is not linked at all (nm:
 *    no irdm_sim_ symbol); a board naming a left-out back-end is refused,
 *    exit 3, one line naming the board's line and the CONFIG_ switch;
 *  - trimming shrinks it: text full > default > minimal > can.
 * And irdm image config writes the configuration an image and board need;
 * make refuses a malformed config.
 * Needs IRDM, IRDM_FW and IRDM_BUILD (make test sets them).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support/run_prog.h"
#include "support/test_files.h"

enum { FULL,
       DEFAULT,
       MINIMAL,
       CAN,
       N_BUILDS };
enum { MODAL,
       FIR,
       FLOATING,
       DEFORM,
       HAL_SIM,
       HAL_CANEMU,
       HAL_SOCKETCAN,
       N_FEATURES };

static const char *const build_name[N_BUILDS] = { "full", "default", "minimal", "can" };
static const char *const feature_name[N_FEATURES] = {
	"MODAL",
	"FIR",
	"FLOATING",
	"DEFORM",
	"HAL_SIM",
	"HAL_CANEMU",
	"HAL_SOCKETCAN",
};
/* one function each feature's files define and the tick or set-up calls;
 * a back-end's: its ops table, which only its registration reaches */
static const char *const feature_symbol[N_FEATURES] = {
	"irdm_modal_apply",
	"irdm_fir_apply",
	"irdm_rigid_step",
	"irdm_deform_update",
	"irdm_hal_sim_backend",
	"irdm_hal_canemu_backend",
	"irdm_hal_socketcan_backend",
};

static char dir[256], fw[N_BUILDS][320], out[16384], err[4096];
static char img_modal[320], img_fir[320], img_cube[320], board_nodeform[320];
static bool on[N_BUILDS][N_FEATURES];

static const char *env_or(const char *name, const char *dflt)
{
	const char *p = getenv(name);

	return p ? p : dflt;
}

/* The config file is the specification: CONFIG_IRDM_X=y|n lines. */
static void read_config(const char *path, bool feat[N_FEATURES])
{
	char text[4096], want[64];

	tf_read_text(path, text, sizeof(text));
	for (int f = 0; f < N_FEATURES; f++) {
		snprintf(want, sizeof(want), "\nCONFIG_IRDM_%s=y", feature_name[f]);
		feat[f] = strstr(text, want) != NULL;
		snprintf(want, sizeof(want), "\nCONFIG_IRDM_%s=n", feature_name[f]);
		assert_true(feat[f] != (strstr(text, want) != NULL));
	}
}

static int sh(const char *cmd)
{
	return rp_run(dir, "/bin/sh", (const char *const[]){ "-c", cmd, NULL }, out, sizeof(out),
		      err, sizeof(err));
}

static void test_left_out_features_are_absent(void **state)
{
	char cmd[2048];

	(void)state;
	/* in the binary, and in its libraries, core and platform (left out of
	 * the build, not merely unlinked) */
	for (int b = 0; b < N_BUILDS; b++)
		for (int f = 0; f < HAL_SIM; f++)
			for (int lib = 0; lib < 2; lib++) {
				snprintf(cmd, sizeof(cmd), "nm %s | grep -c ' T %s$' || true", fw[b],
					 feature_symbol[f]);
				if (lib)
					snprintf(cmd, sizeof(cmd), "d=$(dirname %s); nm $d/libirdmfw.a "
								   "$d/libirdmposix.a | grep -c ' T %s$' || true",
						 fw[b],
						 feature_symbol[f]);
				assert_int_equal(sh(cmd), 0);
				if ((atoi(out) == 1) != on[b][f])
					fail_msg("%s build's %s: %s (%s) is %s", build_name[b],
						 lib ? "libirdmfw.a + libirdmposix.a" : "irdm-fw", feature_name[f],
						 feature_symbol[f], on[b][f] ? "missing" : "still there");
			}
	/* BLAS only with the deformed surface */
	for (int b = 0; b < N_BUILDS; b++) {
		snprintf(cmd, sizeof(cmd), "readelf -d %s | grep -c 'libopenblas' || true", fw[b]);
		assert_int_equal(sh(cmd), 0);
		assert_int_equal(atoi(out) > 0, on[b][DEFORM]);
	}
}

/* How many symbols of nm's listing of irdm-fw of build b match the regex. */
static int nm_count(int b, const char *regex)
{
	char cmd[2048];

	snprintf(cmd, sizeof(cmd), "nm %s | grep -c '%s' || true", fw[b], regex);
	assert_int_equal(sh(cmd), 0);
	return atoi(out);
}

static void test_left_out_backends_are_absent(void **state)
{
	char regex[128];

	(void)state;
	for (int b = 0; b < N_BUILDS; b++) {
		bool simulated = on[b][HAL_SIM] || on[b][HAL_CANEMU];
		int n_sim;

		for (int f = HAL_SIM; f < N_FEATURES; f++) {
			snprintf(regex, sizeof(regex), " [RrDd] %s$", feature_symbol[f]);
			if ((nm_count(b, regex) == 1) != on[b][f])
				fail_msg("%s build: %s (%s) is %s", build_name[b], feature_name[f],
					 feature_symbol[f], on[b][f] ? "missing" : "still there");
		}
		/* the simulator whole: the arm, the user, the drive emulator */
		n_sim = nm_count(b, " irdm_sim_");
		print_message("%s build: %d irdm_sim_ symbols\n", build_name[b], n_sim);
		if ((n_sim > 0) != simulated)
			fail_msg("%s build: %d irdm_sim_ symbols %s a simulated back-end",
				 build_name[b], n_sim, simulated ? "with" : "without");
	}
	assert_false(on[CAN][HAL_SIM] || on[CAN][HAL_CANEMU]);
}

static void expect_refusal(int b, const char *board, const char *image, const char *needle)
{
	int rc = rp_run(dir, fw[b], (const char *const[]){ "--board", board, "--image", image, "--clock", "virtual", "--duration", "0.1", NULL }, out, sizeof(out), err,
			sizeof(err));

	if (rc != 3 || !strstr(err, needle) || strchr(err, '\n') != err + strlen(err) - 1)
		fail_msg("%s build on %s: expected exit 3 naming '%s', got %d: %s", build_name[b],
			 image, needle, rc, err);
}

static void test_refuses_what_it_lacks(void **state)
{
	(void)state;
	expect_refusal(DEFAULT, "boards/sim-phantom.board", img_fir,
		       "the image holds FIR responses; this build has CONFIG_IRDM_FIR off");
	expect_refusal(DEFAULT, "boards/sim-phantom-cube.board", img_cube,
		       "the image holds a floating object; this build has CONFIG_IRDM_FLOATING off");
	expect_refusal(MINIMAL, "boards/sim-phantom.board", img_modal,
		       "this build has CONFIG_IRDM_DEFORM off");
	/* a board on a back-end the build left out, by its line */
	expect_refusal(CAN, "boards/sim-phantom.board", img_modal,
		       "boards/sim-phantom.board:15: hal = sim: not built in this irdm-fw "
		       "(CONFIG_IRDM_HAL_SIM)");
	expect_refusal(CAN, "boards/canemu-3dof.board", img_modal,
		       "boards/canemu-3dof.board:20: hal = canemu: not built in this irdm-fw "
		       "(CONFIG_IRDM_HAL_CANEMU)");
	/* and runs what it has */
	assert_int_equal(rp_run(dir, fw[MINIMAL], (const char *const[]){ "--board", board_nodeform, "--image", img_modal, "--clock", "virtual", "--duration", "0.5", "-q", NULL },
				out, sizeof(out), err, sizeof(err)),
			 0);
}

/* The press on the default build and the full one: the same log, byte for byte. */
static void test_same_run_as_the_full_build(void **state)
{
	char log[2][320];
	char *bytes[2];
	size_t len[2];

	(void)state;
	for (int k = 0; k < 2; k++) {
		snprintf(log[k], sizeof(log[k]), "%s/press%d.log", dir, k);
		if (rp_run(dir, fw[k == 0 ? FULL : DEFAULT], (const char *const[]){ "--board", "boards/sim-phantom.board", "--image", img_modal, "--user", "scenes/users/press-hold-release.user", "--clock", "virtual", "--log", log[k], "-q", NULL }, out, sizeof(out), err, sizeof(err)))
			fail_msg("%s build: %s", k ? "default" : "full", err);
		bytes[k] = tf_load(log[k], &len[k]);
	}
	print_message("press run: full and default builds, logs of %zu and %zu bytes\n", len[0],
		      len[1]);
	assert_int_equal(len[0], len[1]);
	assert_memory_equal(bytes[0], bytes[1], len[0]);
	free(bytes[0]);
	free(bytes[1]);
}

static long text_size(const char *bin)
{
	char cmd[512];

	snprintf(cmd, sizeof(cmd), "size %s | tail -n 1", bin);
	assert_int_equal(sh(cmd), 0);
	return atol(out);
}

static void test_trimming_shrinks(void **state)
{
	long t[N_BUILDS];

	(void)state;
	for (int b = 0; b < N_BUILDS; b++)
		t[b] = text_size(fw[b]);
	print_message("irdm-fw text: full %ld, default %ld, minimal %ld, can %ld bytes\n", t[FULL],
		      t[DEFAULT], t[MINIMAL], t[CAN]);
	assert_true(t[FULL] > t[DEFAULT] && t[DEFAULT] > t[MINIMAL] && t[MINIMAL] > t[CAN]);
}

static void expect_config(const char *image, const char *board, const char *want)
{
	const char *args[6] = { "image", "config", image, NULL, NULL, NULL };

	if (board) {
		args[3] = "--board";
		args[4] = board;
	}
	assert_int_equal(rp_run(dir, env_or("IRDM", "build/irdm"), args, out, sizeof(out), err,
				sizeof(err)),
			 0);
	if (!strstr(out, want))
		fail_msg("irdm image config %s: '%s' lacks '%s'", image, out, want);
}

static void test_image_config_and_bad_configs(void **state)
{
	char bad[320], cmd[1024];

	(void)state;
	expect_config(img_modal, "boards/sim-phantom.board",
		      "CONFIG_IRDM_MODAL=y\nCONFIG_IRDM_FIR=n\nCONFIG_IRDM_FLOATING=n\n"
		      "CONFIG_IRDM_DEFORM=y\n");
	expect_config(img_fir, NULL, "CONFIG_IRDM_MODAL=n\nCONFIG_IRDM_FIR=y\n");
	expect_config(img_cube, board_nodeform, "CONFIG_IRDM_FLOATING=y\nCONFIG_IRDM_DEFORM=n\n");
	/* what the default scene on its board needs is configs/default.config */
	snprintf(bad, sizeof(bad), "%s/bad.config", dir);
	tf_write_text(bad, "CONFIG_IRDM_MODAL=y\nCONFIG_IRDM_FIR=maybe\nCONFIG_IRDM_FLOATING=n\n"
			   "CONFIG_IRDM_DEFORM=n\n");
	snprintf(cmd, sizeof(cmd), "make -n CONFIG=%s all", bad);
	assert_int_not_equal(sh(cmd), 0);
	assert_non_null(strstr(err, "CONFIG_IRDM_FIR must be y or n, got 'maybe'"));
	tf_write_text(bad, "CONFIG_IRDM_MODAL=n\nCONFIG_IRDM_FIR=n\nCONFIG_IRDM_FLOATING=n\n"
			   "CONFIG_IRDM_DEFORM=n\n");
	assert_int_not_equal(sh(cmd), 0);
	assert_non_null(strstr(err, "the engine needs one"));
	/* a back-end's switch may be left unsaid (built), not misspelt */
	tf_write_text(bad, "CONFIG_IRDM_MODAL=y\nCONFIG_IRDM_FIR=n\nCONFIG_IRDM_FLOATING=n\n"
			   "CONFIG_IRDM_DEFORM=n\nCONFIG_IRDM_HAL_SIM=no\n");
	assert_int_not_equal(sh(cmd), 0);
	assert_non_null(strstr(err, "CONFIG_IRDM_HAL_SIM must be y or n, got 'no'"));
}

static void precompute(char *path, const char *name, const char *const *args)
{
	const char *argv[24] = { "precompute", "-q", "--max_error", "none" };
	int n = 4;

	snprintf(path, 320, "%s/%s.img", dir, name);
	for (; *args && n < 20; args++)
		argv[n++] = *args;
	argv[n++] = "-o";
	argv[n++] = path;
	argv[n] = NULL;
	if (rp_run(dir, env_or("IRDM", "build/irdm"), argv, out, sizeof(out), err, sizeof(err)))
		fail_msg("precompute %s: %s", name, err);
}

static int setup(void **state)
{
	const char *build = env_or("IRDM_BUILD", "build");
	char text[16384], *p;

	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "buildcfg"))
		return -1;
	snprintf(fw[FULL], sizeof(fw[FULL]), "%s", env_or("IRDM_FW", "build/irdm-fw"));
	for (int b = DEFAULT; b < N_BUILDS; b++) {
		char cfg[128];

		snprintf(fw[b], sizeof(fw[b]), "%s/cfg-%s/irdm-fw", build, build_name[b]);
		snprintf(cfg, sizeof(cfg), "configs/%s.config", build_name[b]);
		read_config(cfg, on[b]);
	}
	read_config("configs/full.config", on[FULL]);
	precompute(img_modal, "modal", (const char *const[]){ "--scene", "scenes/cuboid-paper.scene", "--resolution", "2,2,4", "--representation", "modal:10", NULL });
	precompute(img_fir, "fir", (const char *const[]){ "--scene", "scenes/cuboid-paper.scene", "--resolution", "2,2,4", "--representation", "fir:20", "--dt", "0.001", "--uncertified", "yes", "--fir_tail", "none", NULL });
	precompute(img_cube, "cube", (const char *const[]){ "--scene", "scenes/cube-floating.scene", "--resolution", "2,2,2", "--representation", "modal:10", NULL });
	/* the shipped board without the deformed surface */
	tf_read_text("boards/sim-phantom.board", text, sizeof(text));
	p = strstr(text, "deform_rate_hz");
	assert_non_null(p);
	memcpy(p, "#eform_rate_hz", 14);
	snprintf(board_nodeform, sizeof(board_nodeform), "%s/nodeform.board", dir);
	strncat(text, "\ndeform_rate_hz = 0\n", sizeof(text) - strlen(text) - 1);
	tf_write_text(board_nodeform, text);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_left_out_features_are_absent),
		cmocka_unit_test(test_left_out_backends_are_absent),
		cmocka_unit_test(test_refuses_what_it_lacks),
		cmocka_unit_test(test_same_run_as_the_full_build),
		cmocka_unit_test(test_trimming_shrinks),
		cmocka_unit_test(test_image_config_and_bad_configs),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
