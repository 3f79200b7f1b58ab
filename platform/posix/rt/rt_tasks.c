/* SPDX-License-Identifier: MIT */
/*
 * The loop's CPU to the loop alone: every other thread of the process is
 * moved off it and then read back from /proc/self/task.  A thread that may
 * run there can be in a system call, holding the CPU with preemption off,
 * when the loop's timer fires; whichever thread it is (the program's own,
 * or one a library started before main, with the whole machine in its
 * mask), the loop then wakes late.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "irdm/posix/rt.h"

/* The next thread id of an open /proc/self/task, 0 at the end. */
static pid_t next_tid(DIR *d)
{
	struct dirent *e;

	while ((e = readdir(d))) {
		char *end;
		long v = strtol(e->d_name, &end, 10);

		if (*end == '\0' && v > 0)
			return (pid_t)v;
	}
	return 0;
}

/* Online CPUs but cpu: where a thread pinned to it alone goes. */
static void others(int cpu, cpu_set_t *set)
{
	long online = sysconf(_SC_NPROCESSORS_ONLN);

	CPU_ZERO(set);
	for (long c = 0; c < online && c < CPU_SETSIZE; c++)
		if (c != cpu)
			CPU_SET((int)c, set);
}

int irdm_rt_isolate_cpu(int cpu, pid_t keep_tid)
{
	cpu_set_t set, rest;
	DIR *d;
	pid_t tid;
	int rc = IRDM_OK;

	if (cpu < 0 || cpu >= CPU_SETSIZE)
		return IRDM_EINVAL;
	others(cpu, &rest);
	if (!CPU_COUNT(&rest))
		return IRDM_EINVAL;
	d = opendir("/proc/self/task");
	if (!d)
		return IRDM_EIO;
	while ((tid = next_tid(d))) {
		if (tid == keep_tid)
			continue;
		/* a thread that ended meanwhile (ESRCH) no longer matters */
		if (sched_getaffinity(tid, sizeof(set), &set))
			continue;
		if (!CPU_ISSET(cpu, &set))
			continue;
		CPU_CLR(cpu, &set);
		if (!CPU_COUNT(&set))
			set = rest;
		if (sched_setaffinity(tid, sizeof(set), &set) && errno != ESRCH)
			rc = IRDM_EPERM;
	}
	closedir(d);
	return rc;
}

static void read_name(pid_t tid, char *name, size_t len)
{
	char path[64];
	FILE *f;

	snprintf(path, sizeof(path), "/proc/self/task/%d/comm", (int)tid);
	name[0] = '\0';
	f = fopen(path, "r");
	if (!f)
		return;
	if (fgets(name, (int)len, f))
		name[strcspn(name, "\n")] = '\0';
	fclose(f);
}

static void read_task(pid_t tid, struct irdm_rt_task *t)
{
	struct sched_param sp;
	cpu_set_t set;
	int policy;

	memset(t, 0, sizeof(*t));
	t->tid = tid;
	t->policy = -1;
	read_name(tid, t->name, sizeof(t->name));
	policy = sched_getscheduler(tid);
	if (policy >= 0 && !sched_getparam(tid, &sp)) {
		t->policy = policy & ~SCHED_RESET_ON_FORK;
		t->priority = sp.sched_priority;
	}
	if (sched_getaffinity(tid, sizeof(set), &set))
		return;
	t->n_cpus = (unsigned)CPU_COUNT(&set);
	for (int c = 0; c < 64; c++)
		if (CPU_ISSET(c, &set))
			t->cpu_mask |= UINT64_C(1) << c;
}

/* May t run on cpu?  Unknown counts as yes; CPUs above 63 as the mask says. */
static bool may_run_on(const struct irdm_rt_task *t, int cpu)
{
	if (!t->n_cpus)
		return true;
	if (cpu < 64)
		return t->cpu_mask >> cpu & 1;
	return t->n_cpus > (unsigned)__builtin_popcountll(t->cpu_mask);
}

int irdm_rt_isolation_check(int cpu, pid_t loop_tid, struct irdm_rt_task *tasks, size_t max,
			    size_t *n)
{
	DIR *d = opendir("/proc/self/task");
	int intruders = 0;
	bool more = false;
	pid_t tid;

	*n = 0;
	if (!d)
		return IRDM_EIO;
	while ((tid = next_tid(d))) {
		struct irdm_rt_task *t = &tasks[*n];

		if (*n == max) {
			more = true;
			break;
		}
		read_task(tid, t);
		t->loop = tid == loop_tid;
		t->intrudes = !t->loop && cpu >= 0 && may_run_on(t, cpu);
		intruders += t->intrudes;
		(*n)++;
	}
	closedir(d);
	return more ? IRDM_ENOMEM : intruders;
}
