/* SPDX-License-Identifier: MIT */
/*
 * Whole-controller tick benchmark: irdm_ctrl_tick() (encoders, device
 * model, limits, proxy on the deformed surface, engine, force to torque)
 * timed one tick at a time with CLOCK_MONOTONIC, median / p99 / max, on the
 * default scene (scenes/cuboid-top.scene) pinned to modal 300 + static
 * correction:
 *  - hover:      the tip 1 mm above the top face, moving (free ticks: the
 *                proxy's closest-point query every tick);
 *  - slide/1:    pressed 3 mm in and sliding 50 um per tick, so the
 *                contact site (triangle or barycentrics) changes every tick;
 *  - slide/10:   the same path, the tip moved every 10th tick only;
 *  - edge:       slide/1's stroke along the line of mesh edges nearest
 *                it (a row of the top face's grid): the contact point on
 *                an edge shared by two triangles.
 * The encoder counts are computed (inverse kinematics) outside the timed
 * region.  Prints figures; never fails on time.
 *
 * Beside each tick, timed the same way in the same loop, a spin: about
 * 6 us of arithmetic on registers.  Its tail is what the host adds to any
 * work of that length at that duty cycle (timer interrupts, a VM's exits,
 * preemption): the part of the ticks' p99 and p99.9 that no change to the
 * tick can remove (on this VM an interrupt costs 40-90 us).
 *
 * Run from the repository root; the image is reused from out/bench/ and
 * made there when missing, or given as the first argument (ticked at its
 * own dt: the controller's period and coupling follow it).  Instructions
 * per tick, independent of the host's load (bench_util.h):
 *   valgrind --tool=callgrind --collect-atstart=no \
 *     --toggle-collect=irdm_ctrl_tick build/bench/bench_ctrl
 * with IRDM_BENCH_TICKS=2000 and IRDM_BENCH_ONLY=hover,edge to shorten it.
 */
#define _GNU_SOURCE
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "irdm/controller.h"
#include "irdm/posix/rt.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "../support/bench_util.h"
#include "../support/device_ik.h"

#define N_TICKS 20000
#define FIFO_PRIO 80
#define BENCH_CPU 1
#define GAP_M 0.002 /* home tip above the top face */
#define SLIDE_M_PER_TICK 50e-6
#define SLIDE_HALF_M 0.025 /* back and forth +-2.5 cm about the centre */

static const double rot[9] = { 1, 0, 0, 0, 0, -1, 0, 1, 0 }; /* device -> object */

struct bench {
	struct irdm_session *s;
	struct irdm_ctrl_config cfg;
	struct irdm_ctrl ctrl;
	struct irdm_ctrl_input in;
	struct irdm_ctrl_output out;
	double cx, cy, top_z;
	double edge_y; /* y of the top face's grid row nearest cy */
};

enum kase { C_HOVER,
	    C_SLIDE1,
	    C_SLIDE10,
	    C_EDGE,
	    C_COUNT };

static const char *const kase_name[C_COUNT] = { "hover   ", "slide/1 ", "slide/10",
						"edge    " };
static long n_ticks;

static double *samples, *spins;
static long spin_n; /* spin() iterations for SPIN_US */
#define SPIN_US 6.0

static volatile double spin_sink;

/* About n dependent multiply-adds on registers (the sink keeps them). */
static void spin(long n)
{
	double y = spin_sink;

	for (long i = 0; i < n; i++)
		y = y * 0.999999 + 1e-9;
	spin_sink = y;
}

/* spin() iterations for about SPIN_US: the median of 201 timings. */
static void calibrate_spin(void)
{
	struct timespec t0, t1;
	double t[201];

	spin_n = 1000;
	for (int k = 0; k < 201; k++) {
		clock_gettime(CLOCK_MONOTONIC, &t0);
		spin(spin_n);
		clock_gettime(CLOCK_MONOTONIC, &t1);
		t[k] = bench_elapsed_ns(&t0, &t1) * 1e-3;
	}
	for (int i = 1; i < 201; i++) /* insertion sort: small */
		for (int j = i; j > 0 && t[j - 1] > t[j]; j--) {
			double x = t[j];
			t[j] = t[j - 1];
			t[j - 1] = x;
		}
	spin_n = (long)(spin_n * SPIN_US / t[100]);
}

static double time_spin(void)
{
	struct timespec t0, t1;

	clock_gettime(CLOCK_MONOTONIC, &t0);
	spin(spin_n);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	return bench_elapsed_ns(&t0, &t1) * 1e-3;
}

/* Counts that put the tip at the object-frame point p: R^T (p - t). */
static int put(struct bench *b, const double p[3])
{
	double v[3], d[3], q[3];

	for (int a = 0; a < 3; a++)
		v[a] = p[a] - b->cfg.obj_offset_m[a];
	for (int a = 0; a < 3; a++)
		d[a] = rot[a] * v[0] + rot[3 + a] * v[1] + rot[6 + a] * v[2];
	dik_angles(&b->cfg.device[0].dev, d, q);
	return irdm_device_counts_from_angles(&b->cfg.device[0].dev, q, b->in.counts[0]);
}

static int tick(struct bench *b, uint32_t cmd)
{
	b->in.cmd = cmd;
	return irdm_ctrl_tick(&b->ctrl, &b->in, &b->out);
}

static void top_of(struct bench *b)
{
	const struct irdm_image *img = b->s->img;
	double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY }, best = INFINITY;

	b->top_z = -INFINITY;
	for (uint32_t k = 0; k < img->meta->n_nodes; k++) {
		for (int a = 0; a < 2; a++) {
			lo[a] = fmin(lo[a], img->nodes[k].pos_m[a]);
			hi[a] = fmax(hi[a], img->nodes[k].pos_m[a]);
		}
		b->top_z = fmax(b->top_z, img->nodes[k].pos_m[2]);
	}
	b->cx = 0.5 * (lo[0] + hi[0]);
	b->cy = 0.5 * (lo[1] + hi[1]);
	for (uint32_t k = 0; k < img->meta->n_nodes; k++) {
		const float *x = img->nodes[k].pos_m;

		if (x[2] == b->top_z && fabs(x[1] - b->cy) < best) {
			best = fabs(x[1] - b->cy);
			b->edge_y = x[1];
		}
	}
}

/*
 * The session on the image at path, its controller ticking at the image's
 * dt (an image at 2 ms is timed at 500 Hz, as a board for it would run):
 * opened at the default period, and again at the image's if they differ.
 */
static int open_session(struct bench *b, const char *path)
{
	struct irdm_session_config sc = { .deform = false };
	const struct irdm_ctrl_device_config *d = &b->cfg.device[0];
	char err[512];
	double dt;

	sc.engine = b->cfg.engine;
	if (irdm_session_open(&b->s, path, &sc, err, sizeof(err))) {
		printf("ctrl  %s: %s\n", path, err);
		return -1;
	}
	dt = b->s->img->meta->dt_s;
	if (fabs(dt - b->cfg.period_us * 1e-6) <= 1e-6)
		return 0;
	irdm_session_close(b->s);
	b->cfg.period_us = (uint32_t)lround(dt * 1e6);
	irdm_engine_config_haptic(&b->cfg.engine, b->cfg.period_us * 1e-6, d->dev.k_max_n_per_m,
				  d->dev.b_device_ns_per_m, b->cfg.limits.max_force_n);
	b->cfg.engine.max_force_n = IRDM_CTRL_ENGINE_FORCE_GUARD * b->cfg.limits.max_force_n;
	sc.engine = b->cfg.engine;
	if (irdm_session_open(&b->s, path, &sc, err, sizeof(err))) {
		printf("ctrl  %s: %s\n", path, err);
		return -1;
	}
	return 0;
}

static int open_bench(struct bench *b, const char *path)
{
	memset(b, 0, sizeof(*b));
	irdm_ctrl_config_default(&b->cfg);
	memcpy(b->cfg.obj_rot, rot, sizeof(rot));
	b->cfg.limits.max_tip_speed_m_per_s = 10; /* the steps of slide/10 */
	b->cfg.limits.watchdog_us = 1000000;      /* a preempted tick is a figure here */
	if (open_session(b, path))
		return -1;
	top_of(b);
	b->cfg.obj_offset_m[0] = b->cx;
	b->cfg.obj_offset_m[1] = b->cy;
	b->cfg.obj_offset_m[2] = b->top_z + GAP_M;
	if (irdm_ctrl_init(&b->ctrl, &b->cfg, b->s) ||
	    irdm_device_counts_from_angles(&b->cfg.device[0].dev, b->cfg.device[0].calib_q_rad,
					   b->in.counts[0]) ||
	    tick(b, IRDM_CTRL_CMD_CALIBRATE) || tick(b, IRDM_CTRL_CMD_ENABLE) ||
	    b->out.state != IRDM_SAFETY_ENABLED) {
		printf("ctrl  the controller did not enable\n");
		irdm_session_close(b->s);
		return -1;
	}
	return 0;
}

/* Where the tip is at step k of a case: a triangle wave in x. */
static void path(const struct bench *b, enum kase k, long step, double p[3])
{
	long held = k == C_SLIDE10 ? step / 10 * 10 : step;
	double s = fmod((double)held * SLIDE_M_PER_TICK, 4 * SLIDE_HALF_M);
	double x = s < 2 * SLIDE_HALF_M ? s - SLIDE_HALF_M : 3 * SLIDE_HALF_M - s;

	p[0] = b->cx + x;
	p[1] = k == C_EDGE ? b->edge_y : b->cy;
	p[2] = b->top_z + (k == C_HOVER ? 0.001 : -0.003);
}

/* Go from the home tip to the case's start, 20 um a tick (untimed). */
static int approach(struct bench *b, enum kase k)
{
	double home[3] = { b->cx, b->cy, b->top_z + GAP_M }, to[3], p[3];

	path(b, k, 0, to);
	for (int n = 1; n <= 400; n++) {
		for (int a = 0; a < 3; a++)
			p[a] = home[a] + (to[a] - home[a]) * n / 400;
		if (put(b, p) || tick(b, 0))
			return -1;
	}
	return 0;
}

static int run_case(const char *path_img, enum kase k)
{
	struct bench b;
	struct bench_stats st;
	struct timespec t0, t1;
	long contact = 0, tri_changes = 0;
	uint32_t last_tri = UINT32_MAX;
	double p[3];

	if (open_bench(&b, path_img))
		return -1;
	if (approach(&b, k))
		goto fault;
	bench_count_begin();
	for (long i = 0; i < n_ticks; i++) {
		path(&b, k, i, p);
		if (put(&b, p))
			goto fault;
		clock_gettime(CLOCK_MONOTONIC, &t0);
		int rc = tick(&b, 0);
		clock_gettime(CLOCK_MONOTONIC, &t1);
		if (rc)
			goto fault;
		samples[i] = bench_elapsed_ns(&t0, &t1) * 1e-3;
		spins[i] = time_spin();
		contact += b.out.dev[0].contact;
		if (b.out.dev[0].contact && b.out.dev[0].tri != last_tri) {
			tri_changes++;
			last_tri = b.out.dev[0].tri;
		}
	}
	bench_count_end(kase_name[k]);
	bench_stats(samples, n_ticks, &st);
	printf("ctrl  %s median %7.2f us  p99 %7.2f us  p99.9 %7.2f us  max %8.2f us  (in contact "
	       "%5.1f%%, triangle changes %ld)\n",
	       kase_name[k], st.median, st.p99, st.p999, st.max,
	       100.0 * (double)contact / n_ticks, tri_changes);
	bench_stats(spins, n_ticks, &st);
	printf("ctrl    spin   median %7.2f us  p99 %7.2f us  p99.9 %7.2f us  max %8.2f us  "
	       "(beside each tick: the host's share)\n",
	       st.median, st.p99, st.p999, st.max);
	irdm_session_close(b.s);
	return 0;
fault:
	printf("ctrl  %s the controller faulted (state %d, cause 0x%x)\n", kase_name[k], b.out.state,
	       b.out.cause);
	irdm_session_close(b.s);
	return -1;
}

static void realtime(void)
{
	struct irdm_rt_report rep;
	char line[256];
	int cpu = sysconf(_SC_NPROCESSORS_ONLN) > BENCH_CPU ? BENCH_CPU : 0, rc;

	rc = bench_counting() ? IRDM_EINVAL :
				irdm_rt_set_self(&(struct irdm_rt_sched){ SCHED_FIFO, FIFO_PRIO, cpu });
	if (rc)
		printf("ctrl  scheduling: SCHED_FIFO %d on CPU %d refused: %s\n", FIFO_PRIO, cpu,
		       irdm_strerror(rc));
	rc = irdm_rt_lock_memory();
	if (rc)
		printf("ctrl  memory: mlockall refused: %s: pages may fault\n", irdm_strerror(rc));
	irdm_rt_report_get(&rep);
	irdm_rt_report_format(&rep, line, sizeof(line));
	printf("ctrl  %s\n", line);
}

int main(int argc, char **argv)
{
	static const char *const pinned[] = { "representation", "modal:300", "static_correction", "yes",
					      "max_error", "none", NULL };
	const char *img = argc > 1 ? argv[1] : "out/bench/cuboid-top.img";
	int rc = 0;

	if (argc < 2 && bench_ensure_image("ctrl", img, "scenes/cuboid-top.scene", pinned))
		return 1;
	n_ticks = bench_ticks(N_TICKS);
	samples = malloc(n_ticks * sizeof(*samples));
	spins = malloc(n_ticks * sizeof(*spins));
	if (!samples || !spins)
		return 1;
	realtime();
	calibrate_spin();
	printf("ctrl  whole controller tick (irdm_ctrl_tick), %s, %ld ticks a case, one device, "
	       "slide %.0f um/tick over +-%.0f mm (timer overhead included)\n",
	       img, n_ticks, SLIDE_M_PER_TICK * 1e6, SLIDE_HALF_M * 1e3);
	for (int k = 0; k < C_COUNT; k++)
		if (bench_selected(kase_name[k]))
			rc |= run_case(img, (enum kase)k);
	free(samples);
	free(spins);
	return rc ? 1 : 0;
}
