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
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "worker_priv.h"

/* OpenBLAS's own; not in every cblas.h. */
void openblas_set_num_threads(int n);

#define DEFORM_NICE 5
#define STACK_PREFAULT (64 * 1024)

static void timespec_add(struct timespec *t, const struct timespec *dt)
{
	t->tv_sec += dt->tv_sec;
	t->tv_nsec += dt->tv_nsec;
	if (t->tv_nsec >= 1000000000L) {
		t->tv_nsec -= 1000000000L;
		t->tv_sec++;
	}
}

static bool timespec_before(const struct timespec *a, const struct timespec *b)
{
	return a->tv_sec < b->tv_sec || (a->tv_sec == b->tv_sec && a->tv_nsec < b->tv_nsec);
}

/* Touch the stack the update will use, so it never faults in the loop. */
static void prefault_stack(void)
{
	volatile unsigned char buf[STACK_PREFAULT];

	for (size_t i = 0; i < sizeof(buf); i += 256)
		buf[i] = 0;
}

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

	if (!pthread_getschedparam(pthread_self(), &policy, &sp) && policy == SCHED_OTHER)
		th->prio_errno = lower_nice();
	prefault_stack();
	sem_post(&th->started);
	clock_gettime(CLOCK_MONOTONIC, &next);
	while (!atomic_load_explicit(&th->stop, memory_order_acquire)) {
		uint64_t tick;
		if (irdm_deform_update(th->w, th->w->frame_pos, &tick))
			th->frame(th->ctx, th->w->frame_pos, tick);
		timespec_add(&next, &th->period);
		/* a display frame late is a frame lost: skip, never catch up */
		clock_gettime(CLOCK_MONOTONIC, &now);
		if (timespec_before(&next, &now))
			next = now;
		while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR)
			;
	}
	return NULL;
}

/*
 * Scheduling below the caller: SCHED_FIFO one level lower under a real-time
 * caller, else SCHED_OTHER (and nice + 5 in the thread).  Explicit in both
 * cases, so the thread never inherits the caller's real-time priority.
 */
static int make_attr(pthread_attr_t *a, bool rt)
{
	struct sched_param sp = { 0 };
	int policy, rc;

	rc = pthread_attr_init(a);
	if (rc)
		return rc;
	rc = pthread_attr_setinheritsched(a, PTHREAD_EXPLICIT_SCHED);
	if (!rc && rt && !pthread_getschedparam(pthread_self(), &policy, &sp) &&
	    (policy == SCHED_FIFO || policy == SCHED_RR) &&
	    sp.sched_priority > sched_get_priority_min(SCHED_FIFO)) {
		sp.sched_priority--;
		rc = pthread_attr_setschedpolicy(a, SCHED_FIFO);
		if (!rc)
			rc = pthread_attr_setschedparam(a, &sp);
		return rc;
	}
	sp.sched_priority = 0;
	if (!rc)
		rc = pthread_attr_setschedpolicy(a, SCHED_OTHER);
	if (!rc)
		rc = pthread_attr_setschedparam(a, &sp);
	return rc;
}

static int spawn(struct irdm_deform_thread *th, bool rt)
{
	pthread_attr_t a;
	int rc = make_attr(&a, rt);

	if (!rc)
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
			     double rate_hz, void (*frame)(void *ctx, const double *pos_m,
							   uint64_t tick),
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
			 "running at SCHED_OTHER", strerror(rc));
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
