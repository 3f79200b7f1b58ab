/* SPDX-License-Identifier: MIT */
/*
 * Interrupted tools leave nothing (util/interrupt.h, the image writer):
 *  - SIGINT, SIGTERM and SIGHUP each remove the registered temporary file
 *    and directory, stop the registered process group, and the process
 *    dies of that very signal; a signal ignored at start stays ignored;
 *  - irdm precompute interrupted while tetgen runs: tetgen (in a group of
 *    its own) is stopped, its directory removed, irdm dies of SIGINT;
 *  - a temporary image left by a killed writer (no lock on it any more) is
 *    removed by the next precompute of the same image, one still locked by
 *    a live writer is left alone.
 * Needs IRDM (make test sets it); runs from the repository root.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <setjmp.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/posix/outdir.h"
#include "support/run_prog.h"
#include "support/test_files.h"
#include "util/interrupt.h"

extern char **environ;

static char dir[256], err_text[4096];

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "interrupt");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

static bool exists(const char *path)
{
	struct stat st;

	return !lstat(path, &st);
}

/* The process ended: no such pid, or a zombie nobody reaped yet (its
 * parent died; a container's init may be slow to reap). */
static bool ended(pid_t pid)
{
	char path[64], text[256] = "";
	const char *close_paren;

	if (kill(pid, 0) && errno == ESRCH)
		return true;
	snprintf(path, sizeof(path), "/proc/%d/stat", (int)pid);
	tf_read_text(path, text, sizeof(text));
	close_paren = strrchr(text, ')');
	return close_paren && close_paren[1] == ' ' && close_paren[2] == 'Z';
}

/* Poll, 10 s at most: a signalled process takes a moment to go. */
static bool process_gone(pid_t pid)
{
	for (int i = 0; i < 1000; i++) {
		if (ended(pid))
			return true;
		usleep(10000);
	}
	return false;
}

static pid_t spawn_sleeper_group(void)
{
	char *argv[] = { "sleep", "60", NULL };
	posix_spawnattr_t at;
	pid_t pid;

	assert_int_equal(posix_spawnattr_init(&at), 0);
	assert_int_equal(posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP), 0);
	assert_int_equal(posix_spawnattr_setpgroup(&at, 0), 0);
	assert_int_equal(posix_spawnp(&pid, "sleep", NULL, &at, argv, environ), 0);
	posix_spawnattr_destroy(&at);
	return pid;
}

/*
 * A child registers a file, a directory of files and a sleeper's group,
 * says so through a pipe and waits; the parent sends sig.
 */
static void one_signal(int sig, bool ignore_first)
{
	char file[320], sub[320], inner[400], pidtext[32] = "";
	int p[2], status;
	pid_t child, sleeper;

	snprintf(file, sizeof(file), "%s/sig%d.tmp", dir, sig);
	snprintf(sub, sizeof(sub), "%s/sig%d.dir", dir, sig);
	snprintf(inner, sizeof(inner), "%s/frame", sub);
	assert_int_equal(pipe(p), 0);
	child = fork();
	assert_true(child >= 0);
	if (child == 0) {
		pid_t s;

		close(p[0]);
		if (ignore_first)
			signal(sig, SIG_IGN);
		tf_write_text(file, "half an image");
		mkdir(sub, 0777);
		tf_write_text(inner, "half a frame");
		s = spawn_sleeper_group();
		irdm_interrupt_add(IRDM_INTERRUPT_FILE, file, 0);
		irdm_interrupt_add(IRDM_INTERRUPT_DIR, sub, 0);
		irdm_interrupt_add(IRDM_INTERRUPT_PGROUP, NULL, s);
		dprintf(p[1], "%d\n", (int)s);
		close(p[1]);
		for (;;)
			pause();
	}
	close(p[1]);
	assert_true(read(p[0], pidtext, sizeof(pidtext) - 1) > 0);
	close(p[0]);
	sleeper = (pid_t)atoi(pidtext);
	assert_int_equal(kill(child, sig), 0);
	if (ignore_first) {
		/* ignored at start: still running, everything still there */
		usleep(200000);
		assert_int_equal(waitpid(child, &status, WNOHANG), 0);
		assert_true(exists(file) && exists(inner));
		assert_int_equal(kill(child, SIGTERM), 0);
	}
	assert_int_equal(waitpid(child, &status, 0), child);
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), ignore_first ? SIGTERM : sig);
	assert_false(exists(file));
	assert_false(exists(sub));
	assert_true(process_gone(sleeper));
}

static void test_signals_clean_up(void **state)
{
	(void)state;
	one_signal(SIGINT, false);
	one_signal(SIGTERM, false);
	one_signal(SIGHUP, false);
	one_signal(SIGHUP, true);
}

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

/* irdm precompute on a surface, its tetgen a stand-in that records its pid
 * and sleeps: SIGINT once it runs. */
static void test_precompute_interrupted_in_tetgen(void **state)
{
	char fake[320], pidfile[320], img[320], pattern[400], text[32] = "", env[400];
	const char *const args[] = { "precompute", "--mesh", "tests/data/mesh/cube.off",
				     "--fixed", "z<=0", "--touch", "z>=0.9", "--max_error", "none",
				     "-o", img, NULL };
	pid_t irdm, tetgen;
	glob_t g;
	int status;
	FILE *f;

	(void)state;
	snprintf(fake, sizeof(fake), "%s/fake-tetgen", dir);
	snprintf(pidfile, sizeof(pidfile), "%s/tetgen.pid", dir);
	snprintf(img, sizeof(img), "%s/cube.img", dir);
	f = fopen(fake, "w");
	assert_non_null(f);
	fprintf(f, "#!/bin/sh\necho $$ > %s.new && mv %s.new %s\nexec sleep 60\n", pidfile,
		pidfile, pidfile);
	fclose(f);
	assert_int_equal(chmod(fake, 0755), 0);
	assert_int_equal(setenv("IRDM_TETGEN", fake, 1), 0);
	assert_int_equal(setenv("TMPDIR", dir, 1), 0);
	irdm = rp_spawn(dir, irdm_path(), args);
	for (int i = 0; i < 2000 && !exists(pidfile); i++)
		usleep(10000);
	assert_true(exists(pidfile));
	tf_read_text(pidfile, text, sizeof(text));
	tetgen = (pid_t)atoi(text);
	assert_true(tetgen > 0);
	assert_int_equal(kill(irdm, SIGINT), 0);
	assert_int_equal(waitpid(irdm, &status, 0), irdm);
	unsetenv("IRDM_TETGEN");
	unsetenv("TMPDIR");
	assert_true(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
	assert_true(process_gone(tetgen));
	snprintf(pattern, sizeof(pattern), "%s/irdm-mesh-*", dir);
	assert_int_equal(glob(pattern, 0, NULL, &g), GLOB_NOMATCH);
	assert_false(exists(img));
	snprintf(env, sizeof(env), "%s/stderr", dir);
	tf_read_text(env, err_text, sizeof(err_text));
	print_message("interrupted in tetgen: irdm died of SIGINT, tetgen %d stopped; stderr '%s'\n",
		      (int)tetgen, err_text);
}

/* Debris of a killed writer: removed by the next write of the same image. */
static void test_image_debris(void **state)
{
	char img[320], dead[400], live[400];
	const char *const args[] = { "precompute", "-q", "--mesh", "box:0.04,0.04,0.08",
				     "--resolution", "2,2,4", "--fixed", "z<=0", "--touch",
				     "z>=0.08", "--representation", "modal:all", "--max_error", "none",
				     "-o", img, NULL };
	int fd, rc;

	(void)state;
	snprintf(img, sizeof(img), "%s/box.img", dir);
	snprintf(dead, sizeof(dead), "%s%sAbC123", img, IRDM_OUTDIR_TMP);
	snprintf(live, sizeof(live), "%s%sLiVe00", img, IRDM_OUTDIR_TMP);
	tf_write_text(dead, "half an image of a killed run");
	tf_write_text(live, "half an image of a running writer");
	fd = open(live, O_RDONLY);
	assert_true(fd >= 0);
	assert_int_equal(flock(fd, LOCK_EX), 0); /* this process: a live writer */
	rc = rp_run(dir, irdm_path(), args, NULL, 0, err_text, sizeof(err_text));
	close(fd);
	if (rc)
		fail_msg("irdm precompute: exit %d: %s", rc, err_text);
	assert_false(exists(dead));
	assert_true(exists(live));
	assert_true(exists(img));
	assert_non_null(strstr(err_text, "AbC123, left by an interrupted run"));
}

int main(void)
{
	/* The tests set each signal's starting disposition themselves: run
	 * from a background job, this process starts with SIGINT ignored
	 * (POSIX), its children would inherit that, and the tools rightly
	 * keep a signal ignored at start ignored, so a SIGINT would never
	 * end them. */
	static const int sigs[] = { SIGINT, SIGTERM, SIGHUP };
	for (size_t i = 0; i < sizeof(sigs) / sizeof(sigs[0]); i++)
		signal(sigs[i], SIG_DFL);

	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_signals_clean_up),
		cmocka_unit_test(test_precompute_interrupted_in_tetgen),
		cmocka_unit_test(test_image_debris),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
