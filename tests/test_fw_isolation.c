/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw's loop has its CPU to itself: during a real-clock run on a board
 * whose `cpu` is set, every thread of the process but the loop's (the log
 * writer, the deformation worker, the run's monitor, and the BLAS pool
 * started before main with the whole machine in its mask) may run on
 * every other CPU and not on that one, as /proc/PID/task says from
 * outside the process; the loop's thread runs on that CPU alone.  The
 * start-up lines list each of those threads, as seen here, and none as
 * "may run on the loop's CPU".  While the loop runs, no CPU may enter an
 * idle state slower than 0 us to leave (/dev/cpu_dma_latency reads 0:
 * the request irdm-fw holds, as cyclictest does).
 * Needs IRDM_FW and IRDM_TICK_IMAGE (make test sets them) and two CPUs.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "support/run_prog.h"
#include "support/test_files.h"
#include "support/tick_image.h"

#define BOARD "boards/sim-phantom.board"
#define PRESS "scenes/users/press-hold-release.user"
#define TASKS_MAX 64

static char dir[256], out_text[16384], err_text[8192];

static const char *env_or(const char *name, const char *dflt)
{
	const char *p = getenv(name);

	return p ? p : dflt;
}

/* BOARD pinned to cpu, overruns counted rather than faulting (a busy host). */
static void pinned_board(char *path, size_t len, int cpu)
{
	char text[16384], out[16384] = "", *line, *save, pin[32];

	snprintf(pin, sizeof(pin), "cpu = %d", cpu);
	tf_read_text(BOARD, text, sizeof(text));
	for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		if (!strncmp(line, "overrun_fault_count", 19))
			line = "overrun_fault_count = 1000";
		else if (!strncmp(line, "watchdog_us", 11))
			line = "watchdog_us = 1000000";
		else if (!strncmp(line, "cpu ", 4))
			line = pin;
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	snprintf(path, len, "%s/pinned.board", dir);
	tf_write_text(path, out);
}

/* "0-1,3" into a mask of CPUs 0..63. */
static uint64_t parse_cpu_list(const char *s)
{
	uint64_t mask = 0;

	while (*s && *s != '\n') {
		char *end;
		long a = strtol(s, &end, 10), b = a;

		if (end == s)
			fail_msg("bad CPU list: %s", s);
		if (*end == '-')
			b = strtol(end + 1, &end, 10);
		for (long c = a; c <= b && c < 64; c++)
			mask |= UINT64_C(1) << c;
		s = *end == ',' ? end + 1 : end;
	}
	return mask;
}

/* A task's Cpus_allowed_list; false if it ended meanwhile. */
static bool task_mask(pid_t pid, pid_t tid, uint64_t *mask)
{
	char path[96], line[256];
	bool found = false;
	FILE *f;

	snprintf(path, sizeof(path), "/proc/%d/task/%d/status", (int)pid, (int)tid);
	f = fopen(path, "r");
	if (!f)
		return false;
	while (fgets(line, sizeof(line), f))
		if (!strncmp(line, "Cpus_allowed_list:", 18)) {
			*mask = parse_cpu_list(line + 18 + strspn(line + 18, " \t"));
			found = true;
		}
	fclose(f);
	return found;
}

/* The child's tasks and their masks, read from outside the process. */
static size_t read_tasks(pid_t pid, pid_t *tids, uint64_t *masks)
{
	char path[64];
	struct dirent *e;
	size_t n = 0;
	DIR *d;

	snprintf(path, sizeof(path), "/proc/%d/task", (int)pid);
	d = opendir(path);
	assert_non_null(d);
	while ((e = readdir(d)) && n < TASKS_MAX) {
		pid_t tid = (pid_t)atoi(e->d_name);

		if (tid > 0 && task_mask(pid, tid, &masks[n]))
			tids[n++] = tid;
	}
	closedir(d);
	return n;
}

/* The kernel's idle-latency limit in force, us; -1 if unreadable (not root). */
static int32_t cpu_latency_us(void)
{
	FILE *f = fopen("/dev/cpu_dma_latency", "rb");
	int32_t us = -1;

	if (!f)
		return -1;
	if (fread(&us, sizeof(us), 1, f) != 1)
		us = -1;
	fclose(f);
	return us;
}

static void test_only_the_loop_runs_on_its_cpu(void **state)
{
	const struct timespec settle = { 1, 0 }; /* every thread up, the loop running */
	pid_t pid, tids[TASKS_MAX];
	uint64_t masks[TASKS_MAX], loop_bit;
	char board[320], log[320], line[128];
	int32_t before = cpu_latency_us(), during;
	int cpu, rc;
	size_t n;

	(void)state;
	if (sysconf(_SC_NPROCESSORS_ONLN) < 2)
		skip();
	cpu = (int)sysconf(_SC_NPROCESSORS_ONLN) - 1;
	loop_bit = UINT64_C(1) << cpu;
	pinned_board(board, sizeof(board), cpu);
	snprintf(log, sizeof(log), "%s/run.log", dir);
	/* with the log: its writer is one more thread */
	pid = rp_spawn(dir, env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){ "--board", board, "--image", tick_image_path(), "--user", PRESS, "--clock", "real", "--duration", "2", "--log", log, NULL });
	nanosleep(&settle, NULL);
	n = read_tasks(pid, tids, masks);
	during = cpu_latency_us();
	rc = rp_finish(dir, pid, out_text, sizeof(out_text), err_text, sizeof(err_text));
	if (rc != 0)
		fail_msg("irdm-fw exited %d: %s", rc, err_text);
	print_message("/dev/cpu_dma_latency: %d us before, %d during the run, %d after\n",
		      (int)before, (int)during, (int)cpu_latency_us());
	/* readable here (root): irdm-fw could open it too; 0 before is
	 * another process's request, which would hide irdm-fw's */
	if (before > 0) {
		assert_int_equal(during, 0);
		assert_non_null(strstr(out_text, "idle states: none slower than 0 us to leave"));
	}
	/* the loop, the log writer, the deformation worker, the monitor at least */
	print_message("%zu threads during the run, the loop on CPU %d\n", n, cpu);
	assert_true(n >= 4);
	for (size_t i = 0; i < n; i++) {
		print_message("  task %d: CPUs 0x%llx\n", (int)tids[i], (unsigned long long)masks[i]);
		if (tids[i] == pid)
			assert_true(masks[i] == loop_bit);
		else if (masks[i] & loop_bit)
			fail_msg("thread %d may run on the loop's CPU %d (mask 0x%llx)", (int)tids[i],
				 cpu, (unsigned long long)masks[i]);
		/* the start-up lines name each thread seen from outside */
		snprintf(line, sizeof(line), "thread %d '", (int)tids[i]);
		if (!strstr(out_text, line))
			fail_msg("no start-up line for thread %d: %s", (int)tids[i], out_text);
	}
	snprintf(line, sizeof(line), "thread %d 'irdm-fw': SCHED_", (int)pid);
	assert_non_null(strstr(out_text, line));
	assert_non_null(strstr(out_text, "(the loop)\n"));
	assert_null(strstr(out_text, "may run on the loop's CPU"));
	assert_null(strstr(err_text, "may run on the loop's CPU"));
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "fw-isolation") ? -1 : 0;
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_only_the_loop_runs_on_its_cpu),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
