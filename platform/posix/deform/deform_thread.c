/* SPDX-License-Identifier: MIT */
/*
 * The deformation thread: irdm_deform_update() at its own rate, below the
 * caller's priority, so that the force tick never competes with it.
 */
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "irdm/posix/rt.h"

#include "worker_priv.h"

/* OpenBLAS's own; not in every cblas.h. */
void openblas_set_num_threads(int n);

#define DEFORM_NICE 5
#define STACK_PREFAULT (64 * 1024)

/* SCHED_OTHER: nice applies per thread on Linux (setpriority on the tid). */
static int lower_nice(void)
{
	pid_t tid = (pid_t)syscall(SYS_gettid);
	int nice;

	errno = 0;
	nice = getpriority(PRIO_PROCESS, (id_t)tid);
	if (nice == -1 && errno)
		return errno;
	nice += DEFORM_NICE;
	if (nice > 19)
		nice = 19;
	return setpriority(PRIO_PROCESS, (id_t)tid, nice) ? errno : 0;
}

static void *deform_thread(void *arg)
{
	struct irdm_deform_thread *th = arg;
	struct timespec next, now;
	int policy;
	struct sched_param sp;

	/* its name in /proc, for a program that lists its threads */
	prctl(PR_SET_NAME, "irdm-deform", 0UL, 0UL, 0UL);
	if (!pthread_getschedparam(pthread_self(), &policy, &sp) && policy == SCHED_OTHER)
		th->prio_errno = lower_nice();
	/* the stack the update will use, so it never faults in the loop; a
	 * thread stack far larger than this cannot refuse it */
	(void)irdm_rt_prefault_stack(STACK_PREFAULT);
	sem_post(&th->started);
	clock_gettime(CLOCK_MONOTONIC, &next);
	while (!atomic_load_explicit(&th->stop, memory_order_acquire)) {
		uint64_t tick;
		if (irdm_deform_update(th->w, th->w->frame_pos, &tick))
			th->frame(th->ctx, th->w->frame_pos, tick);
		irdm_rt_timespec_add(&next, &th->period);
		/* a display frame late is a frame lost: skip, never catch up */
		clock_gettime(CLOCK_MONOTONIC, &now);
		if (irdm_rt_timespec_cmp(&next, &now) < 0)
			next = now;
		irdm_rt_sleep_until(&next);
	}
	return NULL;
}

/*
 * Scheduling below the caller: SCHED_FIFO one level lower under a real-time
 * caller, else SCHED_OTHER (and nice + 5 in the thread).  Explicit in both
 * cases, so the thread never inherits the caller's real-time priority; and
 * off the caller's CPU when the caller is pinned to one (a force thread):
 * inherited, that pin would put the BLAS updates on the force loop's CPU,
 * in its caches.
 */
static int make_attr(pthread_attr_t *a, bool rt)
{
	struct irdm_rt_sched s = { SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	struct sched_param sp;
	int policy, cpu = irdm_rt_pinned_cpu();

	if (rt && !pthread_getschedparam(pthread_self(), &policy, &sp) &&
	    (policy == SCHED_FIFO || policy == SCHED_RR) &&
	    sp.sched_priority > sched_get_priority_min(SCHED_FIFO)) {
		s.policy = SCHED_FIFO;
		s.priority = sp.sched_priority - 1;
	}
	if (cpu >= 0)
		s.cpu = IRDM_RT_CPU_EXCEPT(cpu);
	return irdm_rt_thread_attr(a, &s);
}

/* Returns an errno value, as pthread_create(). */
static int spawn(struct irdm_deform_thread *th, bool rt)
{
	pthread_attr_t a;
	int rc;

	/* what make_attr() asks is valid: only memory can be short */
	if (make_attr(&a, rt))
		return ENOMEM;
	rc = pthread_create(&th->tid, &a, deform_thread, th);
	pthread_attr_destroy(&a);
	return rc;
}

static bool caller_is_rt(void)
{
	struct sched_param sp;
	int policy;

	return !pthread_getschedparam(pthread_self(), &policy, &sp) &&
	       (policy == SCHED_FIFO || policy == SCHED_RR);
}

int irdm_deform_thread_start(struct irdm_deform_thread **thp, struct irdm_deform_worker *w,
			     double rate_hz, void (*frame)(void *ctx, const double *pos_m, uint64_t tick),
			     void *ctx, char *err, size_t errlen)
{
	struct irdm_deform_thread *th = &w->th;
	double period;
	int rc;

	*thp = NULL;
	if (!frame || !(rate_hz > 0) || rate_hz > IRDM_DEFORM_MAX_RATE_HZ) {
		snprintf(err, errlen, "deform thread: rate %g Hz not in (0, %g]", rate_hz,
			 IRDM_DEFORM_MAX_RATE_HZ);
		return IRDM_EINVAL;
	}
	if (th->running) {
		snprintf(err, errlen, "deform thread: already running");
		return IRDM_EBUSY;
	}
	period = 1.0 / rate_hz;
	th->w = w;
	th->frame = frame;
	th->ctx = ctx;
	th->period.tv_sec = (time_t)period;
	th->period.tv_nsec = (long)((period - floor(period)) * 1e9);
	th->prio_errno = 0;
	atomic_store(&th->stop, false);
	if (sem_init(&th->started, 0, 0)) {
		snprintf(err, errlen, "deform thread: sem_init: %s", strerror(errno));
		return IRDM_ETHREAD;
	}
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
	if (err && errlen)
		err[0] = '\0';
	rc = spawn(th, true);
	if (rc && caller_is_rt()) {
		/* e.g. no RLIMIT_RTPRIO left: run, but say so */
		snprintf(err, errlen, "deform thread: cannot use SCHED_FIFO below the caller (%s); "
				      "running at SCHED_OTHER",
			 strerror(rc));
		rc = spawn(th, false);
	}
	if (rc) {
		snprintf(err, errlen, "deform thread: pthread_create: %s", strerror(rc));
		goto fail;
	}
	while (sem_wait(&th->started) && errno == EINTR)
		;
	if (th->prio_errno)
		snprintf(err, errlen, "deform thread: cannot lower its priority (nice +%d): %s",
			 DEFORM_NICE, strerror(th->prio_errno));
	th->running = true;
	*thp = th;
	return IRDM_OK;
fail:
	sem_destroy(&th->started);
	return IRDM_ETHREAD;
}

void irdm_deform_thread_stop(struct irdm_deform_thread *th)
{
	if (!th || !th->running)
		return;
	atomic_store_explicit(&th->stop, true, memory_order_release);
	pthread_join(th->tid, NULL);
	sem_destroy(&th->started);
	th->running = false;
}
