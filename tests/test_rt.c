/* SPDX-License-Identifier: MIT */
/*
 * The real-time set-up (irdm/posix/rt.h) against what the system says on its own:
 * PREEMPT_RT detection on both kinds of strings, timespec arithmetic across
 * second boundaries and below zero, thread attributes read back from the
 * attr, this host's report against /sys/kernel/realtime and uname computed
 * here, memory locking read back from /proc, a SCHED_FIFO thread's policy
 * read back inside it, refusals (as an unprivileged child) returned as
 * IRDM_EPERM, and the stack pre-fault measured in page faults.
 */
#define _GNU_SOURCE
#include <alloca.h>
#include <pthread.h>
#include <sched.h>
#include <semaphore.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/posix/rt.h"

#define NS 1000000000L
#define FIFO_PRIO 10

static void ts_eq(struct timespec t, time_t sec, long nsec)
{
	assert_int_equal(t.tv_sec, sec);
	assert_int_equal(t.tv_nsec, nsec);
}

/* ---- PREEMPT_RT detection ---- */

static void test_preempt_rt_strings(void **state)
{
	const char *rt = "#1 SMP PREEMPT_RT Thu Jan  1 00:00:00 UTC 2026";
	const char *dyn = "#1 SMP PREEMPT_DYNAMIC @0";

	(void)state;
	/* the file decides when present */
	assert_true(irdm_rt_kernel_is_preempt_rt("1\n", dyn));
	assert_true(irdm_rt_kernel_is_preempt_rt("1", NULL));
	assert_false(irdm_rt_kernel_is_preempt_rt("0\n", rt));
	assert_false(irdm_rt_kernel_is_preempt_rt("", rt));
	assert_false(irdm_rt_kernel_is_preempt_rt("10\n", dyn));
	/* without it, the version string */
	assert_true(irdm_rt_kernel_is_preempt_rt(NULL, rt));
	assert_false(irdm_rt_kernel_is_preempt_rt(NULL, dyn));
	assert_false(irdm_rt_kernel_is_preempt_rt(NULL, "#1 SMP PREEMPT"));
	assert_false(irdm_rt_kernel_is_preempt_rt(NULL, NULL));
}

/* ---- timespec ---- */

static void test_timespec_add(void **state)
{
	struct timespec t;

	(void)state;
	t = (struct timespec){ 1, 999999999 };
	irdm_rt_timespec_add(&t, &(struct timespec){ 0, 1 });
	ts_eq(t, 2, 0);
	t = (struct timespec){ 0, 500000000 };
	irdm_rt_timespec_add(&t, &(struct timespec){ 0, 600000000 });
	ts_eq(t, 1, 100000000);
	t = (struct timespec){ 7, 999999999 };
	irdm_rt_timespec_add(&t, &(struct timespec){ 2, 999999999 });
	ts_eq(t, 10, 999999998);
	t = (struct timespec){ 3, 0 };
	irdm_rt_timespec_add(&t, &(struct timespec){ 0, 0 });
	ts_eq(t, 3, 0);
	/* negative steps: -0.1 s is { -1, 900000000 } */
	t = (struct timespec){ 5, 200000000 };
	irdm_rt_timespec_add(&t, &(struct timespec){ -1, 900000000 });
	ts_eq(t, 5, 100000000);
	t = (struct timespec){ 5, 50000000 };
	irdm_rt_timespec_add(&t, &(struct timespec){ -1, 900000000 });
	ts_eq(t, 4, 950000000);
	t = (struct timespec){ 0, 0 };
	irdm_rt_timespec_add(&t, &(struct timespec){ -1, 750000000 });
	ts_eq(t, -1, 750000000);
	/* 1 kHz for 1000 periods from just below a second: exactly one second on */
	t = (struct timespec){ 41, 999999000 };
	for (int i = 0; i < 1000; i++)
		irdm_rt_timespec_add(&t, &(struct timespec){ 0, 1000000 });
	ts_eq(t, 42, 999999000);
}

static void test_timespec_diff_cmp(void **state)
{
	const struct timespec a = { 1, 999999999 }, b = { 2, 1 }, c = { -1, 750000000 };
	const struct timespec z = { 0, 0 }, big = { 4000000000LL, 5 };

	(void)state;
	assert_int_equal(irdm_rt_timespec_diff_ns(&a, &b), 2);
	assert_int_equal(irdm_rt_timespec_diff_ns(&b, &a), -2);
	assert_int_equal(irdm_rt_timespec_diff_ns(&a, &a), 0);
	assert_int_equal(irdm_rt_timespec_diff_ns(&z, &c), -250000000);
	assert_int_equal(irdm_rt_timespec_diff_ns(&c, &b), 2250000001LL);
	/* past 2^32 seconds: 64-bit all the way */
	assert_true(irdm_rt_timespec_diff_ns(&z, &big) == 4000000000LL * NS + 5);
	assert_true(irdm_rt_timespec_cmp(&a, &b) < 0);
	assert_true(irdm_rt_timespec_cmp(&b, &a) > 0);
	assert_int_equal(irdm_rt_timespec_cmp(&a, &a), 0);
	assert_true(irdm_rt_timespec_cmp(&c, &z) < 0);
	assert_true(irdm_rt_timespec_cmp(&z, &c) > 0);
	/* same second: the nanoseconds decide */
	assert_true(irdm_rt_timespec_cmp(&(struct timespec){ 2, 0 }, &b) < 0);
	assert_true(irdm_rt_timespec_cmp(&b, &(struct timespec){ 2, 0 }) > 0);
}

static void test_sleep_until(void **state)
{
	struct timespec t0, until, t1;

	(void)state;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	until = t0;
	irdm_rt_timespec_add(&until, &(struct timespec){ 0, 5000000 });
	assert_int_equal(irdm_rt_sleep_until(&until), IRDM_OK);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	assert_true(irdm_rt_timespec_cmp(&t1, &until) >= 0);
	/* a time in the past returns at once */
	assert_int_equal(irdm_rt_sleep_until(&t0), IRDM_OK);
	assert_int_equal(irdm_rt_sleep_until(&(struct timespec){ 0, NS }), IRDM_EINVAL);
	assert_int_equal(irdm_rt_sleep_until(&(struct timespec){ 0, -1 }), IRDM_EINVAL);
}

/* ---- thread attributes ---- */

static void test_attr_fifo(void **state)
{
	struct irdm_rt_sched s = { SCHED_FIFO, FIFO_PRIO, IRDM_RT_ANY_CPU };
	struct sched_param sp;
	pthread_attr_t a;
	cpu_set_t set;
	int v;

	(void)state;
	assert_int_equal(irdm_rt_thread_attr(&a, &s), IRDM_OK);
	assert_int_equal(pthread_attr_getinheritsched(&a, &v), 0);
	assert_int_equal(v, PTHREAD_EXPLICIT_SCHED);
	assert_int_equal(pthread_attr_getschedpolicy(&a, &v), 0);
	assert_int_equal(v, SCHED_FIFO);
	assert_int_equal(pthread_attr_getschedparam(&a, &sp), 0);
	assert_int_equal(sp.sched_priority, FIFO_PRIO);
	pthread_attr_destroy(&a);

	s = (struct irdm_rt_sched){ SCHED_FIFO, 99, 0 };
	assert_int_equal(irdm_rt_thread_attr(&a, &s), IRDM_OK);
	assert_int_equal(pthread_attr_getschedparam(&a, &sp), 0);
	assert_int_equal(sp.sched_priority, 99);
	assert_int_equal(pthread_attr_getaffinity_np(&a, sizeof(set), &set), 0);
	assert_int_equal(CPU_COUNT(&set), 1);
	assert_true(CPU_ISSET(0, &set));
	pthread_attr_destroy(&a);

	s = (struct irdm_rt_sched){ SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	assert_int_equal(irdm_rt_thread_attr(&a, &s), IRDM_OK);
	assert_int_equal(pthread_attr_getinheritsched(&a, &v), 0);
	assert_int_equal(v, PTHREAD_EXPLICIT_SCHED);
	assert_int_equal(pthread_attr_getschedpolicy(&a, &v), 0);
	assert_int_equal(v, SCHED_OTHER);
	pthread_attr_destroy(&a);

	/* what no thread can be given */
	static const struct irdm_rt_sched bad[] = {
		{ SCHED_FIFO, 0, IRDM_RT_ANY_CPU },
		{ SCHED_FIFO, 100, IRDM_RT_ANY_CPU },
		{ SCHED_OTHER, 5, IRDM_RT_ANY_CPU },
		{ SCHED_RR, 10, IRDM_RT_ANY_CPU },
		{ 12345, 0, IRDM_RT_ANY_CPU },
		{ SCHED_FIFO, 10, IRDM_RT_CPU_EXCEPT(CPU_SETSIZE) },
		{ SCHED_FIFO, 10, CPU_SETSIZE },
	};
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++)
		assert_int_equal(irdm_rt_thread_attr(&a, &bad[i]), IRDM_EINVAL);
}

/* ---- the report on this host ---- */

/* This host's kernel, found here without the module. */
static bool host_is_preempt_rt(void)
{
	FILE *f = fopen("/sys/kernel/realtime", "r");
	struct utsname u;
	int c;

	if (f) {
		c = fgetc(f);
		fclose(f);
		return c == '1';
	}
	assert_int_equal(uname(&u), 0);
	return strstr(u.version, "PREEMPT_RT") != NULL;
}

static void test_report_this_host(void **state)
{
	struct irdm_rt_report r;
	struct sched_param sp;
	cpu_set_t set;
	char line[256];
	int policy;
	bool rt = host_is_preempt_rt();

	(void)state;
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	print_message("  %s\n", line);
	assert_int_equal(r.preempt_rt, rt);
	assert_int_equal(pthread_getschedparam(pthread_self(), &policy, &sp), 0);
	assert_int_equal(r.policy, policy);
	assert_int_equal(r.priority, sp.sched_priority);
	assert_int_equal(sched_getaffinity(0, sizeof(set), &set), 0);
	assert_int_equal(r.n_cpus, CPU_COUNT(&set));
	for (int c = 0; c < 64; c++)
		assert_int_equal(!!(r.cpu_mask >> c & 1), !!CPU_ISSET(c, &set));
	assert_true(r.cpu >= 0 && CPU_ISSET(r.cpu, &set));
	assert_true(r.mapped_kb > 0);
	if (!rt) {
		/* this kernel is not PREEMPT_RT: nothing may claim real time */
		assert_false(irdm_rt_report_realtime(&r));
		assert_non_null(strstr(line, "kernel not PREEMPT_RT"));
		assert_int_equal(strncmp(line, "real-time: NO (", 15), 0);
	}
}

/* The line says yes only when everything holds, and says what is missing. */
static void test_report_format(void **state)
{
	struct irdm_rt_report r = {
		.preempt_rt = true,
		.policy = SCHED_FIFO,
		.priority = 80,
		.cpu = 1,
		.cpu_mask = 0x4e,
		.n_cpus = 4,
		.memory_locked = true,
		.locked_kb = 2000,
		.mapped_kb = 2032,
	};
	char line[256], small[24];

	(void)state;
	assert_true(irdm_rt_report_realtime(&r));
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_string_equal(line, "real-time: yes (kernel PREEMPT_RT, SCHED_FIFO priority 80, "
				  "memory locked); CPU 1, affinity 1-3,6");
	r.n_cpus = 6;
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_non_null(strstr(line, "affinity 1-3,6,+2 above 63"));
	r.n_cpus = 4;

	r.memory_locked = false;
	assert_false(irdm_rt_report_realtime(&r));
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_string_equal(line, "real-time: NO (kernel PREEMPT_RT, SCHED_FIFO priority 80, "
				  "memory not locked: 2000 of 2032 kB); CPU 1, affinity 1-3,6");
	r.memory_locked = true;
	r.preempt_rt = false;
	assert_false(irdm_rt_report_realtime(&r));
	r.preempt_rt = true;
	r.policy = SCHED_OTHER;
	r.priority = 0;
	assert_false(irdm_rt_report_realtime(&r));
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_int_equal(strncmp(line, "real-time: NO (kernel PREEMPT_RT, SCHED_OTHER, memory locked)",
				 61),
			 0);
	r.policy = -1;
	r.cpu = -1;
	r.n_cpus = 0;
	assert_false(irdm_rt_report_realtime(&r));
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_string_equal(line, "real-time: NO (kernel PREEMPT_RT, policy unknown, memory locked); "
				  "CPU unknown, affinity unknown");
	/* cut, not overrun */
	assert_int_equal(irdm_rt_report_format(&r, small, sizeof(small)), IRDM_ENOMEM);
	assert_int_equal(strlen(small), sizeof(small) - 1);
	assert_int_equal(irdm_rt_report_format(&r, NULL, 10), IRDM_EINVAL);
	assert_int_equal(irdm_rt_report_format(&r, small, 0), IRDM_EINVAL);
}

/* ---- memory ---- */

static void test_lock_memory(void **state)
{
	struct irdm_rt_report r;
	char line[256];
	int rc;

	(void)state;
	rc = irdm_rt_lock_memory();
	if (IRDM_RT_ASAN) {
		assert_int_equal(rc, IRDM_ENOTSUP);
		return;
	}
	if (rc == IRDM_EPERM) {
		print_message("  mlockall refused: %s\n", irdm_strerror(rc));
		assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
		assert_false(r.memory_locked);
		return;
	}
	assert_int_equal(rc, IRDM_OK);
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	assert_true(r.memory_locked);
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	print_message("  locked: %s\n", line);
	assert_non_null(strstr(line, ", memory locked)"));
	/* MCL_FUTURE: a mapping made after the call is locked too */
	void *p = malloc(16 << 20);
	assert_non_null(p);
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	assert_true(r.memory_locked);
	free(p);
	irdm_rt_unlock_memory();
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	assert_false(r.memory_locked);
	assert_int_equal(irdm_rt_report_format(&r, line, sizeof(line)), IRDM_OK);
	assert_non_null(strstr(line, ", memory not locked: "));
}

/* ---- the stack ---- */

static long thread_minflt(void)
{
	struct rusage ru;

	getrusage(RUSAGE_THREAD, &ru);
	return ru.ru_minflt;
}

/* What a loop's deep frames do: write use bytes of stack. */
static __attribute__((noinline)) void use_stack(size_t use)
{
	volatile unsigned char *p = alloca(use);

	for (size_t i = use; i > 0; i -= 512)
		p[i - 1] = 1;
}

struct stack_probe {
	size_t prefault, use;
	int rc;
	long faults;
};

static void *probe_stack(void *arg)
{
	struct stack_probe *s = arg;
	long f0;

	s->rc = irdm_rt_prefault_stack(s->prefault);
	f0 = thread_minflt();
	use_stack(s->use);
	s->faults = thread_minflt() - f0;
	return NULL;
}

/* A fresh stack of stack_bytes (no size the glibc stack cache holds). */
static void run_probe(struct stack_probe *s, size_t stack_bytes)
{
	pthread_attr_t a;
	pthread_t t;

	assert_int_equal(pthread_attr_init(&a), 0);
	assert_int_equal(pthread_attr_setstacksize(&a, stack_bytes), 0);
	assert_int_equal(pthread_create(&t, &a, probe_stack, s), 0);
	assert_int_equal(pthread_join(t, NULL), 0);
	pthread_attr_destroy(&a);
}

static void test_prefault_stack(void **state)
{
	struct stack_probe cold = { 0, 512 << 10, -1, 0 }, warm = { 1 << 20, 512 << 10, -1, 0 };
	struct stack_probe deep = { 1 << 20, 4096, -1, 0 };

	(void)state;
	/* more than the stack holds: refused, not a SIGSEGV */
	run_probe(&deep, 256 << 10);
	assert_int_equal(deep.rc, IRDM_EINVAL);
	assert_int_equal(irdm_rt_prefault_stack((size_t)1 << 40), IRDM_EINVAL);
	assert_int_equal(irdm_rt_prefault_stack(256 << 10), IRDM_OK);
	assert_int_equal(irdm_rt_prefault_stack(0), IRDM_OK);
	if (IRDM_RT_ASAN) {
		/* ASan's stack shadow faults on its own schedule */
		print_message("  built with AddressSanitizer: fault counts skipped\n");
		return;
	}
	/* without: the 128 pages fault as they are first written */
	run_probe(&cold, 13 << 20);
	assert_int_equal(cold.rc, IRDM_OK);
	print_message("  512 KiB of fresh stack: %ld faults cold, ", cold.faults);
	assert_true(cold.faults >= 64);
	/* with: none */
	run_probe(&warm, 14 << 20);
	print_message("%ld after a 1 MiB pre-fault\n", warm.faults);
	assert_int_equal(warm.rc, IRDM_OK);
	assert_true(warm.faults <= 1);
}

/* ---- scheduling ---- */

struct granted {
	struct irdm_rt_sched set_self; /* applied inside, if policy >= 0 */
	int set_rc;
	struct irdm_rt_report r;
	int report_rc;
	char line[256];
};

static void *read_back(void *arg)
{
	struct granted *g = arg;

	g->set_rc = g->set_self.policy >= 0 ? irdm_rt_set_self(&g->set_self) : IRDM_OK;
	g->report_rc = irdm_rt_report_get(&g->r);
	irdm_rt_report_format(&g->r, g->line, sizeof(g->line));
	return NULL;
}

static void test_thread_fifo(void **state)
{
	const struct irdm_rt_sched s = { SCHED_FIFO, FIFO_PRIO, IRDM_RT_ANY_CPU };
	struct granted g = { .set_self.policy = -1 };
	pthread_t t;
	int rc;

	(void)state;
	rc = irdm_rt_thread_start(&t, &s, read_back, &g);
	if (rc == IRDM_EPERM) {
		/* refused: said so, and no thread runs at some other policy */
		print_message("  SCHED_FIFO %d refused: %s\n", FIFO_PRIO, irdm_strerror(rc));
		return;
	}
	assert_int_equal(rc, IRDM_OK);
	assert_int_equal(pthread_join(t, NULL), 0);
	print_message("  in the thread: %s\n", g.line);
	assert_int_equal(g.report_rc, IRDM_OK);
	assert_int_equal(g.r.policy, SCHED_FIFO);
	assert_int_equal(g.r.priority, FIFO_PRIO);
	assert_non_null(strstr(g.line, "SCHED_FIFO priority 10,"));
	assert_int_equal(irdm_rt_report_realtime(&g.r), g.r.preempt_rt && g.r.memory_locked);
}

/*
 * A helper kept off the force thread's CPU: started by a creator pinned to
 * one CPU (which it would inherit), with IRDM_RT_CPU_EXCEPT(that CPU) it
 * runs on every other online CPU, and only there; alone on a one-CPU
 * machine it keeps that CPU.
 */
static void *pinned_cpu_of(void *arg)
{
	((struct granted *)arg)->set_rc = irdm_rt_pinned_cpu();
	return NULL;
}

static void test_cpu_except(void **state)
{
	const struct irdm_rt_sched pin_first = { SCHED_OTHER, 0, 0 };
	struct granted g = { .set_self = { SCHED_OTHER, 0, IRDM_RT_CPU_EXCEPT(0) } };
	long online = sysconf(_SC_NPROCESSORS_ONLN);
	uint64_t want = 0;
	pthread_t t;

	(void)state;
	for (long c = 1; c < online && c < 64; c++)
		want |= UINT64_C(1) << c;
	if (!want)
		want = 1;
	/* pinned to CPU 0 first, as a force thread would be */
	assert_int_equal(irdm_rt_thread_start(&t, &pin_first, read_back, &g), IRDM_OK);
	assert_int_equal(pthread_join(t, NULL), 0);
	print_message("  CPU_EXCEPT(0) on %ld CPUs: %s\n", online, g.line);
	assert_int_equal(g.set_rc, IRDM_OK);
	assert_true(g.r.cpu_mask == want);
	assert_int_equal(irdm_rt_pinned_cpu(), -1); /* the test runs on all */
	g = (struct granted){ .set_self = { SCHED_OTHER, 0, 0 } };
	assert_int_equal(irdm_rt_thread_start(&t, &pin_first, pinned_cpu_of, &g), IRDM_OK);
	assert_int_equal(pthread_join(t, NULL), 0);
	assert_int_equal(g.set_rc, 0); /* pinned to CPU 0: 0 */
}

/* A thread that starts SCHED_OTHER and makes itself FIFO on the last CPU. */
static void test_set_self(void **state)
{
	const struct irdm_rt_sched other = { SCHED_OTHER, 0, 0 };
	struct granted g;
	cpu_set_t set;
	pthread_t t;
	int cpu = -1;

	(void)state;
	assert_int_equal(sched_getaffinity(0, sizeof(set), &set), 0);
	for (int c = 0; c < 64; c++)
		if (CPU_ISSET(c, &set))
			cpu = c;
	assert_true(cpu >= 0);
	g = (struct granted){ .set_self = { SCHED_FIFO, FIFO_PRIO + 2, cpu } };
	assert_int_equal(irdm_rt_thread_start(&t, &other, read_back, &g), IRDM_OK);
	assert_int_equal(pthread_join(t, NULL), 0);
	print_message("  after irdm_rt_set_self: %s\n", g.line);
	assert_int_equal(g.r.cpu, cpu);
	assert_true(g.r.cpu_mask == UINT64_C(1) << cpu);
	assert_int_equal(g.r.n_cpus, 1);
	if (g.set_rc == IRDM_EPERM) {
		assert_int_equal(g.r.policy, SCHED_OTHER);
		return;
	}
	assert_int_equal(g.set_rc, IRDM_OK);
	assert_int_equal(g.r.policy, SCHED_FIFO);
	assert_int_equal(g.r.priority, FIFO_PRIO + 2);

	/* a CPU that is not ours: refused before anything changes */
	g = (struct granted){ .set_self = { SCHED_FIFO, FIFO_PRIO, CPU_SETSIZE - 1 } };
	assert_int_equal(irdm_rt_thread_start(&t, &other, read_back, &g), IRDM_OK);
	assert_int_equal(pthread_join(t, NULL), 0);
	assert_int_equal(g.set_rc, IRDM_EINVAL);
	assert_int_equal(g.r.policy, SCHED_OTHER);
}

/*
 * Refusals, for real: a child that drops to an unprivileged user with no
 * RLIMIT_RTPRIO and no RLIMIT_MEMLOCK.  Each refusal must come back as
 * IRDM_EPERM: the exit code is the first step that did not.
 */
static int refused_child(void)
{
	const struct rlimit none = { 0, 0 };
	const struct irdm_rt_sched fifo = { SCHED_FIFO, FIFO_PRIO, IRDM_RT_ANY_CPU };
	struct granted g = { .set_self.policy = -1 };
	struct sched_param sp;
	int policy;
	pthread_t t;

	if (setrlimit(RLIMIT_RTPRIO, &none) || setrlimit(RLIMIT_MEMLOCK, &none))
		return 10;
	if (getuid() == 0 && (setgid(65534) || setuid(65534)))
		return 11;
	if (irdm_rt_thread_start(&t, &fifo, read_back, &g) != IRDM_EPERM)
		return 1;
	if (irdm_rt_set_self(&fifo) != IRDM_EPERM)
		return 2;
	/* and the caller was not changed behind its back */
	if (pthread_getschedparam(pthread_self(), &policy, &sp) || policy != SCHED_OTHER)
		return 3;
	if (irdm_rt_lock_memory() != (IRDM_RT_ASAN ? IRDM_ENOTSUP : IRDM_EPERM))
		return 4;
	return 0;
}

static void test_refusals(void **state)
{
	int status;
	pid_t pid;

	(void)state;
	fflush(NULL);
	pid = fork();
	if (pid == 0)
		_exit(refused_child());
	assert_true(pid > 0);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status));
	if (WEXITSTATUS(status) >= 10) {
		print_message("  cannot drop privileges here (step %d): skipped\n",
			      WEXITSTATUS(status));
		skip();
	}
	assert_int_equal(WEXITSTATUS(status), 0);
}

/* ---- the loop's CPU to itself ---- */

struct waiter {
	sem_t *go, up;
	pid_t tid;
};

static void *wait_on(void *arg)
{
	struct waiter *w = arg;

	w->tid = (pid_t)syscall(SYS_gettid);
	sem_post(&w->up);
	sem_wait(w->go);
	return NULL;
}

/* Reads this process's threads: counts the intruders; their masks in *masks. */
static int check_tasks(int cpu, pid_t loop, pid_t a, pid_t b, uint64_t masks[2], bool *loop_seen)
{
	struct irdm_rt_task tasks[16];
	char line[160];
	size_t n;
	int rc = irdm_rt_isolation_check(cpu, loop, tasks, 16, &n);

	*loop_seen = false;
	for (size_t i = 0; i < n; i++) {
		assert_int_equal(irdm_rt_task_format(&tasks[i], line, sizeof(line)), IRDM_OK);
		print_message("  %s\n", line);
		assert_int_equal(tasks[i].intrudes, strstr(line, "may run on the loop's CPU") != NULL);
		if (tasks[i].tid == a)
			masks[0] = tasks[i].cpu_mask;
		if (tasks[i].tid == b)
			masks[1] = tasks[i].cpu_mask;
		if (tasks[i].tid == loop) {
			*loop_seen = tasks[i].loop && strstr(line, "(the loop)");
			assert_false(tasks[i].intrudes);
		}
	}
	return rc;
}

/*
 * Two threads that may run on the loop's CPU (one on every CPU, one pinned
 * to it alone): the check names both; after irdm_rt_isolate_cpu() neither
 * may, the first keeps its other CPUs, the second moves to them; the loop's
 * own thread (this one) is never an intruder nor moved.
 */
static void test_isolation(void **state)
{
	struct irdm_rt_sched pin;
	long online = sysconf(_SC_NPROCESSORS_ONLN);
	uint64_t all = 0, masks[2] = { 0, 0 }, bit, mine;
	struct irdm_rt_report r;
	pthread_t ta, tb;
	pid_t loop = (pid_t)syscall(SYS_gettid), a, b;
	struct waiter wa, wb;
	bool loop_seen;
	sem_t go;
	int cpu;

	(void)state;
	if (online < 2 || online > 64)
		skip();
	cpu = (int)online - 1;
	bit = UINT64_C(1) << cpu;
	for (long c = 0; c < online; c++)
		all |= UINT64_C(1) << c;
	pin = (struct irdm_rt_sched){ SCHED_OTHER, 0, cpu };
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	mine = r.cpu_mask;
	sem_init(&go, 0, 0);
	wa = (struct waiter){ .go = &go };
	wb = wa;
	sem_init(&wa.up, 0, 0);
	sem_init(&wb.up, 0, 0);
	assert_int_equal(pthread_create(&ta, NULL, wait_on, &wa), 0);
	assert_int_equal(irdm_rt_thread_start(&tb, &pin, wait_on, &wb), IRDM_OK);
	sem_wait(&wa.up);
	sem_wait(&wb.up);
	a = wa.tid;
	b = wb.tid;
	assert_int_equal(check_tasks(cpu, loop, a, b, masks, &loop_seen), 2);
	assert_true(loop_seen);
	assert_true(masks[0] == all && masks[1] == bit);
	/* without a CPU of its own, the loop has no intruder to name */
	assert_int_equal(check_tasks(-1, loop, a, b, masks, &loop_seen), 0);
	assert_int_equal(irdm_rt_isolate_cpu(cpu, loop), IRDM_OK);
	assert_int_equal(check_tasks(cpu, loop, a, b, masks, &loop_seen), 0);
	assert_true(masks[0] == (all & ~bit) && masks[1] == (all & ~bit));
	assert_int_equal(irdm_rt_report_get(&r), IRDM_OK);
	assert_true(r.cpu_mask == mine);
	assert_int_equal(irdm_rt_isolate_cpu(-1, loop), IRDM_EINVAL);
	sem_post(&go);
	sem_post(&go);
	pthread_join(ta, NULL);
	pthread_join(tb, NULL);
	sem_destroy(&go);
}

/*
 * The idle-latency request: held, the kernel's answer is the value asked
 * for; released, it is what it was before.  Needs the device (root): a
 * refusal is IRDM_EPERM and the rest is skipped.
 */
static void test_cpu_latency_hold(void **state)
{
	int32_t before = irdm_rt_cpu_latency_us();
	int hold;

	(void)state;
	hold = irdm_rt_cpu_latency_hold(0);
	print_message("  /dev/cpu_dma_latency: %d us before, hold %d\n", (int)before, hold);
	if (hold == IRDM_EPERM || hold == IRDM_ENOTSUP)
		skip();
	assert_true(hold >= 0);
	assert_int_equal(irdm_rt_cpu_latency_us(), 0);
	irdm_rt_cpu_latency_release(hold);
	assert_int_equal(irdm_rt_cpu_latency_us(), before);
	irdm_rt_cpu_latency_release(-1); /* nothing held: nothing done */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_preempt_rt_strings),
		cmocka_unit_test(test_timespec_add),
		cmocka_unit_test(test_timespec_diff_cmp),
		cmocka_unit_test(test_sleep_until),
		cmocka_unit_test(test_attr_fifo),
		cmocka_unit_test(test_report_this_host),
		cmocka_unit_test(test_report_format),
		/* before any lock: MCL_FUTURE would populate the fresh stacks */
		cmocka_unit_test(test_prefault_stack),
		cmocka_unit_test(test_lock_memory),
		cmocka_unit_test(test_thread_fifo),
		cmocka_unit_test(test_set_self),
		cmocka_unit_test(test_cpu_except),
		cmocka_unit_test(test_refusals),
		cmocka_unit_test(test_isolation),
		cmocka_unit_test(test_cpu_latency_hold),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
