/* SPDX-License-Identifier: MIT */
/*
 * The run's monitor: what the summary (the force's peak, the ringing after
 * release) and the frames (the contact at each frame's tick, virtual
 * time's deformation update) take from each tick, off the force loop.
 *
 * The loop hands each tick's output to fw_monitor_tick(), which keeps one
 * sample of it (struct fw_sample): device 0's force, clamp, contact and
 * proxy, the engine's tick count, and the one thing that can only be read
 * in the tick, the displacement of the watched node (the vertex of the
 * latest contact triangle that carries most of the contact) along that
 * contact's normal.  Everything else is the consumer's:
 *  - real time: a thread at the lowest priority, off the force thread's
 *    CPU when it has one, drains the samples' ring (lock-free, one
 *    writer, one reader) every millisecond; it is joined before the
 *    frames are written and the summary printed.  A ring that is full
 *    loses the sample and counts it (the summary says so).
 *  - virtual time: the loop outruns any thread, so the sample is consumed
 *    at once, in the loop's thread, as the log is drained there (virtual
 *    time is not real time); the deformation update then runs on the
 *    snapshot grid before the next tick publishes over it.
 */
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <time.h>

#include "irdm/error.h"
#include "irdm/posix/rt.h"
#include "irdm/vec3.h"

#include "fw.h"

#define RING_SAMPLES 4096u /* 4 s at 1 kHz: the consumer may stall that long */

/* The node whose motion after release is the "ringing": the vertex of the
 * contact triangle that carries most of the contact. */
static void watch_contact_node(struct fw *fw, const struct irdm_ctrl_device_output *d)
{
	struct fw_monitor *m = &fw->monitor;
	unsigned best = 0;

	if (!d->contact || d->tri >= fw->s->img->meta->n_tris)
		return;
	for (unsigned k = 1; k < 3; k++)
		if (d->bary[k] > d->bary[best])
			best = k;
	m->watch_row = fw->s->img->tris[3 * (size_t)d->tri + best];
	memcpy(m->watch_normal, d->normal, sizeof(m->watch_normal));
	m->watching = true;
}

/* One sample, in tick order: the trace, the rendered peak, the frames. */
static void consume(struct fw *fw, const struct fw_sample *s)
{
	double f = irdm_v3_norm(s->force_obj_n);

	fw_trace_add(&fw->trace, f, s->node_u_m, s->contact);
	if (s->state == IRDM_SAFETY_ENABLED && f * s->scale > fw->rendered_peak_n) {
		fw->rendered_peak_n = f * s->scale;
		fw->rendered_peak_tick = fw->trace.n - 1;
	}
	fw_frame_sample(fw, s);
}

static void drain(struct fw *fw)
{
	struct fw_monitor *m = &fw->monitor;
	uint64_t t = atomic_load_explicit(&m->tail, memory_order_relaxed);
	uint64_t h = atomic_load_explicit(&m->head, memory_order_acquire);

	for (; t != h; t++)
		consume(fw, &m->ring[t & (RING_SAMPLES - 1)]);
	atomic_store_explicit(&m->tail, t, memory_order_release);
}

static void *consumer(void *arg)
{
	struct fw *fw = arg;
	const struct timespec nap = { 0, 1000000 };

	/* its name in /proc: what irdm-fw's start-up lines call it */
	prctl(PR_SET_NAME, "irdm-monitor", 0UL, 0UL, 0UL);
	for (;;) {
		/* read before the drain: what came before the stop is drained */
		bool stopping = atomic_load_explicit(&fw->monitor.stop, memory_order_acquire);

		drain(fw);
		if (stopping)
			return NULL;
		nanosleep(&nap, NULL);
	}
}

int fw_monitor_open(struct fw *fw)
{
	struct fw_monitor *m = &fw->monitor;

	atomic_init(&m->head, 0);
	atomic_init(&m->tail, 0);
	atomic_init(&m->stop, false);
	if (fw->args.clock != IRDM_CLOCK_REAL)
		return IRDM_OK;
	m->ring = calloc(RING_SAMPLES, sizeof(*m->ring));
	if (!m->ring) {
		snprintf(fw->err, sizeof(fw->err), "out of memory for the run's monitor");
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

int fw_monitor_start(struct fw *fw)
{
	struct irdm_rt_sched sched = { SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	int rc;

	if (!fw->monitor.ring)
		return IRDM_OK;
	if (fw->board.cpu >= 0)
		sched.cpu = IRDM_RT_CPU_EXCEPT(fw->board.cpu);
	rc = irdm_rt_thread_start(&fw->monitor.tid, &sched, consumer, fw);
	if (rc)
		snprintf(fw->err, sizeof(fw->err), "the run's monitor thread: %s", irdm_strerror(rc));
	fw->monitor.running = !rc;
	return rc;
}

void fw_monitor_tick(struct fw *fw, const struct irdm_ctrl_output *out)
{
	struct fw_monitor *m = &fw->monitor;
	const struct irdm_ctrl_device_output *d = &out->dev[0];
	double u[3] = { 0, 0, 0 };
	struct fw_sample s;
	uint64_t h, t;

	watch_contact_node(fw, d);
	if (m->watching)
		irdm_engine_node_disp(fw->s->eng, m->watch_row, u);
	s.eng_tick = irdm_engine_stats(fw->s->eng)->ticks;
	s.state = out->state;
	s.contact = d->contact;
	s.scale = d->scale;
	memcpy(s.force_obj_n, d->force_obj_n, sizeof(s.force_obj_n));
	memcpy(s.proxy_m, d->proxy_m, sizeof(s.proxy_m));
	s.node_u_m = irdm_v3_dot(u, m->watch_normal);
	if (!m->ring) {
		consume(fw, &s);
		return;
	}
	h = atomic_load_explicit(&m->head, memory_order_relaxed);
	t = atomic_load_explicit(&m->tail, memory_order_acquire);
	if (h - t >= RING_SAMPLES) {
		m->lost++;
		return;
	}
	m->ring[h & (RING_SAMPLES - 1)] = s;
	atomic_store_explicit(&m->head, h + 1, memory_order_release);
}

void fw_monitor_stop(struct fw *fw)
{
	struct fw_monitor *m = &fw->monitor;

	if (m->running) {
		atomic_store_explicit(&m->stop, true, memory_order_release);
		pthread_join(m->tid, NULL);
		m->running = false;
	}
	if (m->ring)
		drain(fw); /* a thread that never started: the loop's samples */
}

void fw_monitor_free(struct fw *fw)
{
	free(fw->monitor.ring);
	fw->monitor.ring = NULL;
}
