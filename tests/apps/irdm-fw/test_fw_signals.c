/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw's signal handlers alone (apps/irdm-fw/fw_signals.c), each case
 * in a child process that raises the signals itself: raise() delivers
 * before it returns, so which signal came first, and whether the loop ran
 * then, is exact, not a race with a running controller.
 *
 *  - every signal asking the process to end sets the flag and returns
 *    (SIGINT ... SIGSTKFLT, SIGRTMIN..SIGRTMAX), named in the stop line;
 *  - SIGXFSZ is ignored (a write past the limit fails with EFBIG instead);
 *  - SIGTRAP and SIGSYS take the emergency path: one line, exit 8;
 *  - a second signal escalates to exit 8 only while the loop runs, never
 *    before or after it, and SIGPIPE never does.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "fw.h"

#define CHILD_ALIVE 42 /* the child came back from every signal */
#define CHILD_WRONG 43 /* the flag did not say what it should */

static volatile sig_atomic_t flag;

/*
 * Fork; the child arms the handlers (no device open), marks the loop
 * running or not, raises sigs[0..n) in order and exits CHILD_ALIVE if the
 * flag then holds the last one and (if name is given) fw_signal_name()
 * names it so.  Return: its exit status; its stderr in err.
 */
static int child_raises(bool loop_running, const int *sigs, size_t n, const char *name, char *err,
			size_t errlen)
{
	int fds[2], status;
	ssize_t got, total = 0;
	pid_t pid;

	assert_int_equal(pipe(fds), 0);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		static struct fw fw; /* nothing open: the emergency path's "0 of 0" */

		close(fds[0]);
		dup2(fds[1], STDERR_FILENO);
		flag = 0;
		if (fw_signals_arm(&fw, &flag))
			_exit(CHILD_WRONG);
		fw_signals_loop(loop_running);
		for (size_t i = 0; i < n; i++)
			raise(sigs[i]);
		if (name && strcmp(fw_signal_name(sigs[n - 1]), name))
			_exit(CHILD_WRONG);
		_exit(flag == (n && sigs[n - 1] != SIGXFSZ ? sigs[n - 1] : 0) ? CHILD_ALIVE : CHILD_WRONG);
	}
	close(fds[1]);
	while (total + 1 < (ssize_t)errlen &&
	       (got = read(fds[0], err + total, errlen - 1 - (size_t)total)) > 0)
		total += got;
	err[total] = '\0';
	close(fds[0]);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static void expect_soft(int sig, const char *name)
{
	char err[256];
	int rc = child_raises(true, &sig, 1, name, err, sizeof(err));

	if (rc != CHILD_ALIVE)
		fail_msg("%s (signal %d): expected the flag set, so named, and the child alive, "
			 "got %d: %s",
			 name, sig, rc, err);
}

static void expect_emergency(const int *sigs, size_t n, bool loop_running, const char *line)
{
	char err[256];
	int rc = child_raises(loop_running, sigs, n, NULL, err, sizeof(err));

	if (rc != FW_EXIT_EMERGENCY || strcmp(err, line))
		fail_msg("expected exit 8 and '%s', got %d: '%s'", line, rc, err);
}

static void test_requests_set_the_flag(void **state)
{
	static const struct {
		int sig;
		const char *name;
	} soft[] = {
		{ SIGINT, "SIGINT" },
		{ SIGTERM, "SIGTERM" },
		{ SIGHUP, "SIGHUP" },
		{ SIGQUIT, "SIGQUIT" },
		{ SIGPIPE, "SIGPIPE" },
		{ SIGXCPU, "SIGXCPU" },
		{ SIGUSR1, "SIGUSR1" },
		{ SIGUSR2, "SIGUSR2" },
		{ SIGALRM, "SIGALRM" },
		{ SIGVTALRM, "SIGVTALRM" },
		{ SIGPROF, "SIGPROF" },
#ifdef SIGPWR
		{ SIGPWR, "SIGPWR" },
#endif
#ifdef SIGSTKFLT
		{ SIGSTKFLT, "SIGSTKFLT" },
#endif
	};
	char name[16];

	(void)state;
	for (size_t i = 0; i < sizeof(soft) / sizeof(soft[0]); i++)
		expect_soft(soft[i].sig, soft[i].name);
	for (int sig = SIGRTMIN; sig <= SIGRTMAX; sig++) {
		snprintf(name, sizeof(name), "SIGRTMIN+%d", sig - SIGRTMIN);
		expect_soft(sig, name);
	}
}

static void test_sigxfsz_ignored(void **state)
{
	int sig = SIGXFSZ;
	char err[256];

	(void)state;
	assert_int_equal(child_raises(true, &sig, 1, NULL, err, sizeof(err)), CHILD_ALIVE);
}

static void test_bug_signals_take_the_emergency_path(void **state)
{
	int trap = SIGTRAP, sys = SIGSYS;
	char line[128];

	(void)state;
	snprintf(line, sizeof(line), "irdm-fw: SIGTRAP (signal %d): emergency torque off on 0 of 0 "
				     "devices\n",
		 SIGTRAP);
	expect_emergency(&trap, 1, true, line);
	snprintf(line, sizeof(line), "irdm-fw: SIGSYS (signal %d): emergency torque off on 0 of 0 "
				     "devices\n",
		 SIGSYS);
	expect_emergency(&sys, 1, false, line); /* at any time */
}

/* A second request while the loop runs: it is not listening. */
static void test_second_signal_in_the_loop_escalates(void **state)
{
	int sigs[2] = { SIGTERM, SIGINT };
	char line[128];

	(void)state;
	snprintf(line, sizeof(line), "irdm-fw: SIGINT (signal %d): emergency torque off on 0 of 0 "
				     "devices\n",
		 SIGINT);
	expect_emergency(sigs, 2, true, line);
}

/* Outside the loop (the set-up, or stop() and the log's close after it) a
 * second request changes nothing: the run ends as the first asked. */
static void test_second_signal_outside_the_loop_does_not(void **state)
{
	int sigs[2] = { SIGINT, SIGINT };
	char err[256];
	int rc;

	(void)state;
	rc = child_raises(false, sigs, 2, NULL, err, sizeof(err));
	if (rc != CHILD_ALIVE)
		fail_msg("expected no escalation outside the loop, got %d: %s", rc, err);
}

/* SIGPIPE comes from irdm-fw's own writes: never an escalation. */
static void test_sigpipe_never_escalates(void **state)
{
	int sigs[3] = { SIGTERM, SIGPIPE, SIGPIPE };
	char err[256];
	int rc;

	(void)state;
	rc = child_raises(true, sigs, 3, NULL, err, sizeof(err));
	if (rc != CHILD_ALIVE)
		fail_msg("expected SIGPIPE not to escalate, got %d: %s", rc, err);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_requests_set_the_flag),
		cmocka_unit_test(test_sigxfsz_ignored),
		cmocka_unit_test(test_bug_signals_take_the_emergency_path),
		cmocka_unit_test(test_second_signal_in_the_loop_escalates),
		cmocka_unit_test(test_second_signal_outside_the_loop_does_not),
		cmocka_unit_test(test_sigpipe_never_escalates),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
