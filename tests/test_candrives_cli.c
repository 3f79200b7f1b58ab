/* SPDX-License-Identifier: MIT */
/*
 * irdm-candrives' command line (the process itself runs in make hil's VM,
 * on vcan0): --help and its exit code, every refusal in one line naming
 * the argument and the reason with its exit code, checked before the
 * socket opens; on a kernel without CAN the socket's refusal (exit 4).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "support/run_prog.h"
#include "support/test_files.h"

#define BOARD "boards/can-3dof.board"

static char dir[256], prog[256], out_text[8192], err_text[4096];

static int run(const char *const *args)
{
	return rp_run(dir, prog, args, out_text, sizeof(out_text), err_text, sizeof(err_text));
}

/* Exit code and a single line "irdm-candrives: ...needle..." on stderr. */
static void refused(const char *const *args, int code, const char *needle)
{
	int rc = run(args);

	if (rc != code || strncmp(err_text, "irdm-candrives: ", 16) || !strstr(err_text, needle) ||
	    strchr(err_text, '\n') != err_text + strlen(err_text) - 1)
		fail_msg("exit %d (want %d), stderr '%s' (want one line with '%s')", rc, code,
			 err_text, needle);
}

static void test_help(void **state)
{
	(void)state;
	assert_int_equal(run((const char *const[]){ "--help", NULL }), 0);
	assert_non_null(strstr(out_text, "usage: irdm-candrives --board BOARD"));
	assert_non_null(strstr(out_text, "heartbeat-stop:NODE:SYNC"));
	assert_non_null(strstr(out_text, "exit codes:"));
}

static void test_bad_arguments(void **state)
{
	(void)state;
	refused((const char *const[]){ NULL }, 2, "missing --board BOARD");
	refused((const char *const[]){ "--board", BOARD, "--nodes", "4", NULL }, 2,
		"--nodes 4: must be <= 3");
	refused((const char *const[]){ "--board", BOARD, "--bogus", NULL }, 2, "bogus");
	refused((const char *const[]){ "--board", BOARD, "--fault", "drop:1:0:3", NULL }, 2,
		"fault 'drop:1:0:3': SYNC counts from 1");
	refused((const char *const[]){ "--board", BOARD, "--fault", "stall:1", NULL }, 2,
		"unknown kind");
	refused((const char *const[]){ "--board", BOARD, "--fault", "emcy:4:10:0x2310", NULL }, 2,
		"node 4 is not one of the drives 1..3");
	refused((const char *const[]){ "--board", BOARD, "--seconds", "-1", NULL }, 2, "seconds");
}

static void test_bad_inputs(void **state)
{
	(void)state;
	refused((const char *const[]){ "--board", "no/such.board", NULL }, 3, "no/such.board");
	refused((const char *const[]){ "--board", BOARD, "--user", "scenes/users/pinch.user", NULL },
		3, "uses 2 hands, the drives move one arm");
	refused((const char *const[]){ "--board", BOARD, "--user", "no/such.user", NULL }, 3,
		"no/such.user");
}

static void test_no_can(void **state)
{
	int fd = socket(PF_CAN, SOCK_RAW, 1);

	(void)state;
	if (fd >= 0) {
		close(fd);
		skip(); /* a kernel with CAN: make hil runs the process */
	}
	refused((const char *const[]){ "--board", BOARD, "--if", "vcan0", NULL }, 4,
		"vcan0: this kernel has no CAN sockets");
}

static int setup(void **state)
{
	const char *build = getenv("IRDM_BUILD");

	(void)state;
	snprintf(prog, sizeof(prog), "%s/irdm-candrives", build ? build : "build");
	return tf_tmpdir(dir, sizeof(dir), "candrives");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_help),
		cmocka_unit_test(test_bad_arguments),
		cmocka_unit_test(test_bad_inputs),
		cmocka_unit_test(test_no_can),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
