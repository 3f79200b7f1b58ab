/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw end to end, on the simulated board with the virtual user:
 *  - bad arguments, boards and images: one line naming the thing and the
 *    reason, the documented exit code, the torque never enabled;
 *  - virtual time is deterministic: two runs write byte-identical logs;
 *  - the object rings after release at the frequency modal superposition
 *    predicts (computed here from the image: the mode with the largest
 *    static amplitude at the touched node), not at one the loop invents;
 *  - --require-rt refuses a kernel that is not PREEMPT_RT (checked here
 *    independently) and runs on one that is;
 *  - SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGALRM, a real-time signal
 *    mid-contact: torque off and state off in the next tick, the reason
 *    logged, exit 6; SIGXFSZ ignored; SIGSEGV, SIGSYS: the emergency path,
 *    exit 8; signals pending at start: the run ends in the set-up, exit 6,
 *    no drive enabled, no escalation (tests/apps/irdm-fw/test_fw_signals.c has every
 *    signal, and the escalation, in detail);
 *  - the image file truncated or written over under a running loop: the
 *    run goes on to its end on its own copy;
 *  - a run whose limits never let the torque on exits 7 naming the limit;
 *  - two arms: the image's two-contact figure printed under the one-contact
 *    one, as the image holds it, or "not measured"; one arm: no such line;
 *  - --frame-at: the deformed surface in VTK, checked physically (a dent
 *    at the pressed top centre, a still bottom) and byte-identical in
 *    virtual time;
 *  - --doc boards prints the board key table (what make docs
 *    splices into docs/boards.md), exit 0, and runs nothing.
 * Needs IRDM and IRDM_FW (make test sets them); runs from the repository root.
 */
#define _GNU_SOURCE
#include <fcntl.h>
#include <glob.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/board.h"
#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/options_doc.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/vec3.h"
#include "irdm/safety.h"
#include "irdm/telemetry.h"
#include "support/run_prog.h"
#include "support/test_files.h"

extern char **environ;

#define BOARD "boards/sim-phantom.board"
#define PRESS "scenes/users/press-hold-release.user"

static char dir[256], image[320], out_text[16384], err_text[8192];

static const char *env_or(const char *name, const char *dflt)
{
	const char *p = getenv(name);

	return p ? p : dflt;
}

/* Start prog with args (NULL-terminated); stdout/stderr to files. */
static pid_t spawn(const char *prog, const char *const *args)
{
	return rp_spawn(dir, prog, args);
}

static int finish(pid_t pid)
{
	return rp_finish(dir, pid, out_text, sizeof(out_text), err_text, sizeof(err_text));
}

static int run_fw(const char *const *args)
{
	return finish(spawn(env_or("IRDM_FW", "build/irdm-fw"), args));
}

static void expect_error(int rc, int code, const char *needle)
{
	if (rc != code || !strstr(err_text, needle) || strncmp(err_text, "irdm-fw: ", 9) != 0 ||
	    strchr(err_text, '\n') != err_text + strlen(err_text) - 1)
		fail_msg("expected exit %d with one line naming '%s'; got %d: %s", code, needle, rc,
			 err_text);
}

/* BOARD with one key's line replaced (key = value), into dir/NAME. */
static const char *board_with(const char *name, const char *key, const char *value)
{
	static char path[320];
	char text[16384], out[16384] = "", *line, *save;

	tf_read_text(BOARD, text, sizeof(text));
	/* line by line, empty ones kept: the messages' line numbers are BOARD's */
	for (line = text; *line; line = save) {
		char repl[256];

		save = line + strcspn(line, "\n");
		if (*save)
			*save++ = 0;
		if (!strncmp(line, key, strlen(key)) && line[strlen(key)] == ' ') {
			snprintf(repl, sizeof(repl), "%s = %s", key, value);
			line = repl;
		}
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	tf_write_text(path, out);
	return path;
}

/*
 * docs/hal-options.md is what `irdm-fw --doc hal-options` writes from the
 * back-ends' option tables, the key table of docs/boards.md what
 * `--doc boards` writes; --help-board lists the board keys and every
 * back-end's options with their defaults.
 */
static void test_generated_docs_current(void **state)
{
	static char doc[16384];
	static const char begin[] = "<!-- begin board keys -->\n";
	char *a, *b;

	(void)state;
	tf_read_text("docs/hal-options.md", doc, sizeof(doc));
	assert_int_equal(run_fw((const char *const[]){ "--doc", "hal-options", NULL }), 0);
	if (strcmp(out_text, doc))
		fail_msg("docs/hal-options.md is not what `irdm-fw --doc hal-options` writes");
	tf_read_text("docs/boards.md", doc, sizeof(doc));
	a = strstr(doc, begin);
	b = a ? strstr(a, "<!-- end board keys -->") : NULL;
	assert_non_null(b);
	*b = 0;
	assert_int_equal(run_fw((const char *const[]){ "--doc", "boards", NULL }), 0);
	if (strcmp(out_text, a + strlen(begin)))
		fail_msg("docs/boards.md's key table is not what `irdm-fw --doc boards` writes");
	assert_int_equal(run_fw((const char *const[]){ "--help-board", NULL }), 0);
	assert_non_null(strstr(out_text, "  watchdog_us = N           one tick longer than this "
					 "faults; > period_us\n                            "
					 "(default 5000); 1 <= watchdog_us <= 1000000 us\n"));
	assert_non_null(strstr(out_text, "hal_options of hal = sim (key=value words; "
					 "docs/hal-options.md):\n  write_delay = K"));
	assert_non_null(strstr(out_text, "hal_options of hal = canemu"));
	assert_non_null(strstr(out_text, "hal_options of hal = socketcan"));
}

/*
 * Each refusal names the thing, the place and the reason: a hal_options
 * word the back-end's option table refuses, at the board's line, a value
 * no device has at its line, a --user board whose back-end does not exist
 * or has no simulated arm, a frame period shorter than the deformation's
 * before the run, and --help hinted once.
 */
static void test_clear_messages(void **state)
{
	const char *b;

	(void)state;
	b = board_with("opts.board", "hal_options", "write_delay=0,frobnicate=3");
	expect_error(run_fw((const char *const[]){ "--board", b, "--image", image, "--clock",
						   "virtual", NULL }),
		     4, "opts.board:16: hal_options: unknown sim option 'frobnicate' "
			"(see docs/hal-options.md)\n");
	b = board_with("delay.board", "hal_options", "write_delay=999");
	expect_error(run_fw((const char *const[]){ "--board", b, "--image", image, "--clock",
						   "virtual", NULL }),
		     4, "delay.board:16: hal_options: write_delay = 999: must be <= 16\n");
	b = board_with("gear.board", "gear_ratio", "1e-300,1e-300,1e-300");
	expect_error(run_fw((const char *const[]){ "--board", b, "--image", image, "--clock",
						   "virtual", NULL }),
		     3, "gear.board:27: gear_ratio = 1e-300,1e-300,1e-300: joint 1: must be >= 0.01");
	b = board_with("cpr.board", "counts_per_rev", "1e300,4000,4000");
	expect_error(run_fw((const char *const[]){ "--board", b, "--image", image, "--clock",
						   "virtual", NULL }),
		     3, "cpr.board:26: counts_per_rev = 1e300,4000,4000: joint 1: must be <=");
	b = board_with("nohal.board", "hal", "teleport");
	expect_error(run_fw((const char *const[]){ "--board", b, "--image", image, "--user",
						   PRESS, "--clock", "virtual", NULL }),
		     3, "nohal.board: hal 'teleport': no such back-end in this build");
	/* a back-end without a simulated arm has nothing for a hand to push */
	expect_error(run_fw((const char *const[]){ "--board", "boards/can-3dof.board", "--image",
						   image, "--user", PRESS, "--clock", "virtual",
						   NULL }),
		     3, "--user " PRESS ": a virtual user needs a back-end with a simulated arm, "
			"and boards/can-3dof.board's hal 'socketcan' has none (hal = sim or canemu)");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock",
						   "virtual", "--frames-every", "0.001", "--frames-out",
						   "/nonexistent/never", NULL }),
		     2, "--frames-every 0.001: shorter than the deformation period, 0.01 s");
	expect_error(run_fw((const char *const[]){ "--bogus", NULL }), 2,
		     "--bogus: unknown option 'bogus' (see irdm-fw --help)");
	assert_null(strstr(strstr(err_text, "--help") + 1, "--help"));
}

/* The board keys, not irdm-fw's own options, and nothing else: no board or
 * image is needed, none is read. */

static void test_bad_input(void **state)
{
	char bad_board[320], img2[320];

	(void)state;
	expect_error(run_fw((const char *const[]){ "--image", image, NULL }), 2, "--board");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--frobnicate",
						   "1", NULL }),
		     2, "frobnicate");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock",
						   "sundial", NULL }),
		     2, "sundial");
	expect_error(run_fw((const char *const[]){ "--board", "/nonexistent.board", "--image", image,
						   NULL }),
		     3, "/nonexistent.board");
	snprintf(bad_board, sizeof(bad_board), "%s/bad.board", dir);
	tf_write_text(bad_board, "name = x\nhal = sim\nperiod_us = -5\n");
	expect_error(run_fw((const char *const[]){ "--board", bad_board, "--image", image, NULL }), 3,
		     "bad.board:3");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", "/nonexistent.img",
						   NULL }),
		     3, "EIO");
	/* a 2 ms image on a 1 ms board */
	snprintf(img2, sizeof(img2), "%s/dt2.img", dir);
	{
		pid_t p = spawn(env_or("IRDM", "build/irdm"), (const char *const[]){
								      "precompute", "-q", "--mesh", "cuboid", "--resolution", "2,2,4", "--fixed", "z<=0",
								      "--touch", "z>=0.2", "--display", "touch", "--representation", "modal:10",
								      "--dt", "0.002", "--max_error", "none", "-o", img2, NULL });
		assert_int_equal(finish(p), 0);
	}
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", img2, NULL }), 3,
		     "period_us");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--user",
						   "/nonexistent.user", "--clock", "virtual", NULL }),
		     3, "/nonexistent.user");
	/* a hand that would grab the stylus 5 cm from where it rests; two
	 * hands on a one-arm board */
	{
		char far_user[320], two_user[320];

		snprintf(far_user, sizeof(far_user), "%s/far.user", dir);
		tf_write_text(far_user, "place 1 at 0.05,0.05,0.26\nhold 1 for 1\n");
		expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
							   "--user", far_user, "--clock", "virtual",
							   NULL }),
			     3, "far.user: hand 1: first placed 5.0 cm from where the tip rests");
		snprintf(two_user, sizeof(two_user), "%s/two.user", dir);
		tf_write_text(two_user, "place 1 at home\nplace 2 at home\n");
		expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
							   "--user", two_user, "--clock", "virtual",
							   NULL }),
			     3, "uses 2 hands, the board has 1 device");
	}
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock",
						   "virtual", "--require-rt", NULL }),
		     2, "--require-rt");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
						   "--frame-at", "1", NULL }),
		     2, "--frame-out");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock",
						   "virtual", "--duration", "1", "--frame-at", "2",
						   "--frame-out", "/nonexistent/f.vtk", NULL }),
		     2, "after the run's end");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock",
						   "virtual", "--duration", "0.1", "--frame-at",
						   "0.05", "--frame-out", "/nonexistent/f.vtk", NULL }),
		     4, "/nonexistent/f.vtk");
}

static void test_virtual_runs_are_identical(void **state)
{
	char log[2][320];
	char *bytes[2];
	size_t len[2];

	(void)state;
	for (int k = 0; k < 2; k++) {
		snprintf(log[k], sizeof(log[k]), "%s/run%d.log", dir, k);
		assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
							       "--user", PRESS, "--clock", "virtual",
							       "--log", log[k], "-q", NULL }),
				 0);
		bytes[k] = tf_load(log[k], &len[k]);
	}
	assert_int_equal(len[0], len[1]);
	assert_true(len[0] > IRDM_LOG_HEADER_SIZE + 6000 * IRDM_TICK_RECORD_SIZE);
	assert_memory_equal(bytes[0], bytes[1], len[0]);
	free(bytes[0]);
	free(bytes[1]);
}

static double phi(const struct irdm_image *img, uint32_t row, int axis, uint32_t k)
{
	return irdm_elem_get(img->mode_shapes, img->meta->precision,
			     ((size_t)row * 3 + (size_t)axis) * img->meta->n_modes + k);
}

/*
 * After a vertical push at node c is released, mode k moves c by
 * phi_kz(c)^2 F / omega_k^2 (modal superposition of the static
 * deflection): the mode of largest amplitude sets the ringing, at its
 * damped frequency.
 */
static double predicted_ringing_hz(const double touch_m[3])
{
	struct irdm_image img;
	char err[256];
	uint32_t best_row = 0, best_k = 0;
	double best_d = INFINITY, best_a = 0;

	assert_int_equal(irdm_image_map(image, 0, &img, err, sizeof(err)), 0);
	for (uint32_t r = 0; r < img.meta->n_nodes; r++) {
		double d = 0;
		for (int a = 0; a < 3; a++)
			d += pow(img.nodes[r].pos_m[a] - touch_m[a], 2);
		if (d < best_d) {
			best_d = d;
			best_row = r;
		}
	}
	for (uint32_t k = 0; k < img.meta->n_modes; k++) {
		double w = img.modes[k].omega_rad_s, a = pow(phi(&img, best_row, 2, k), 2) / (w * w);
		if (a > best_a) {
			best_a = a;
			best_k = k;
		}
	}
	best_d = img.modes[best_k].omega_rad_s * sqrt(1 - pow(img.modes[best_k].zeta, 2)) /
		 (2 * M_PI);
	irdm_image_unmap(&img);
	return best_d;
}

static void test_release_ringing_is_the_dominant_mode(void **state)
{
	const double top_centre[3] = { 0.05, 0.05, 0.2 };
	double hz, ref;
	const char *p;

	(void)state;
	assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--user",
						       PRESS, "--clock", "virtual", NULL }),
			 0);
	p = strstr(out_text, "release ringing: ");
	assert_non_null(p);
	assert_int_equal(sscanf(p, "release ringing: %lf Hz", &hz), 1);
	ref = predicted_ringing_hz(top_centre);
	print_message("release ringing %.3f Hz; dominant mode at the top centre %.3f Hz\n", hz, ref);
	/* measured 0.002 Hz apart; the scan steps 0.01 Hz: two steps */
	assert_true(fabs(hz - ref) <= 0.02);
	assert_non_null(strstr(out_text, "state: off"));
}

/*
 * The summary's force line gives both the force on the object and the one
 * rendered on the tip: on a board whose max_force_n (0.2 N) is below the
 * press's peak, the object-side peak is above it and the rendered one is
 * the clamp's, to the printed digits.
 */
static void test_summary_rendered_force(void **state)
{
	char text[16384], out[16384] = "", *line, *save, path[320];
	double obj, at_obj, rend, at_rend;
	const char *p;

	(void)state;
	tf_read_text(BOARD, text, sizeof(text));
	for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		if (!strncmp(line, "max_force_n", 11))
			line = "max_force_n = 0.2";
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	snprintf(path, sizeof(path), "%s/weak.board", dir);
	tf_write_text(path, out);
	assert_int_equal(run_fw((const char *const[]){ "--board", path, "--image", image, "--user",
						       PRESS, "--clock", "virtual", NULL }),
			 0);
	p = strstr(out_text, "force: peak ");
	assert_non_null(p);
	assert_int_equal(sscanf(p, "force: peak %lf N at %lf s on the object, %lf N at %lf s rendered",
				&obj, &at_obj, &rend, &at_rend),
			 4);
	print_message("summary: %.4f N on the object, %.4f N rendered (max_force_n 0.2 N)\n", obj,
		      rend);
	assert_true(obj > 0.25);
	assert_true(fabs(rend - 0.2) <= 5e-5);
}

/*
 * Two arms: the image's force error is one contact's, so irdm-fw says
 * what two at once are worth too, as the image says it (the precompute's
 * two-contact figure), or that it was not measured; one arm, no such line.
 */
static void test_two_arms_see_the_two_contact_figure(void **state)
{
	static const char pinch[] = "boards/sim-phantom-pinch.board";
	char path[320], err[256], want[128];
	struct irdm_image img;
	const char *fw_args[] = { "--board", pinch, "--image", image, "--user", "scenes/users/pinch.user",
				  "--clock", "virtual", "--duration", "0.01", NULL };

	(void)state;
	assert_int_equal(run_fw(fw_args), 0);
	assert_non_null(strstr(out_text, "\nimage: two contacts at once: force error not measured\n"));
	assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--user",
						       PRESS, "--clock", "virtual", "--duration", "0.01",
						       NULL }),
			 0);
	assert_null(strstr(out_text, "two contacts"));

	snprintf(path, sizeof(path), "%s/measured.img", dir);
	assert_int_equal(finish(spawn(env_or("IRDM", "build/irdm"), (const char *const[]){
									    "precompute", "-q", "--mesh", "cuboid", "--resolution", "4,4,8", "--fixed", "z<=0",
									    "--touch", "z>=0.2", "--display", "touch", "-o", path, NULL })),
			 0);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	assert_true(img.two_contacts_error > 0 && img.two_contacts_error < 0.1);
	snprintf(want, sizeof(want), "\nimage: two contacts at once: force error %.3g against the exact model\n",
		 img.two_contacts_error);
	irdm_image_unmap(&img);
	fw_args[3] = path;
	assert_int_equal(run_fw(fw_args), 0);
	if (!strstr(out_text, want))
		fail_msg("expected '%s' in: %s", want + 1, out_text);
	unlink(path);
}

static bool kernel_is_rt(void)
{
	char buf[64] = "";
	FILE *f = fopen("/sys/kernel/realtime", "r");

	if (f) {
		bool rt = fgets(buf, sizeof(buf), f) && buf[0] == '1';
		fclose(f);
		return rt;
	}
	f = popen("uname -v", "r");
	assert_non_null(f);
	if (!fgets(buf, sizeof(buf), f))
		buf[0] = 0;
	pclose(f);
	return strstr(buf, "PREEMPT_RT") != NULL;
}

static void test_require_rt(void **state)
{
	int rc;

	(void)state;
	rc = run_fw((const char *const[]){ "--board", BOARD, "--image", image, "--clock", "real",
					   "--require-rt", "--duration", "0.2", NULL });
	if (kernel_is_rt()) {
		print_message("PREEMPT_RT kernel: --require-rt may run: %s", out_text);
		assert_true(rc == 0 || (rc == 4 && strstr(err_text, "EPERM")));
		return;
	}
	expect_error(rc, 4, "EPERM");
	assert_non_null(strstr(err_text, "not PREEMPT_RT"));
}

/*
 * The shipped board with overruns and the watchdog relaxed: on a loaded
 * host (or under ASan) a real-time run may overrun, and this test is about
 * the signal, not the overrun policy (tests/test_controller.c has that).
 */
static void relaxed_board(char *path, size_t len)
{
	char text[16384], out[16384] = "", *line, *save;

	tf_read_text(BOARD, text, sizeof(text));
	for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		if (!strncmp(line, "overrun_fault_count", 19))
			line = "overrun_fault_count = 1000";
		else if (!strncmp(line, "watchdog_us", 11))
			line = "watchdog_us = 1000000";
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	snprintf(path, len, "%s/relaxed.board", dir);
	tf_write_text(path, out);
}

/* The log's records: how many, how many in contact from tick `from` on,
 * and the last one. */
static uint64_t read_log(const char *log, uint64_t from, uint64_t *contact_ticks,
			 struct irdm_tick_record *last)
{
	struct irdm_tick_record rec;
	struct irdm_log_reader *r;
	char err[256];
	uint64_t n = 0;

	*contact_ticks = 0;
	assert_int_equal(irdm_log_open(&r, log, err, sizeof(err)), 0);
	memset(last, 0, sizeof(*last));
	while (irdm_log_next(r, &rec, err, sizeof(err)) == 1) {
		*contact_ticks += rec.tick >= from && rec.dev[0].contact_tri != IRDM_TELEM_NO_TRI;
		*last = rec;
		n++;
	}
	irdm_log_close(r);
	return n;
}

static void assert_off_with_zero_torque(const struct irdm_tick_record *last)
{
	assert_int_equal(last->state, IRDM_SAFETY_OFF);
	for (int j = 0; j < 3; j++)
		assert_true(last->dev[0].joint_torque_nm[j] == 0.0);
}

/* One real-clock run of PRESS sent sig after wait_s: its exit checked,
 * its log read. */
static uint64_t signal_run(int sig, const char *name, double wait_s, uint64_t *contact_ticks,
			   struct irdm_tick_record *last)
{
	char log[320], board[320], line[96];
	struct timespec t = { (time_t)wait_s, (long)((wait_s - floor(wait_s)) * 1e9) };
	pid_t pid;
	int rc;

	snprintf(log, sizeof(log), "%s/sig-%d.log", dir, sig);
	relaxed_board(board, sizeof(board));
	pid = spawn(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
								"--board", board, "--image", image, "--user", PRESS, "--clock", "real",
								"--log", log, NULL });
	nanosleep(&t, NULL);
	kill(pid, sig);
	rc = finish(pid);
	if (rc != 6)
		fail_msg("%s: expected exit 6 (stopped by a signal), got %d: %s", name, rc, err_text);
	snprintf(line, sizeof(line), "stopped by %s (signal %d)", name, sig);
	assert_non_null(strstr(err_text, line));
	assert_non_null(strstr(err_text, "torque off, state off"));
	return read_log(log, 0, contact_ticks, last);
}

/*
 * A signal asking irdm-fw to end, mid-contact on a real-clock run: the
 * next tick shuts down (state off, torque zero, the signal logged as the
 * reason) and irdm-fw exits 6, as --help says.  The signal goes 1.7 s in
 * (1700 ticks: pressed and holding); on a host so busy that the run's
 * ticks fell behind the clock and the press had not begun, once or twice
 * more after as long as 1700 ticks took at the rate seen.
 */
static void signal_mid_contact(int sig, const char *name)
{
	struct irdm_tick_record last;
	double wait_s = 1.7;
	uint64_t n = 0, contact_ticks = 0;

	for (int attempt = 0; attempt < 3; attempt++) {
		n = signal_run(sig, name, wait_s, &contact_ticks, &last);
		print_message("%s after %.2f s: %llu ticks logged, %llu in contact; last: state %u, faults 0x%x\n",
			      name, wait_s, (unsigned long long)n, (unsigned long long)contact_ticks,
			      last.state, last.fault_flags);
		if (contact_ticks > 100)
			break;
		wait_s = fmin(1700.0 * wait_s / (double)(n ? n : 1), 10.0);
	}
	assert_true(contact_ticks > 100); /* the signal came mid-contact */
	assert_off_with_zero_torque(&last);
	assert_true(last.fault_flags & IRDM_FAULT_SIGNAL);
}

static void test_sigterm_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGTERM, "SIGTERM");
}

static void test_sighup_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGHUP, "SIGHUP");
}

static void test_sigquit_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGQUIT, "SIGQUIT");
}

/* Signals whose default action ends the process, handled as a request. */
static void test_sigusr1_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGUSR1, "SIGUSR1");
}

static void test_sigalrm_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGALRM, "SIGALRM");
}

static void test_realtime_signal_mid_contact_turns_torque_off(void **state)
{
	(void)state;
	signal_mid_contact(SIGRTMIN + 3, "SIGRTMIN+3");
}

/*
 * SIGXFSZ is ignored (a write past the file-size limit fails instead and
 * the log's loss path answers it): sent mid-contact, the run goes on to
 * its end and exits 0, its log whole.
 */
static void test_sigxfsz_is_ignored(void **state)
{
	struct timespec t = { 1, 200000000 };
	char board[320], log[320];
	struct irdm_tick_record last;
	uint64_t contact_ticks;
	pid_t pid;
	int rc;

	(void)state;
	snprintf(log, sizeof(log), "%s/xfsz.log", dir);
	relaxed_board(board, sizeof(board));
	pid = spawn(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
								"--board", board, "--image", image, "--user", PRESS, "--clock", "real",
								"--duration", "2.5", "--log", log, "-q", NULL });
	nanosleep(&t, NULL);
	kill(pid, SIGXFSZ);
	rc = finish(pid);
	if (rc != 0)
		fail_msg("SIGXFSZ: expected the run to go on to exit 0, got %d: %s", rc, err_text);
	/* 2.5 s at the board's 1 kHz, every tick logged */
	assert_int_equal(read_log(log, 0, &contact_ticks, &last), 2500);
	assert_false(last.fault_flags & IRDM_FAULT_SIGNAL);
}

/*
 * A fatal signal (here sent, as a crash would raise it) takes the
 * emergency path: torque off on the device, one line, exit 8.
 */
static void emergency_signal(int sig, const char *name)
{
	struct timespec t = { 1, 200000000 };
	char board[320], line[128];
	pid_t pid;
	int rc;

	relaxed_board(board, sizeof(board));
	pid = spawn(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
								"--board", board, "--image", image, "--user", PRESS, "--clock", "real", NULL });
	nanosleep(&t, NULL);
	kill(pid, sig);
	rc = finish(pid);
	snprintf(line, sizeof(line), "%s (signal %d): emergency torque off on 1 of 1 device\n", name,
		 sig);
	if (rc != 8 || !strstr(err_text, line))
		fail_msg("%s: expected exit 8 and the emergency line; got %d: %s", name, rc, err_text);
}

static void test_sigsegv_takes_the_emergency_path(void **state)
{
	(void)state;
	emergency_signal(SIGSEGV, "SIGSEGV");
}

/* SIGSYS: a bad system call, or a seccomp filter's kill: a bug. */
static void test_sigsys_takes_the_emergency_path(void **state)
{
	(void)state;
	emergency_signal(SIGSYS, "SIGSYS");
}

/*
 * Signals that came before irdm-fw could answer them (here: blocked and
 * pending when it starts, two different ones): arming unblocks them, both
 * arrive during the set-up.  The run ends there, cleanly: exit 6, no drive
 * enabled and not one tick run (the log has no record), and the second
 * signal, outside the loop, does not escalate to the emergency exit 8.
 */
static void test_signals_during_setup_enable_nothing(void **state)
{
	char log[320], out_path[300], err_path[300];
	struct irdm_tick_record last;
	uint64_t contact_ticks;
	const char *prog = env_or("IRDM_FW", "build/irdm-fw");
	pid_t pid;
	int rc;

	(void)state;
	snprintf(log, sizeof(log), "%s/setup-sig.log", dir);
	snprintf(out_path, sizeof(out_path), "%s/stdout", dir);
	snprintf(err_path, sizeof(err_path), "%s/stderr", dir);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		sigset_t set;
		int fd_out = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
		int fd_err = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);

		if (fd_out < 0 || fd_err < 0 || dup2(fd_out, 1) < 0 || dup2(fd_err, 2) < 0)
			_exit(120);
		sigemptyset(&set);
		sigaddset(&set, SIGTERM);
		sigaddset(&set, SIGINT);
		sigprocmask(SIG_BLOCK, &set, NULL);
		raise(SIGTERM); /* pending across exec */
		raise(SIGINT);
		execl(prog, prog, "--board", BOARD, "--image", image, "--user", PRESS, "--clock",
		      "virtual", "--log", log, (char *)NULL);
		_exit(121);
	}
	rc = finish(pid);
	if (rc != 6)
		fail_msg("expected exit 6 (stopped during the set-up), got %d: %s", rc, err_text);
	assert_non_null(strstr(err_text, "stopped by SIG"));
	assert_non_null(strstr(err_text, "at tick 0: torque off, state off"));
	assert_int_equal(read_log(log, 0, &contact_ticks, &last), 0);
}

/* Copy src to dst (the image a run reads, which the test then damages). */
static void copy_file(const char *src, const char *dst)
{
	size_t len;
	char *bytes = tf_load(src, &len);
	FILE *f = fopen(dst, "wb");

	assert_non_null(f);
	assert_int_equal(fwrite(bytes, 1, len, f), len);
	assert_int_equal(fclose(f), 0);
	free(bytes);
}

/* Replace every byte of path in place (same inode, same size). */
static void scribble_over(const char *path)
{
	size_t len;
	char *bytes = tf_load(path, &len);
	FILE *f = fopen(path, "r+b");

	assert_non_null(f);
	for (size_t i = 0; i < len; i++)
		bytes[i] = (char)(i * 131u + 7u);
	assert_int_equal(fwrite(bytes, 1, len, f), len);
	assert_int_equal(fclose(f), 0);
	free(bytes);
}

/*
 * The image file truncated, or written over, under a real-clock run in
 * contact: the loop reads its own copy, so the run goes on in contact to
 * its end (exit 0), the last record state off with zero torque.  (A file
 * mapped in place gives SIGBUS or garbage in the force tick.)
 */
static void image_changed_under_run(bool truncate_it)
{
	char log[320], board[320], live[320];
	struct timespec t = { 1, 500000000 }; /* 1.5 s: holding */
	struct irdm_tick_record last;
	uint64_t n, contact_after;
	pid_t pid;
	int rc;

	snprintf(log, sizeof(log), "%s/changed-%d.log", dir, truncate_it);
	snprintf(live, sizeof(live), "%s/live-%d.img", dir, truncate_it);
	copy_file(image, live);
	relaxed_board(board, sizeof(board));
	pid = spawn(env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){
								"--board", board, "--image", live, "--user", PRESS, "--clock", "real",
								"--duration", "2.5", "--log", log, NULL });
	nanosleep(&t, NULL);
	if (truncate_it)
		assert_int_equal(truncate(live, 0), 0);
	else
		scribble_over(live);
	rc = finish(pid);
	if (rc != 0)
		fail_msg("image %s under the run: exit %d: %s", truncate_it ? "truncated" : "overwritten",
			 rc, err_text);
	n = read_log(log, 1600, &contact_after, &last);
	print_message("image %s at 1.5 s: %llu ticks, %llu in contact after 1.6 s\n",
		      truncate_it ? "truncated" : "overwritten", (unsigned long long)n,
		      (unsigned long long)contact_after);
	assert_true(n == 2500);
	assert_true(contact_after > 500); /* still pressing, on the same surface */
	assert_off_with_zero_torque(&last);
}

static void test_image_truncated_under_run(void **state)
{
	(void)state;
	image_changed_under_run(true);
}

static void test_image_overwritten_under_run(void **state)
{
	(void)state;
	image_changed_under_run(false);
}

/*
 * A limit that holds all run long (the speed limit, the lowest a board
 * may set, far below the sag of
 * the unpowered arm, then the tip below the workspace where it came to
 * rest): every enable request refused, exit 7 naming the condition.
 */
static void test_never_enabled_exits_nonzero(void **state)
{
	char text[16384], out[16384] = "", *line, *save, board[320];
	int rc;

	(void)state;
	tf_read_text(BOARD, text, sizeof(text));
	for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		if (!strncmp(line, "max_tip_speed_m_per_s", 21))
			line = "max_tip_speed_m_per_s = 0.001";
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	snprintf(board, sizeof(board), "%s/slow.board", dir);
	tf_write_text(board, out);
	rc = run_fw((const char *const[]){ "--board", board, "--image", image, "--clock", "virtual",
					   "--duration", "0.5", "-q", NULL });
	expect_error(rc, 7, "the torque was never enabled in 500 ticks: 'workspace' refused");
}

/* The numbers after the first line starting with `key` (NULL if none). */
static const char *vtk_section(const char *text, const char *key)
{
	const char *p = strstr(text, key);

	assert_non_null(p);
	p = strchr(p, '\n');
	assert_non_null(p);
	return p + 1;
}

static void vtk_doubles(const char **p, double *v, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		char *end;
		v[i] = strtod(*p, &end);
		assert_true(end != *p);
		*p = end;
	}
}

struct frame_vtk {
	uint32_t n_points, n_polys;
	double *pos, *u, contact_m[3], time_s;
	uint32_t *tris; /* 3 n_polys */
	bool polys_in_range;
};

static void frame_parse(const char *text, struct frame_vtk *f)
{
	const char *p;
	unsigned long n;

	assert_non_null(strstr(text, "# vtk DataFile Version 3.0\n"));
	assert_non_null(strstr(text, "ASCII\nDATASET POLYDATA\n"));
	p = strstr(text, "\nPOINTS ");
	assert_non_null(p);
	n = strtoul(p + 8, NULL, 10);
	f->n_points = (uint32_t)n;
	f->pos = calloc(3 * n, sizeof(double));
	f->u = calloc(3 * n, sizeof(double));
	assert_true(f->pos && f->u);
	p = vtk_section(p + 1, "POINTS");
	vtk_doubles(&p, f->pos, 3 * n);
	p = strstr(text, "\nPOLYGONS ");
	assert_non_null(p);
	f->n_polys = (uint32_t)strtoul(p + 10, NULL, 10);
	p = vtk_section(p + 1, "POLYGONS");
	f->tris = calloc(3 * (size_t)f->n_polys + 1, sizeof(uint32_t));
	assert_non_null(f->tris);
	f->polys_in_range = true;
	for (uint32_t t = 0; t < f->n_polys; t++) {
		double v[4];
		vtk_doubles(&p, v, 4);
		assert_true(v[0] == 3);
		for (int k = 1; k < 4; k++) {
			f->polys_in_range &= v[k] >= 0 && v[k] < (double)f->n_points;
			f->tris[3 * t + k - 1] = (uint32_t)v[k];
		}
	}
	p = vtk_section(text, "VECTORS displacement_m double");
	vtk_doubles(&p, f->u, 3 * n);
	p = vtk_section(text, "contact_point_m 3 1 double");
	vtk_doubles(&p, f->contact_m, 3);
	p = vtk_section(text, "time_s 1 1 double");
	vtk_doubles(&p, &f->time_s, 1);
}

static uint32_t nearest_row(const struct irdm_image *img, const double p[3])
{
	uint32_t best = 0;
	double best_d = INFINITY;

	for (uint32_t r = 0; r < img->meta->n_nodes; r++) {
		const float *x = img->nodes[r].pos_m;
		double d = pow(x[0] - p[0], 2) + pow(x[1] - p[1], 2) + pow(x[2] - p[2], 2);
		if (d < best_d) {
			best_d = d;
			best = r;
		}
	}
	return best;
}

/* The surface image: every face displayed, the bottom's fixed nodes too. */
static void surface_image(char *path, size_t len)
{
	pid_t pid;

	snprintf(path, len, "%s/surface.img", dir);
	pid = spawn(env_or("IRDM", "build/irdm"), (const char *const[]){
							  "precompute", "-q", "--mesh", "cuboid", "--resolution", "4,4,8", "--fixed", "z<=0",
							  "--touch", "z>=0.2", "--display", "surface", "--representation", "modal:40",
							  "--static_correction", "yes", "--max_error", "none", "-o", path, NULL });
	assert_int_equal(finish(pid), 0);
}

/*
 * Mid-hold (1.5 s) the press dents the top: the node nearest the contact
 * point moves down by millimetres (the hand's spring pushes ~0.3 N into a
 * cuboid of a few hundred N/m there), the fixed bottom not at all, and
 * every position is rest + the displacement written beside it.
 */
static void test_frame_at_writes_the_deformed_surface(void **state)
{
	char img_path[320], vtk[2][320], err[256];
	char *bytes[2];
	size_t len[2];
	struct irdm_image img;
	struct frame_vtk f;
	uint32_t row, bottom = 0;
	double worst = 0;

	(void)state;
	surface_image(img_path, sizeof(img_path));
	for (int k = 0; k < 2; k++) {
		snprintf(vtk[k], sizeof(vtk[k]), "%s/frame%d.vtk", dir, k);
		assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", img_path,
							       "--user", PRESS, "--clock", "virtual",
							       "--frame-at", "1.5", "--frame-out",
							       vtk[k], "-q", NULL }),
				 0);
		bytes[k] = tf_load(vtk[k], &len[k]);
	}
	assert_int_equal(len[0], len[1]);
	assert_memory_equal(bytes[0], bytes[1], len[0]);
	assert_int_equal(irdm_image_map(img_path, 0, &img, err, sizeof(err)), 0);
	frame_parse(bytes[0], &f);
	/* 1.5 s is on the 100 Hz snapshot grid: virtual time holds that frame */
	assert_true(f.time_s == 1.5);
	assert_int_equal(f.n_points, img.meta->n_nodes);
	assert_int_equal(f.n_polys, img.meta->n_tris);
	assert_true(f.polys_in_range);
	/* every row is displayed here: the polygons are the SURFACE section */
	assert_memory_equal(f.tris, img.tris, 3 * (size_t)f.n_polys * sizeof(uint32_t));
	for (uint32_t r = 0; r < f.n_points; r++)
		for (int a = 0; a < 3; a++)
			assert_true(fabs(f.pos[3 * r + a] - img.nodes[r].pos_m[a] - f.u[3 * r + a]) <=
				    1e-12);
	/* the contact is at the pressed top centre */
	{
		double d[3];
		irdm_v3_sub(d, f.contact_m, (const double[3]){ 0.05, 0.05, 0.2 });
		assert_true(irdm_v3_norm(d) < 0.01);
	}
	row = nearest_row(&img, f.contact_m);
	print_message("frame at 1.5 s: %u points, %u triangles; node %u nearest the contact "
		      "moved %.3f mm down\n",
		      f.n_points, f.n_polys, row, -f.u[3 * row + 2] * 1e3);
	assert_true(f.u[3 * row + 2] <= -0.002 && f.u[3 * row + 2] >= -0.012);
	for (uint32_t r = 0; r < f.n_points; r++) {
		if (img.nodes[r].pos_m[2] != 0.0f)
			continue;
		bottom++;
		worst = fmax(worst, irdm_v3_norm(f.u + 3 * r));
	}
	assert_true(bottom > 0);
	assert_true(worst <= 1e-12);
	irdm_image_unmap(&img);
	free(f.pos);
	free(f.u);
	free(f.tris);
	free(bytes[0]);
	free(bytes[1]);
}

/*
 * --frames-every: a frame every 0.5 s of the 6.2 s press run into a
 * directory, with the JSON index ParaView reads.  Each frame's time is on
 * its line of the index and in its file; the one at 1.5 s is --frame-at's
 * frame byte for byte (checked physically above); before the touch
 * (1.04 s) the surface is at rest, and through the hold the node nearest
 * the contact is dented; a second run replaces the whole directory.
 */
static void test_frames_series(void **state)
{
	char img_path[320], out[320], single[320], path[400], stray[400], line[256];
	glob_t g;
	char *a, *b;
	size_t la, lb;
	unsigned n = 0;
	FILE *idx;

	(void)state;
	surface_image(img_path, sizeof(img_path));
	snprintf(out, sizeof(out), "%s/series", dir);
	snprintf(single, sizeof(single), "%s/single.vtk", dir);
	snprintf(stray, sizeof(stray), "%s/stray.txt", out);
	/* a second run replaces its own series; a file it did not write stops
	 * it before the run (the file kept) unless --force */
	for (int run = 0; run < 4; run++) {
		int rc = run_fw((const char *const[]){
			"--board", BOARD, "--image", img_path, "--user", PRESS, "--clock", "virtual",
			"--frames-every", "0.5", "--frames-out", out, "--frame-at", "1.5",
			"--frame-out", single, "-q", run == 3 ? "--force" : NULL, NULL });

		if (run == 2) {
			expect_error(rc, 2, "series/stray.txt: not written by irdm-fw");
			assert_int_equal(access(stray, F_OK), 0);
			continue;
		}
		assert_int_equal(rc, 0);
		if (run == 1)
			tf_write_text(stray, "the user's\n");
	}
	assert_int_equal(access(stray, F_OK), -1); /* replaced as a whole */
	snprintf(path, sizeof(path), "%s" IRDM_OUTDIR_TMP "*", out);
	assert_int_equal(glob(path, 0, NULL, &g), GLOB_NOMATCH); /* nothing left beside */
	snprintf(path, sizeof(path), "%s/frames.vtk.series", out);
	idx = fopen(path, "r");
	assert_non_null(idx);
	while (fgets(line, sizeof(line), idx)) {
		unsigned k;
		double t;
		struct frame_vtk f;
		char *text;
		size_t len;
		double du = 0;

		if (sscanf(line, " { \"name\" : \"frame_%5u.vtk\", \"time\" : %lf }", &k, &t) != 2)
			continue;
		n++;
		assert_int_equal(k, n);
		assert_true(t == 0.5 * n);
		snprintf(path, sizeof(path), "%s/frame_%05u.vtk", out, k);
		text = tf_load(path, &len);
		frame_parse(text, &f);
		assert_true(f.time_s == t);
		for (uint32_t r = 0; r < f.n_points; r++)
			du = fmax(du, fabs(f.u[3 * r + 2]));
		if (t < 1.0)
			assert_true(du <= 1e-12); /* not touched yet */
		if (t >= 1.5 && t <= 3.0)
			assert_true(du >= 0.002); /* the press holds its dent */
		free(f.pos);
		free(f.u);
		free(f.tris);
		free(text);
	}
	fclose(idx);
	print_message("series: %u frames every 0.5 s\n", n);
	assert_int_equal(n, 12);
	snprintf(path, sizeof(path), "%s/frame_00003.vtk", out);
	a = tf_load(path, &la);
	b = tf_load(single, &lb);
	assert_int_equal(la, lb);
	assert_memory_equal(a, b, la);
	free(a);
	free(b);
	/* refused before the run: too many frames, a directory that cannot be made */
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", img_path, "--clock",
						   "virtual", "--duration", "20", "--frames-every",
						   "0.01", "--frames-out", out, NULL }),
		     2, "more than 1000 frames");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", img_path, "--clock",
						   "virtual", "--duration", "0.5", "--frames-every",
						   "0.1", "--frames-out", "/nonexistent/series", NULL }),
		     4, "/nonexistent/series.irdm-tmp.");
	expect_error(run_fw((const char *const[]){ "--board", BOARD, "--image", img_path,
						   "--frames-every", "0.1", NULL }),
		     2, "--frames-every needs --frames-out DIR");
}

/* The summary's "memory:" line: peak resident kB. */
static long peak_resident_kb(void)
{
	const char *p = strstr(out_text, "memory: locked ");
	long locked, peak;

	assert_non_null(p);
	assert_int_equal(sscanf(p, "memory: locked %ld kB, peak resident %ld kB", &locked, &peak),
			 2);
	return peak;
}

/*
 * The summary's memory does not grow with the run: 3 s and 150 s of
 * virtual time (150,000 ticks: a per-tick trace of 17 bytes would add
 * 2.5 MB) peak at the same resident size, within allocator noise.
 */
static void test_memory_bounded(void **state)
{
	long short_kb, long_kb;

	(void)state;
	assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
						       "--user", PRESS, "--clock", "virtual",
						       "--duration", "3", NULL }),
			 0);
	short_kb = peak_resident_kb();
	assert_int_equal(run_fw((const char *const[]){ "--board", BOARD, "--image", image,
						       "--user", PRESS, "--clock", "virtual",
						       "--duration", "150", NULL }),
			 0);
	long_kb = peak_resident_kb();
	print_message("peak resident: %ld kB for 3 s, %ld kB for 150 s of virtual time\n",
		      short_kb, long_kb);
	assert_true(labs(long_kb - short_kb) < 1024);
	/* the ringing after release is still found in the bounded window */
	assert_non_null(strstr(out_text, "release ringing: ") &&
					!strstr(out_text, "release ringing: none") ?
				out_text :
				NULL);
}

/*
 * A log that cannot be written whole (a full disk, here the file size
 * limit: the same failed write(), deterministic and without root): the
 * run says so naming the log, exits 9, and leaves no log and no
 * temporary, in virtual time (the loop writes) and real time (the writer
 * thread does).
 */
static void test_log_write_failure(void **state)
{
	static const char *const clocks[] = { "virtual", "real" };
	char log[320], pattern[400], board[320];
	glob_t g;

	(void)state;
	snprintf(log, sizeof(log), "%s/full.log", dir);
	relaxed_board(board, sizeof(board)); /* a busy host: no overrun fault */
	for (int c = 0; c < 2; c++) {
		int rc = finish(spawn("/bin/sh", (const char *const[]){
							 "-c", "ulimit -f 200 && exec \"$0\" \"$@\"",
							 env_or("IRDM_FW", "build/irdm-fw"), "--board", board, "--image", image,
							 "--user", PRESS, "--clock", clocks[c], "--duration", "1.5", "--log", log,
							 "-q", NULL }));

		expect_error(rc, 9, "full.log: log not written: write failed after");
		assert_int_equal(access(log, F_OK), -1);
		snprintf(pattern, sizeof(pattern), "%s" IRDM_OUTDIR_TMP "*", log);
		assert_int_equal(glob(pattern, 0, NULL, &g), GLOB_NOMATCH);
	}
}

/*
 * Real time: the worker's thread draws the frames (about 100 in a second at
 * the board's 100 Hz; a loaded host may skip some) and holds the one
 * nearest the asked time.
 */
static void test_frame_at_in_real_time(void **state)
{
	char img_path[320], vtk[320], board[320];
	unsigned long long frames = 0;
	struct frame_vtk f;
	const char *p;
	size_t len;
	char *bytes;

	(void)state;
	snprintf(img_path, sizeof(img_path), "%s/surface.img", dir);
	if (access(img_path, R_OK)) /* run alone: the previous test made it */
		surface_image(img_path, sizeof(img_path));
	snprintf(vtk, sizeof(vtk), "%s/frame-rt.vtk", dir);
	relaxed_board(board, sizeof(board));
	assert_int_equal(run_fw((const char *const[]){ "--board", board, "--image", img_path,
						       "--user", PRESS, "--clock", "real",
						       "--duration", "1", "--frame-at", "0.5",
						       "--frame-out", vtk, NULL }),
			 0);
	p = strstr(out_text, "deformation: ");
	assert_non_null(p);
	assert_int_equal(sscanf(p, "deformation: %llu frames", &frames), 1);
	assert_non_null(strstr(p, "(worker thread)"));
	print_message("real time, 1 s: %llu frames drawn by the worker thread\n", frames);
	assert_true(frames >= 20 && frames <= 101);
	bytes = tf_load(vtk, &len);
	frame_parse(bytes, &f);
	assert_true(fabs(f.time_s - 0.5) <= 0.1);
	free(f.pos);
	free(f.u);
	free(f.tris);
	free(bytes);
}

static int setup(void **state)
{
	pid_t pid;

	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "fw"))
		return -1;
	snprintf(image, sizeof(image), "%s/cuboid.img", dir);
	/* the paper's cuboid at 4 x 4 x 8 cells, where the board places it */
	pid = spawn(env_or("IRDM", "build/irdm"), (const char *const[]){
							  "precompute", "-q", "--mesh", "cuboid", "--resolution", "4,4,8", "--fixed", "z<=0",
							  "--touch", "z>=0.2", "--display", "touch", "--representation", "modal:40",
							  "--static_correction", "yes", "--max_error", "none", "-o", image, NULL });
	return finish(pid) == 0 ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_bad_input),
		cmocka_unit_test(test_virtual_runs_are_identical),
		cmocka_unit_test(test_release_ringing_is_the_dominant_mode),
		cmocka_unit_test(test_summary_rendered_force),
		cmocka_unit_test(test_two_arms_see_the_two_contact_figure),
		cmocka_unit_test(test_require_rt),
		cmocka_unit_test(test_sigterm_mid_contact_turns_torque_off),
		cmocka_unit_test(test_sighup_mid_contact_turns_torque_off),
		cmocka_unit_test(test_sigquit_mid_contact_turns_torque_off),
		cmocka_unit_test(test_sigusr1_mid_contact_turns_torque_off),
		cmocka_unit_test(test_sigalrm_mid_contact_turns_torque_off),
		cmocka_unit_test(test_realtime_signal_mid_contact_turns_torque_off),
		cmocka_unit_test(test_sigxfsz_is_ignored),
		cmocka_unit_test(test_sigsegv_takes_the_emergency_path),
		cmocka_unit_test(test_sigsys_takes_the_emergency_path),
		cmocka_unit_test(test_signals_during_setup_enable_nothing),
		cmocka_unit_test(test_image_truncated_under_run),
		cmocka_unit_test(test_image_overwritten_under_run),
		cmocka_unit_test(test_never_enabled_exits_nonzero),
		cmocka_unit_test(test_frame_at_writes_the_deformed_surface),
		cmocka_unit_test(test_frames_series),
		cmocka_unit_test(test_log_write_failure),
		cmocka_unit_test(test_generated_docs_current),
		cmocka_unit_test(test_clear_messages),
		cmocka_unit_test(test_memory_bounded),
		cmocka_unit_test(test_frame_at_in_real_time),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
