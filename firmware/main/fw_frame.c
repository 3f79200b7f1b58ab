/* SPDX-License-Identifier: MIT */
/*
 * The deformation worker in irdm-fw, and --frame-at's picture of the
 * deformed surface.
 *
 * Real time: the worker's thread (irdm/deform_worker.h) runs one priority
 * level below the force loop at the board's deform_rate_hz; its frame
 * callback counts frames, measures its own CPU time and holds the frame
 * nearest --frame-at.  It is the only writer of that state until it is
 * joined, so nothing is locked.  Virtual time: no thread; the loop runs
 * irdm_deform_update() itself on the snapshot grid, so the frames (and the
 * VTK) are the same every run.
 *
 * Frame times are engine ticks: the snapshot after engine tick k is the
 * surface at t = k * period.  The engine publishes every every_ticks ticks
 * (at least the worker's rate) and --frame-at is rounded onto that grid, so
 * in virtual time the frame is exactly the one at the target tick.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "irdm/deform_worker.h"
#include "irdm/error.h"

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

/* --frame-at on the snapshot grid, never tick 0 (no snapshot there). */
static uint64_t target_tick(const struct fw *fw)
{
	double ticks = fw->args.frame_at_s * 1e6 / fw->board.period_us;
	uint64_t k = (uint64_t)llround(ticks / fw->frame.every_ticks) * fw->frame.every_ticks;

	return k ? k : fw->frame.every_ticks;
}

static int refuse(struct fw *fw, const char *why)
{
	snprintf(fw->err, sizeof(fw->err), "--frame-at %g: %s", fw->args.frame_at_s, why);
	return IRDM_EINVAL;
}

int fw_frame_check_args(struct fw *fw, uint64_t run_ticks)
{
	if (!fw->args.frame_out)
		return IRDM_OK;
	if (!fw->frame.every_ticks)
		return refuse(fw, "the board's deform_rate_hz is 0");
	fw->frame.target_tick = target_tick(fw);
	if (fw->frame.target_tick > run_ticks)
		return refuse(fw, "after the run's end");
	return IRDM_OK;
}

int fw_frame_open(struct fw *fw)
{
	struct fw_frame *fr = &fw->frame;
	size_t bytes;
	int rc;

	if (!fr->every_ticks)
		return IRDM_OK;
	rc = irdm_session_deform_open(fw->s, fw->err, sizeof(fw->err));
	if (rc)
		return rc;
	fr->rows = irdm_deform_rows(fw->s->worker);
	bytes = 3 * (size_t)fr->rows * sizeof(double);
	fr->pos_m = calloc(1, bytes);
	fr->scratch_m = calloc(1, bytes);
	if (!fr->pos_m || !fr->scratch_m) {
		snprintf(fw->err, sizeof(fw->err), "out of memory for the deformation frames");
		return IRDM_ENOMEM;
	}
	/* without --frame-at no frame is held: the frames are only counted */
	atomic_init(&fr->done, !fw->args.frame_out);
	return IRDM_OK;
}

/* Distance in ticks. */
static uint64_t tick_gap(uint64_t a, uint64_t b)
{
	return a > b ? a - b : b - a;
}

/* Hold the frame nearest the target: a frame at or past it ends the search. */
static void frame_offer(struct fw_frame *fr, const double *pos_m, uint64_t tick)
{
	fr->frames++;
	if (atomic_load_explicit(&fr->done, memory_order_relaxed))
		return;
	if (!fr->held || tick_gap(tick, fr->target_tick) < tick_gap(fr->held_tick, fr->target_tick)) {
		memcpy(fr->pos_m, pos_m, 3 * (size_t)fr->rows * sizeof(double));
		fr->held_tick = tick;
		fr->held = true;
	}
	if (tick >= fr->target_tick)
		atomic_store_explicit(&fr->done, true, memory_order_release);
}

static void cpu_add(struct fw_frame *fr, double ns)
{
	fr->cpu_sum_ns += ns;
	fr->cpu_n++;
	if (ns > fr->cpu_max_ns)
		fr->cpu_max_ns = ns;
}

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
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
	/* the first frame also paid for the thread's start: not counted */
	if (fr->cpu_started)
		cpu_add(fr, ts_ns(&now) - ts_ns(&fr->cpu_prev));
	fr->cpu_prev = now;
	fr->cpu_started = true;
}

int fw_frame_start(struct fw *fw)
{
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
}

static void contact_capture(struct fw_frame *fr, const struct irdm_ctrl_output *out)
{
	const struct irdm_ctrl_device_output *d = &out->dev[0];

	fr->contact_seen = true;
	fr->contact_on = d->contact;
	memcpy(fr->contact_m, d->proxy_m, sizeof(fr->contact_m));
	memcpy(fr->force_obj_n, d->force_obj_n, sizeof(fr->force_obj_n));
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
	if (!irdm_deform_update(fw->s->worker, fr->scratch_m, &tick))
		return;
	clock_gettime(CLOCK_MONOTONIC, &t1);
	cpu_add(fr, ts_ns(&t1) - ts_ns(&t0));
	frame_offer(fr, fr->scratch_m, tick);
}

void fw_frame_tick(struct fw *fw, const struct irdm_ctrl_output *out)
{
	struct fw_frame *fr = &fw->frame;
	uint64_t eng_tick;

	if (!fr->every_ticks)
		return;
	eng_tick = irdm_engine_stats(fw->s->eng)->ticks;
	if (fw->args.frame_out && eng_tick == fr->target_tick && !fr->contact_seen)
		contact_capture(fr, out);
	if (fw->args.clock != IRDM_CLOCK_REAL)
		virtual_update(fw, eng_tick);
}

void fw_frame_stop(struct fw *fw)
{
	irdm_deform_thread_stop(fw->frame.th);
	fw->frame.th = NULL;
}

void fw_frame_free(struct fw *fw)
{
	free(fw->frame.pos_m);
	free(fw->frame.scratch_m);
}

/* Three doubles a line, %.17g: the file holds every bit the run had. */
static void put_vec(FILE *f, const double *v)
{
	fprintf(f, "%.17g %.17g %.17g\n", v[0], v[1], v[2]);
}

static bool tri_shown(const uint32_t *t, uint32_t rows)
{
	return t[0] < rows && t[1] < rows && t[2] < rows;
}

static void write_polys(FILE *f, const struct irdm_image *img, uint32_t rows)
{
	uint32_t n = 0;

	for (uint32_t t = 0; t < img->meta->n_tris; t++)
		n += tri_shown(img->tris + 3 * (size_t)t, rows);
	fprintf(f, "POLYGONS %u %u\n", n, 4 * n);
	for (uint32_t t = 0; t < img->meta->n_tris; t++) {
		const uint32_t *v = img->tris + 3 * (size_t)t;
		if (tri_shown(v, rows))
			fprintf(f, "3 %u %u %u\n", v[0], v[1], v[2]);
	}
}

/*
 * Legacy VTK: the displayed nodes' world positions and the surface; the
 * contact as dataset field data; per point the displacement and the rest
 * position (what plot-surface.py colours by).
 */
static void write_vtk(FILE *f, const struct fw *fw)
{
	const struct fw_frame *fr = &fw->frame;
	const struct irdm_image *img = fw->s->img;
	double dt_s = fw->board.period_us * 1e-6;

	fprintf(f, "# vtk DataFile Version 3.0\n");
	fprintf(f, "irdm-fw frame: tick %llu (t %.6f s), contact at tick %llu\n",
		(unsigned long long)fr->held_tick, (double)fr->held_tick * dt_s,
		(unsigned long long)(fr->contact_seen ? fr->target_tick : 0));
	fprintf(f, "ASCII\nDATASET POLYDATA\nFIELD FieldData 4\n");
	fprintf(f, "time_s 1 1 double\n%.17g\n", (double)fr->held_tick * dt_s);
	fprintf(f, "contact 1 1 int\n%d\n", fr->contact_on ? 1 : 0);
	fprintf(f, "contact_point_m 3 1 double\n");
	put_vec(f, fr->contact_m);
	fprintf(f, "contact_force_n 3 1 double\n");
	put_vec(f, fr->force_obj_n);
	fprintf(f, "POINTS %u double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++)
		put_vec(f, fr->pos_m + 3 * (size_t)r);
	write_polys(f, img, fr->rows);
	fprintf(f, "POINT_DATA %u\nVECTORS displacement_m double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++) {
		const float *rest = img->nodes[r].pos_m;
		const double *p = fr->pos_m + 3 * (size_t)r;
		double u[3] = { p[0] - rest[0], p[1] - rest[1], p[2] - rest[2] };
		put_vec(f, u);
	}
	fprintf(f, "FIELD FieldData 1\nrest_m 3 %u double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++) {
		const float *rest = img->nodes[r].pos_m;
		put_vec(f, (const double[3]){ rest[0], rest[1], rest[2] });
	}
}

/* Written to FILE.tmp and renamed: a reader never sees half a frame. */
int fw_frame_write(struct fw *fw)
{
	const char *path = fw->args.frame_out;
	char tmp[4096];
	FILE *f;
	int bad;

	if (!path)
		return IRDM_OK;
	if (!fw->frame.held) {
		snprintf(fw->err, sizeof(fw->err),
			 "%s: no deformation frame was computed (the run stopped at tick %llu)",
			 path, (unsigned long long)fw->ticks);
		return IRDM_EIO;
	}
	if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= sizeof(tmp)) {
		snprintf(fw->err, sizeof(fw->err), "%s: path too long", path);
		return IRDM_EINVAL;
	}
	f = fopen(tmp, "w");
	if (!f)
		goto fail;
	write_vtk(f, fw);
	bad = ferror(f);
	if (fclose(f) || bad)
		goto fail_unlink;
	if (rename(tmp, path))
		goto fail_unlink;
	return IRDM_OK;
fail_unlink:
	bad = errno;
	remove(tmp);
	errno = bad;
fail:
	snprintf(fw->err, sizeof(fw->err), "%s: %s", path, strerror(errno));
	return IRDM_EIO;
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
	if (fw->args.frame_out)
		printf("frame: t %.3f s (tick %llu) -> %s\n",
		       (double)fr->held_tick * fw->board.period_us * 1e-6,
		       (unsigned long long)fr->held_tick, fw->args.frame_out);
}
