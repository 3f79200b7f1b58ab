/* SPDX-License-Identifier: MIT */
/*
 * No input can hang a reader: each file reader (board, user script, scene,
 * image) given a FIFO nobody writes, /dev/zero, a text with a NUL byte, an
 * over-long line and a file past the size bound returns at once with one
 * message naming the file (and the line) and the reason.  An alarm guards
 * every test: a reader that blocks kills the test instead of hanging it.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/board.h"
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/image_map.h"
#include "irdm/sim/sim_user.h"
#include "irdm/posix/textfile.h"
#include "scene/scene.h"
#include "support/test_files.h"

#define GUARD_S 20 /* far above a reader's real time; a hang dies here */

static char dir[256], fifo[320], nul[320], longl[320], huge[320], err[1024];

enum reader { BOARD,
	      USER,
	      SCENE,
	      IMAGE,
	      N_READERS };
static const char *const reader_name[N_READERS] = { "board", "user script", "scene", "image" };

static int read_with(enum reader r, const char *path)
{
	static struct irdm_board board;
	static struct irdm_sim_user user;
	static struct irdm_scene scene;
	struct irdm_image img;
	int ret = IRDM_EINVAL;

	err[0] = 0;
	switch (r) {
	case BOARD:
		ret = irdm_board_load(&board, path, err, sizeof(err));
		break;
	case USER:
		ret = irdm_sim_user_load(&user, path, err, sizeof(err));
		break;
	case SCENE:
		irdm_scene_defaults(&scene);
		ret = irdm_scene_load(&scene, path, err, sizeof(err));
		break;
	case IMAGE:
		ret = irdm_image_map(path, 0, &img, err, sizeof(err));
		if (!ret)
			irdm_image_unmap(&img);
		break;
	default:
		break;
	}
	return ret;
}

static void expect(enum reader r, const char *path, int code, const char *needle)
{
	int ret = read_with(r, path);

	if (ret != code || !strstr(err, needle) || strchr(err, '\n'))
		fail_msg("%s %s: expected %s naming '%s'; got %s: %s", reader_name[r], path,
			 irdm_errname(code), needle, irdm_errname(ret), err);
}

static int setup(void **state)
{
	FILE *f;

	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "inputs"))
		return -1;
	snprintf(fifo, sizeof(fifo), "%s/fifo", dir);
	snprintf(nul, sizeof(nul), "%s/nul.txt", dir);
	snprintf(longl, sizeof(longl), "%s/long.txt", dir);
	snprintf(huge, sizeof(huge), "%s/huge.txt", dir);
	if (mkfifo(fifo, 0600))
		return -1;
	f = fopen(nul, "w");
	if (!f)
		return -1;
	fputs("# a comment\nab", f);
	fputc(0, f);
	fputs("cd\n", f);
	fclose(f);
	f = fopen(longl, "w");
	if (!f)
		return -1;
	for (int i = 0; i < 5000; i++)
		fputc('x', f);
	fputc('\n', f);
	fclose(f);
	/* sparse: its size, not its blocks, is what the bound is about */
	f = fopen(huge, "w");
	if (!f || ftruncate(fileno(f), (off_t)IRDM_TEXT_MAX_BYTES + 1))
		return -1;
	fclose(f);
	signal(SIGALRM, SIG_DFL);
	alarm(GUARD_S);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	alarm(0);
	return tf_rmdir(dir);
}

/* A FIFO nobody writes: the open would block for ever without O_NONBLOCK. */
static void test_fifo(void **state)
{
	(void)state;
	for (int r = 0; r < N_READERS; r++)
		expect(r, fifo, IRDM_EIO, "not a regular file");
	expect(BOARD, fifo, IRDM_EIO, "fifo: not a regular file (a FIFO)");
}

/* /dev/zero: NULs without end, never a newline nor an end of file. */
static void test_dev_zero(void **state)
{
	(void)state;
	for (int r = 0; r < N_READERS; r++)
		expect(r, "/dev/zero", IRDM_EIO, "/dev/zero: not a regular file");
	expect(USER, "/dev/zero", IRDM_EIO, "(a character device)");
}

/* A NUL in a regular file: named with its line, not taken for an end. */
static void test_nul_byte(void **state)
{
	(void)state;
	for (int r = BOARD; r <= SCENE; r++)
		expect(r, nul, IRDM_EFORMAT, "nul.txt:2: a NUL byte at column 3");
}

static void test_long_line_and_size(void **state)
{
	(void)state;
	for (int r = BOARD; r <= SCENE; r++) {
		expect(r, longl, IRDM_EFORMAT, "long.txt:1: line longer than");
		expect(r, huge, IRDM_ERANGE, "huge.txt: 16777217 bytes, more than");
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fifo),
		cmocka_unit_test(test_dev_zero),
		cmocka_unit_test(test_nul_byte),
		cmocka_unit_test(test_long_line_and_size),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
