/* SPDX-License-Identifier: MIT */
/*
 * Scheduling that is asked for explicitly and refused loudly: a thread gets
 * the policy, priority and CPU it is given or an error, never what it would
 * have inherited.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include "irdm/posix/rt.h"

/* A pthread error number in the project's space; `other` for the rest. */
static int from_errno(int e, int other)
{
	switch (e) {
	case 0:
		return IRDM_OK;
	case EPERM:
		return IRDM_EPERM;
	case EINVAL:
		return IRDM_EINVAL;
	case ENOMEM:
		return IRDM_ENOMEM;
	default:
		return other;
	}
}

static bool sched_valid(const struct irdm_rt_sched *s)
{
	if (s->policy != SCHED_FIFO && s->policy != SCHED_OTHER)
		return false;
	if (s->priority < sched_get_priority_min(s->policy) ||
	    s->priority > sched_get_priority_max(s->policy))
		return false;
	return (s->cpu >= IRDM_RT_CPU_EXCEPT(CPU_SETSIZE - 1) && s->cpu < CPU_SETSIZE);
}

/*
 * The CPUs s->cpu names; false for "any" (the thread keeps the mask it
 * would inherit, which is every CPU unless its creator was pinned).  With
 * EXCEPT: the online CPUs but that one, or "any" if none is left.
 */
static bool cpu_mask(const struct irdm_rt_sched *s, cpu_set_t *set)
{
	long online;
	int avoid;

	CPU_ZERO(set);
	if (s->cpu >= 0) {
		CPU_SET(s->cpu, set);
		return true;
	}
	if (s->cpu == IRDM_RT_ANY_CPU)
		return false;
	avoid = -2 - s->cpu;
	online = sysconf(_SC_NPROCESSORS_ONLN);
	for (long c = 0; c < online && c < CPU_SETSIZE; c++)
		if (c != avoid)
			CPU_SET((int)c, set);
	return CPU_COUNT(set) > 0;
}

int irdm_rt_thread_attr(pthread_attr_t *attr, const struct irdm_rt_sched *s)
{
	struct sched_param sp = { .sched_priority = s->priority };
	cpu_set_t set;
	int rc;

	if (!sched_valid(s))
		return IRDM_EINVAL;
	if (pthread_attr_init(attr))
		return IRDM_ENOMEM;
	/* without EXPLICIT_SCHED the policy below would be silently ignored */
	rc = pthread_attr_setinheritsched(attr, PTHREAD_EXPLICIT_SCHED);
	if (!rc)
		rc = pthread_attr_setschedpolicy(attr, s->policy);
	if (!rc)
		rc = pthread_attr_setschedparam(attr, &sp);
	if (!rc && cpu_mask(s, &set))
		rc = pthread_attr_setaffinity_np(attr, sizeof(set), &set);
	if (rc)
		goto destroy;
	return IRDM_OK;
destroy:
	pthread_attr_destroy(attr);
	return from_errno(rc, IRDM_EINVAL);
}

int irdm_rt_thread_start(pthread_t *tid, const struct irdm_rt_sched *s,
			 void *(*fn)(void *), void *arg)
{
	pthread_attr_t attr;
	int rc;

	rc = irdm_rt_thread_attr(&attr, s);
	if (rc)
		return rc;
	/* EPERM: no CAP_SYS_NICE or RLIMIT_RTPRIO; EINVAL: the CPU is not ours */
	rc = pthread_create(tid, &attr, fn, arg);
	pthread_attr_destroy(&attr);
	return from_errno(rc, IRDM_ETHREAD);
}

int irdm_rt_set_self(const struct irdm_rt_sched *s)
{
	struct sched_param sp = { .sched_priority = s->priority };
	cpu_set_t set;
	int rc;

	if (!sched_valid(s))
		return IRDM_EINVAL;
	if (cpu_mask(s, &set)) {
		rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
		if (rc)
			return from_errno(rc, IRDM_EINVAL);
	}
	rc = pthread_setschedparam(pthread_self(), s->policy, &sp);
	return from_errno(rc, IRDM_EINVAL);
}

int irdm_rt_pinned_cpu(void)
{
	cpu_set_t set;

	if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) || CPU_COUNT(&set) != 1)
		return -1;
	for (int c = 0; c < CPU_SETSIZE; c++)
		if (CPU_ISSET(c, &set))
			return c;
	return -1;
}
