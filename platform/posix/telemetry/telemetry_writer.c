/* SPDX-License-Identifier: MIT */
/*
 * The log writer thread: the ring's consumer.  It runs at the lowest
 * priority of the controller's threads and does the file I/O the tick must
 * not: it pops what the tick pushed and appends it to the log in chunks
 * (one fwrite per chunk), and sleeps when there is nothing to write.  Kept
 * apart from the ring and the histograms so that the tick's objects need
 * neither stdio nor pthreads.
 */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "irdm/posix/rt.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"

struct irdm_log_writer {
	struct irdm_log_file *lf;
	struct irdm_telem_ring *ring;
	pthread_t tid;
	bool lowest_nice; /* default scheduling: nice 19 in the thread */
	atomic_bool stop; /* set by irdm_log_writer_stop() */
	atomic_ullong written;
	int error; /* first append error; read after the join */
	char err[256];
	struct irdm_tick_record chunk[IRDM_LOG_WRITER_CHUNK];
};

/* Pop one chunk and append it (or discard it after an error).  Returns how many were popped. */
static size_t drain_chunk(struct irdm_log_writer *w)
{
	size_t n = irdm_telem_ring_pop(w->ring, w->chunk, IRDM_LOG_WRITER_CHUNK);

	if (!n || w->error)
		return n;
	w->error = irdm_log_file_append(w->lf, w->chunk, n, w->err, sizeof(w->err));
	if (!w->error)
		atomic_fetch_add_explicit(&w->written, n, memory_order_relaxed);
	return n;
}

static void *writer_main(void *arg)
{
	struct irdm_log_writer *w = arg;
	const struct timespec idle = { 0, IRDM_LOG_WRITER_IDLE_US * 1000L };

	/* its name in /proc, for a program that lists its threads */
	prctl(PR_SET_NAME, "irdm-log", 0UL, 0UL, 0UL);
	/*
	 * Below a deformation thread that is itself SCHED_OTHER (at nice + 5)
	 * too: nice is per thread on Linux.  Best effort: raising nice needs
	 * no privilege, and the log is written either way.
	 */
	if (w->lowest_nice)
		setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), 19);
	for (;;) {
		/*
		 * Read the flag before draining: once it is seen set, the
		 * producer has stopped, so an empty ring after it means
		 * everything has been written.
		 */
		bool stopping = atomic_load_explicit(&w->stop, memory_order_acquire);

		if (drain_chunk(w))
			continue;
		if (stopping)
			break;
		nanosleep(&idle, NULL);
	}
	return NULL;
}

int irdm_log_writer_start(struct irdm_log_writer **out, const char *path,
			  const struct irdm_log_info *info, struct irdm_telem_ring *ring,
			  const struct irdm_rt_sched *sched, char *err, size_t errlen)
{
	const struct irdm_rt_sched lowest = { SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	struct irdm_log_writer *w;
	int ret;

	if (!out)
		return IRDM_EINVAL;
	*out = NULL;
	if (!ring) {
		if (err && errlen)
			snprintf(err, errlen, "log writer: no ring");
		return IRDM_EINVAL;
	}
	w = calloc(1, sizeof(*w));
	if (!w) {
		if (err && errlen)
			snprintf(err, errlen, "log writer: out of memory");
		return IRDM_ENOMEM;
	}
	w->ring = ring;
	w->lowest_nice = !sched;
	atomic_init(&w->stop, false);
	atomic_init(&w->written, 0);
	ret = irdm_log_file_open(&w->lf, path, info, err, errlen);
	if (ret)
		goto out_free;
	ret = irdm_rt_thread_start(&w->tid, sched ? sched : &lowest, writer_main, w);
	if (ret) {
		if (err && errlen)
			snprintf(err, errlen, "%s: cannot start the log writer thread: %s", path,
				 irdm_strerror(ret));
		goto out_abort;
	}
	*out = w;
	return IRDM_OK;
out_abort:
	irdm_log_file_abort(w->lf);
out_free:
	free(w);
	return ret;
}

int irdm_log_writer_stop(struct irdm_log_writer *w, char *err, size_t errlen)
{
	int ret;

	atomic_store_explicit(&w->stop, true, memory_order_release);
	pthread_join(w->tid, NULL);
	if (w->error) {
		ret = w->error;
		if (err && errlen)
			snprintf(err, errlen, "%s", w->err);
		irdm_log_file_abort(w->lf);
	} else {
		ret = irdm_log_file_close(w->lf, irdm_telem_ring_drops(w->ring), err, errlen);
	}
	free(w);
	return ret;
}

uint64_t irdm_log_writer_count(const struct irdm_log_writer *w)
{
	return atomic_load_explicit(&w->written, memory_order_relaxed);
}
