/* SPDX-License-Identifier: MIT */
/*
 * The deformation worker in irdm-fw, and the frames of the deformed surface
 * it keeps (--frame-at's one, --frames-every's series; fw_frame_vtk.c
 * writes them).
 *
 * Real time: the worker's thread (irdm/posix/deform_worker.h) runs one priority
 * level below the force loop at the board's deform_rate_hz; its frame
 * callback counts frames, measures its own CPU time and holds, for each
 * slot, the frame nearest the slot's time.  It is the only writer of that
 * state until it is joined, so nothing is locked.  Virtual time: no
 * thread; the run's monitor (fw_monitor.c) runs irdm_deform_update() in the
 * loop's thread on the snapshot grid, so the frames (and the VTK) are the
 * same every run.  The contact at a frame's tick comes from the monitor's
 * samples too (fw_frame_sample()).
 *
 * Frame times are engine ticks: the snapshot after engine tick k is the
 * surface at t = k * period.  The engine publishes every every_ticks ticks
 * (at least the worker's rate) and frame times are rounded onto that grid,
 * so in virtual time a frame is exactly the one at its target tick.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "irdm/build_config.h"
#include "irdm/posix/deform_worker.h"
#include "irdm/error.h"
#include "irdm/posix/session.h"

#include "fw.h"

/* OpenBLAS's own; not in every cblas.h. */
void openblas_set_num_threads(int n);

static double ts_ns(const struct timespec *t)
{
	return (double)t->tv_sec * 1e9 + (double)t->tv_nsec;
}

void fw_frame_config(struct fw *fw, struct irdm_session_config *sc)
{
	double tick_hz = 1e6 / fw->board.period_us;
	unsigned every;

	if (!(fw->board.deform_rate_hz > 0))
		return;
	/* floor: snapshots at least as often as the worker looks */
	every = (unsigned)floor(tick_hz / fw->board.deform_rate_hz);
	fw->frame.every_ticks = every ? every : 1;
	sc->deform = true;
	sc->engine.publish_every = fw->frame.every_ticks;
}

/* Time t_s on the snapshot grid, never tick 0 (no snapshot there). */
static uint64_t grid_tick(const struct fw *fw, double t_s)
{
	double ticks = t_s * 1e6 / fw->board.period_us;
	uint64_t k = (uint64_t)llround(ticks / fw->frame.every_ticks) * fw->frame.every_ticks;

	return k ? k : fw->frame.every_ticks;
}

static int refuse(struct fw *fw, const char *opt, double v, const char *why)
{
	snprintf(fw->err, sizeof(fw->err), "%s %g: %s", opt, v, why);
	return IRDM_EINVAL;
}

/* How many frames --frames-every asks of a run of run_ticks. */
static uint64_t series_frames(const struct fw *fw, uint64_t run_ticks)
{
	double n = floor(run_ticks * fw->board.period_us * 1e-6 / fw->args.frames_every_s + 1e-9);

	return n < 1e9 ? (uint64_t)n : UINT64_MAX;
}

int fw_frame_check_args(struct fw *fw, uint64_t run_ticks)
{
	struct fw_frame *fr = &fw->frame;
	uint64_t n = 0;

	if (!fw->args.frame_out && !fw->args.frames_out)
		return IRDM_OK;
	if (!fr->every_ticks)
		return refuse(fw, fw->args.frame_out ? "--frame-at" : "--frames-every",
			      fw->args.frame_out ? fw->args.frame_at_s : fw->args.frames_every_s,
			      "the board's deform_rate_hz is 0");
	if (fw->args.frame_out && grid_tick(fw, fw->args.frame_at_s) > run_ticks)
		return refuse(fw, "--frame-at", fw->args.frame_at_s, "after the run's end");
	if (fw->args.frames_out) {
		double period_s = fr->every_ticks * fw->board.period_us * 1e-6;

		/* two frames in one deformation period would be the same snapshot */
		if (fw->args.frames_every_s < period_s * (1 - 1e-9)) {
			snprintf(fw->err, sizeof(fw->err), "--frames-every %g: shorter than the "
							   "deformation period, %g s (the board's deform_rate_hz)",
				 fw->args.frames_every_s, period_s);
			return IRDM_EINVAL;
		}
		n = series_frames(fw, run_ticks);
		if (n == 0)
			return refuse(fw, "--frames-every", fw->args.frames_every_s,
				      "longer than the run");
		if (n > FW_FRAMES_MAX)
			return refuse(fw, "--frames-every", fw->args.frames_every_s,
				      "more than 1000 frames in this run");
	}
	fr->n_slots = (unsigned)n + (fw->args.frame_out != NULL);
	return IRDM_OK;
}

/* The slots' targets, in order: the series, and --frame-at's among them. */
static void place_targets(struct fw *fw)
{
	struct fw_frame *fr = &fw->frame;
	unsigned n_series = fr->n_slots - (fw->args.frame_out != NULL), k = 0;
	uint64_t single = fw->args.frame_out ? grid_tick(fw, fw->args.frame_at_s) : 0;

	fr->single_slot = fr->n_slots;
	for (unsigned i = 0; i < n_series; i++) {
		uint64_t t = grid_tick(fw, (i + 1) * fw->args.frames_every_s);

		if (fr->single_slot == fr->n_slots && fw->args.frame_out && single <= t) {
			fr->single_slot = k;
			fr->slot[k++].target_tick = single;
		}
		fr->slot[k++].target_tick = t;
	}
	if (fw->args.frame_out && fr->single_slot == fr->n_slots) {
		fr->single_slot = k;
		fr->slot[k].target_tick = single;
	}
}

int fw_frame_open(struct fw *fw)
{
	struct fw_frame *fr = &fw->frame;
	size_t bytes;
	int rc;

	if (!fr->every_ticks)
		return IRDM_OK;
#if IRDM_CONFIG_DEFORM
	rc = irdm_session_deform_open(fw->s, fw->err, sizeof(fw->err));
	if (rc)
		return rc;
	fr->rows = irdm_deform_rows(fw->s->worker);
#else
	(void)rc; /* the session refused the board before (session.c) */
	return IRDM_ENOTSUP;
#endif
	bytes = 3 * (size_t)fr->rows * sizeof(double);
	fr->scratch_m = calloc(1, bytes);
	fr->slot = calloc(fr->n_slots ? fr->n_slots : 1, sizeof(*fr->slot));
	if (!fr->scratch_m || !fr->slot)
		goto out_of_memory;
	for (unsigned k = 0; k < fr->n_slots; k++) {
		fr->slot[k].pos_m = calloc(1, bytes);
		if (!fr->slot[k].pos_m)
			goto out_of_memory;
	}
	/* without slots no frame is held: the frames are only counted */
	place_targets(fw);
	return IRDM_OK;
out_of_memory:
	snprintf(fw->err, sizeof(fw->err), "out of memory for %u deformation frames of %u nodes",
		 fr->n_slots, fr->rows);
	return IRDM_ENOMEM;
}

/* Distance in ticks. */
static uint64_t tick_gap(uint64_t a, uint64_t b)
{
	return a > b ? a - b : b - a;
}

/*
 * Each slot holds the frame nearest its target; a frame at or past the
 * target ends that slot's search, and the same frame is then offered to
 * the next slot (two targets may share a snapshot).
 */
static void frame_offer(struct fw_frame *fr, const double *pos_m, uint64_t tick)
{
	fr->frames++;
	while (fr->next < fr->n_slots) {
		struct fw_frame_slot *sl = &fr->slot[fr->next];

		if (!sl->held || tick_gap(tick, sl->target_tick) < tick_gap(sl->held_tick,
									    sl->target_tick)) {
			memcpy(sl->pos_m, pos_m, 3 * (size_t)fr->rows * sizeof(double));
			sl->held_tick = tick;
			sl->held = true;
		}
		if (tick < sl->target_tick)
			return;
		fr->next++;
	}
}

static void cpu_add(struct fw_frame *fr, double ns)
{
	fr->cpu_sum_ns += ns;
	fr->cpu_n++;
	if (ns > fr->cpu_max_ns)
		fr->cpu_max_ns = ns;
}

#if IRDM_CONFIG_DEFORM
/*
 * The worker thread's callback.  Its compute time is the thread's CPU time
 * since the previous frame: the update (and the empty polls between
 * snapshots), not the time it slept or was preempted.
 */
static void on_frame(void *ctx, const double *pos_m, uint64_t tick)
{
	struct fw_frame *fr = ctx;
	struct timespec now;

	frame_offer(fr, pos_m, tick);
	fw_view_offer(fr->view, pos_m, tick);
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
	/* the first frame also paid for the thread's start: not counted */
	if (fr->cpu_started)
		cpu_add(fr, ts_ns(&now) - ts_ns(&fr->cpu_prev));
	fr->cpu_prev = now;
	fr->cpu_started = true;
}
#endif

int fw_frame_start(struct fw *fw)
{
#if IRDM_CONFIG_DEFORM
	int rc;

	if (!fw->frame.every_ticks || fw->args.clock != IRDM_CLOCK_REAL) {
		/* the loop runs the update itself: one BLAS thread, as the
		 * worker's own thread would have */
		if (fw->frame.every_ticks)
			openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
		return IRDM_OK;
	}
	fw->err[0] = '\0';
	rc = irdm_deform_thread_start(&fw->frame.th, fw->s->worker, fw->board.deform_rate_hz,
				      on_frame, &fw->frame, fw->err, sizeof(fw->err));
	/* started at a lower priority than asked: run, and say so */
	if (!rc && fw->err[0] && !fw->args.quiet)
		fprintf(stderr, "irdm-fw: %s\n", fw->err);
	return rc;
#else
	(void)fw;
	return IRDM_OK;
#endif
}

static void contact_capture(struct fw_frame_slot *sl, const struct fw_sample *s)
{
	sl->contact_seen = true;
	sl->contact_on = s->contact;
	memcpy(sl->contact_m, s->proxy_m, sizeof(sl->contact_m));
	memcpy(sl->force_obj_n, s->force_obj_n, sizeof(sl->force_obj_n));
}

/* Virtual time: the update on the snapshot grid, timed outside the tick. */
static void virtual_update(struct fw *fw, uint64_t eng_tick)
{
	struct fw_frame *fr = &fw->frame;
	struct timespec t0, t1;
	uint64_t tick;

	if (eng_tick % fr->every_ticks || eng_tick == fr->last_update_tick)
		return;
	fr->last_update_tick = eng_tick;
	clock_gettime(CLOCK_MONOTONIC, &t0);
#if IRDM_CONFIG_DEFORM
	if (!irdm_deform_update(fw->s->worker, fr->scratch_m, &tick))
		return;
#else
	return;
#endif
	clock_gettime(CLOCK_MONOTONIC, &t1);
	cpu_add(fr, ts_ns(&t1) - ts_ns(&t0));
	frame_offer(fr, fr->scratch_m, tick);
	fw_view_offer(fr->view, fr->scratch_m, tick);
}

void fw_frame_sample(struct fw *fw, const struct fw_sample *s)
{
	struct fw_frame *fr = &fw->frame;

	if (!fr->every_ticks)
		return;
	while (fr->contact_next < fr->n_slots &&
	       fr->slot[fr->contact_next].target_tick <= s->eng_tick) {
		if (fr->slot[fr->contact_next].target_tick == s->eng_tick)
			contact_capture(&fr->slot[fr->contact_next], s);
		fr->contact_next++;
	}
	if (fw->args.clock != IRDM_CLOCK_REAL)
		virtual_update(fw, s->eng_tick);
}

void fw_frame_stop(struct fw *fw)
{
	struct fw_frame *fr = &fw->frame;

#if IRDM_CONFIG_DEFORM
	irdm_deform_thread_stop(fr->th);
#endif
	fr->th = NULL;
	/* joined: the slots are the loop's again */
	if (fr->slot && fr->single_slot < fr->n_slots) {
		fr->single_held = fr->slot[fr->single_slot].held;
		fr->single_held_tick = fr->slot[fr->single_slot].held_tick;
	}
}

void fw_frame_free(struct fw *fw)
{
	for (unsigned k = 0; fw->frame.slot && k < fw->frame.n_slots; k++)
		free(fw->frame.slot[k].pos_m);
	free(fw->frame.slot);
	free(fw->frame.scratch_m);
	irdm_outdir_abort(&fw->frames_dir);
}

void fw_frame_summary(const struct fw *fw)
{
	const struct fw_frame *fr = &fw->frame;

	if (!fr->every_ticks) {
		printf("deformation: off (board deform_rate_hz = 0)\n");
		return;
	}
	printf("deformation: %llu frames at %g Hz (%s), worker compute mean %.1f us, max %.1f us\n",
	       (unsigned long long)fr->frames, fw->board.deform_rate_hz,
	       fw->args.clock == IRDM_CLOCK_REAL ? "worker thread" : "in the loop",
	       fr->cpu_n ? fr->cpu_sum_ns / (double)fr->cpu_n * 1e-3 : 0.0, fr->cpu_max_ns * 1e-3);
	if (fw->args.frame_out && fr->single_held)
		printf("frame: t %.3f s (tick %llu) -> %s\n",
		       (double)fr->single_held_tick * fw->board.period_us * 1e-6,
		       (unsigned long long)fr->single_held_tick, fw->args.frame_out);
	if (fw->args.frames_out)
		printf("frames: %u every %g s -> %s/frames.vtk.series\n",
		       fr->n_slots - (fw->args.frame_out != NULL), fw->args.frames_every_s,
		       fw->args.frames_out);
}
