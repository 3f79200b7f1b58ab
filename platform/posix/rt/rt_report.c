/* SPDX-License-Identifier: MIT */
/*
 * What the system granted, read back rather than assumed, and one line that
 * says it: a loop that asked for real time and did not get it must say so
 * before it runs.
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <pthread.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/utsname.h>

#include "irdm/posix/rt.h"

/*
 * The kernel's special mappings ([vvar], [vdso]: 32 kB on x86-64 today)
 * count in VmSize but mlockall() cannot lock them; anything unlocked beyond
 * this is a real mapping.
 */
#define UNLOCKABLE_KB 64

bool irdm_rt_kernel_is_preempt_rt(const char *sys_realtime, const char *uname_version)
{
	/* the file exists on PREEMPT_RT kernels only, and then says "1" */
	if (sys_realtime)
		return sys_realtime[0] == '1' &&
		       (!sys_realtime[1] || isspace((unsigned char)sys_realtime[1]));
	return uname_version && strstr(uname_version, "PREEMPT_RT");
}

/* The first line of a file into buf; NULL if it cannot be read. */
static const char *first_line(const char *path, char *buf, size_t len)
{
	FILE *f = fopen(path, "r");
	const char *s = NULL;

	if (!f)
		return NULL;
	if (fgets(buf, (int)len, f))
		s = buf;
	fclose(f);
	return s;
}

static int read_kernel(struct irdm_rt_report *r)
{
	char rt[16];
	struct utsname u;

	if (uname(&u))
		return IRDM_EIO;
	r->preempt_rt = irdm_rt_kernel_is_preempt_rt(first_line("/sys/kernel/realtime", rt,
								sizeof(rt)),
						     u.version);
	return IRDM_OK;
}

static int read_sched(struct irdm_rt_report *r)
{
	struct sched_param sp;
	cpu_set_t set;
	int policy;

	r->cpu = sched_getcpu();
	if (pthread_getschedparam(pthread_self(), &policy, &sp) ||
	    pthread_getaffinity_np(pthread_self(), sizeof(set), &set))
		return IRDM_EIO;
	r->policy = policy;
	r->priority = sp.sched_priority;
	r->n_cpus = (unsigned)CPU_COUNT(&set);
	for (int c = 0; c < 64; c++)
		if (CPU_ISSET(c, &set))
			r->cpu_mask |= UINT64_C(1) << c;
	return r->cpu < 0 ? IRDM_EIO : IRDM_OK;
}

/* VmLck and VmSize: locked only if every lockable mapping is. */
static int read_memory(struct irdm_rt_report *r)
{
	FILE *f = fopen("/proc/self/status", "r");
	char line[128];
	unsigned found = 0;

	if (!f)
		return IRDM_EIO;
	while (fgets(line, sizeof(line), f)) {
		if (sscanf(line, "VmLck: %lu", &r->locked_kb) == 1)
			found |= 1;
		else if (sscanf(line, "VmSize: %lu", &r->mapped_kb) == 1)
			found |= 2;
	}
	fclose(f);
	if (found != 3)
		return IRDM_EIO;
	r->memory_locked = r->locked_kb + UNLOCKABLE_KB >= r->mapped_kb;
	return IRDM_OK;
}

int irdm_rt_report_get(struct irdm_rt_report *r)
{
	int rc = IRDM_OK;

	memset(r, 0, sizeof(*r));
	r->policy = -1;
	r->cpu = -1;
	/* each part on its own: one that fails does not hide the others */
	if (read_kernel(r))
		rc = IRDM_EIO;
	if (read_sched(r))
		rc = IRDM_EIO;
	if (read_memory(r))
		rc = IRDM_EIO;
	return rc;
}

bool irdm_rt_report_realtime(const struct irdm_rt_report *r)
{
	return r->preempt_rt && (r->policy == SCHED_FIFO || r->policy == SCHED_RR) &&
	       r->priority > 0 && r->memory_locked;
}

/* ---- the line ---- */

struct line {
	char *buf;
	size_t len, used;
	bool cut;
};

static void put(struct line *l, const char *fmt, ...)
{
	va_list ap;
	int n;

	if (l->cut)
		return;
	va_start(ap, fmt);
	n = vsnprintf(l->buf + l->used, l->len - l->used, fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= l->len - l->used) {
		l->cut = true;
		return;
	}
	l->used += (size_t)n;
}

static void put_policy(struct line *l, int policy, int priority)
{
	static const struct {
		int policy;
		const char *name;
	} names[] = {
		{ SCHED_OTHER, "SCHED_OTHER" },
		{ SCHED_FIFO, "SCHED_FIFO" },
		{ SCHED_RR, "SCHED_RR" },
		{ SCHED_BATCH, "SCHED_BATCH" },
		{ SCHED_IDLE, "SCHED_IDLE" },
	};
	const char *name = NULL;

	if (policy < 0) {
		put(l, "policy unknown");
		return;
	}
	for (size_t i = 0; i < sizeof(names) / sizeof(names[0]); i++)
		if (names[i].policy == policy)
			name = names[i].name;
	if (name)
		put(l, "%s", name);
	else
		put(l, "policy %d", policy);
	if (policy == SCHED_FIFO || policy == SCHED_RR)
		put(l, " priority %d", priority);
}

/* "0-3,6" for CPUs 0 to 63, "+N above 63" for the others */
static void put_affinity(struct line *l, uint64_t mask, unsigned n_cpus)
{
	unsigned shown = 0;
	const char *sep = "";

	if (!n_cpus) {
		put(l, "unknown");
		return;
	}
	for (int c = 0; c < 64; c++) {
		int end = c;
		if (!(mask >> c & 1))
			continue;
		while (end + 1 < 64 && (mask >> (end + 1) & 1))
			end++;
		if (end > c)
			put(l, "%s%d-%d", sep, c, end);
		else
			put(l, "%s%d", sep, c);
		shown += (unsigned)(end - c + 1);
		sep = ",";
		c = end;
	}
	if (n_cpus > shown)
		put(l, "%s+%u above 63", sep, n_cpus - shown);
}

int irdm_rt_report_format(const struct irdm_rt_report *r, char *buf, size_t len)
{
	struct line l = { buf, len, 0, false };

	if (!buf || !len)
		return IRDM_EINVAL;
	buf[0] = '\0';
	put(&l, "real-time: %s (kernel %s, ", irdm_rt_report_realtime(r) ? "yes" : "NO",
	    r->preempt_rt ? "PREEMPT_RT" : "not PREEMPT_RT");
	put_policy(&l, r->policy, r->priority);
	if (r->memory_locked)
		put(&l, ", memory locked)");
	else
		put(&l, ", memory not locked: %lu of %lu kB)", r->locked_kb, r->mapped_kb);
	if (r->cpu >= 0)
		put(&l, "; CPU %d, affinity ", r->cpu);
	else
		put(&l, "; CPU unknown, affinity ");
	put_affinity(&l, r->cpu_mask, r->n_cpus);
	return l.cut ? IRDM_ENOMEM : IRDM_OK;
}

int irdm_rt_task_format(const struct irdm_rt_task *t, char *buf, size_t len)
{
	struct line l = { buf, len, 0, false };

	if (!buf || !len)
		return IRDM_EINVAL;
	buf[0] = '\0';
	put(&l, "thread %d '%s': ", (int)t->tid, t->name);
	put_policy(&l, t->policy, t->priority);
	put(&l, ", CPUs ");
	put_affinity(&l, t->cpu_mask, t->n_cpus);
	if (t->loop)
		put(&l, " (the loop)");
	if (t->intrudes)
		put(&l, " (may run on the loop's CPU)");
	return l.cut ? IRDM_ENOMEM : IRDM_OK;
}
