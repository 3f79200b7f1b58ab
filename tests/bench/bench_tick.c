/* SPDX-License-Identifier: MIT */
/*
 * Force tick benchmark: irdm_engine_tick() timed one tick at a time with
 * CLOCK_MONOTONIC over N_TICKS ticks after a warm-up, median / p99 / max,
 * for no contact (the history alone), one contact point at a node, two at
 * nodes, and one on a triangle point; on the paper's cuboid (FIR T = 500
 * at 2 ms, modal 300 modes + static correction, modal with every mode) and
 * on the bunny.  The haptic configuration (virtual coupling, passivity
 * control) and grab contacts (never released, so every timed tick solves
 * its contacts).  Prints figures beside the targets and the paper's
 * Itanium2 times; never fails on time.
 *
 * Run from the repository root: images are reused from out/bench/ and made
 * there when missing, those of the selected cases only.  IRDM_BENCH_ONLY and IRDM_BENCH_TICKS select cases
 * and shorten them, for instructions per tick under callgrind
 * (bench_util.h; --toggle-collect=irdm_engine_tick), e.g.
 * IRDM_BENCH_ONLY=hybrid,fir-500 (2 ms).  Runs under SCHED_FIFO on CPU 1 with mlockall when it
 * may, and says so in the header when it may not.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include "irdm/engine.h"
#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/rt.h"
#include "irdm/session.h"
#include "../support/bench_util.h"
#include "../support/engine_fixture.h"

#define N_TICKS 20000
#define N_WARMUP 2000
#define PAUSE_EVERY 100 /* ticks; then sleep PAUSE_NS (untimed) */
#define PAUSE_NS 200000L
#define FIFO_PRIO 80

/* FIR history summed by the portable path (fir_sum.c) instead of the
 * AVX2 one (fir_sum_avx2.c) the engine picks on this processor */
static bool portable_sum;
#define BENCH_CPU 1

/* A PHANToM-Desktop-class device, as in the tests. */
#define DEVICE_K 1000.0
#define DEVICE_B 5.0

enum kase { K_FREE,
	    K_NODE,
	    K_NODES,
	    K_TRI,
	    K_COUNT };

static const char *const kase_name[K_COUNT] = { "free   ", "1 node ", "2 nodes", "1 tri  " };

/* p99 of the interesting cases, for the closing summary */
struct figures {
	double median, p99, max;
	bool ok;
};

static void pause_untimed(void)
{
	struct timespec d = { 0, PAUSE_NS };

	clock_nanosleep(CLOCK_MONOTONIC, 0, &d, NULL);
}

/* ---- contact sites ---- */

static bool is_col(const struct irdm_image *img, uint32_t row)
{
	for (uint32_t c = 0; c < img->meta->n_cols; c++)
		if (img->columns[c] == row)
			return true;
	return false;
}

/*
 * Where the contacts go: the column nearest the top centre of the
 * touchable region, its nearest other column, and the all-column triangle
 * whose centroid is nearest the first.
 */
struct sites {
	uint32_t row[2];
	uint32_t tri;
	bool have_tri;
};

static void pick_sites(const struct irdm_image *img, struct sites *s)
{
	double top[3] = { 0, 0, -INFINITY }, best = INFINITY;
	uint32_t nc = img->meta->n_cols;

	for (uint32_t c = 0; c < nc; c++) {
		const float *p = img->nodes[img->columns[c]].pos_m;
		top[0] += p[0] / nc;
		top[1] += p[1] / nc;
		top[2] = fmax(top[2], p[2]);
	}
	s->row[0] = efx_column_row_near(img, top);
	const float *p0 = img->nodes[s->row[0]].pos_m;
	s->row[1] = s->row[0];
	for (uint32_t c = 0; c < nc; c++) {
		uint32_t r = img->columns[c];
		const float *p = img->nodes[r].pos_m;
		double d = 0;
		for (int a = 0; a < 3; a++)
			d += ((double)p[a] - p0[a]) * ((double)p[a] - p0[a]);
		if (r != s->row[0] && d < best) {
			best = d;
			s->row[1] = r;
		}
	}
	best = INFINITY;
	s->have_tri = false;
	s->tri = 0;
	for (uint32_t t = 0; t < img->meta->n_tris; t++) {
		const uint32_t *v = &img->tris[3 * t];
		double d = 0;
		if (!is_col(img, v[0]) || !is_col(img, v[1]) || !is_col(img, v[2]))
			continue;
		for (int a = 0; a < 3; a++) {
			double cen = ((double)img->nodes[v[0]].pos_m[a] + img->nodes[v[1]].pos_m[a] +
				      img->nodes[v[2]].pos_m[a]) /
				     3;
			d += (cen - p0[a]) * (cen - p0[a]);
		}
		if (d < best) {
			best = d;
			s->tri = t;
			s->have_tri = true;
		}
	}
}

/* ---- one case ---- */

static double *samples;
static long n_ticks;

static struct figures bench_case(const char *scene, const char *repr, const struct irdm_image *img,
				 const struct sites *st, enum kase k)
{
	struct figures fig = { 0, 0, 0, false };
	struct irdm_session_config sc = { .deform = false };
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_contact_site site[2];
	struct irdm_session *ses;
	struct irdm_engine *e;
	struct bench_stats bs;
	unsigned n_contacts = k == K_FREE ? 0 : k == K_NODES ? 2 :
							       1;
	char err[512];
	int rc = 0;

	char name[64];

	snprintf(name, sizeof(name), "%s %s", repr, kase_name[k]);
	if (!bench_selected(name))
		return fig;
	if (k == K_TRI && !st->have_tri) {
		printf("tick  %-14s %-16s %s  skipped: no triangle with all vertices touchable\n",
		       scene, repr, kase_name[k]);
		return fig;
	}
	irdm_engine_config_haptic(&sc.engine, img->meta->dt_s, DEVICE_K, DEVICE_B, 0 /* no limit */);
	sc.engine.fir_portable_sum = portable_sum;
	if (irdm_session_open_image(&ses, img, &sc, err, sizeof(err))) {
		printf("tick  %-14s %-16s %s  engine init failed: %s\n", scene, repr, kase_name[k],
		       err);
		return fig;
	}
	e = ses->eng;
	memset(cmd, 0, sizeof(cmd));
	for (unsigned i = 0; i < n_contacts; i++) {
		if (k == K_TRI) {
			const double bary[3] = { 0.5, 0.3, 0.2 };
			rc = irdm_engine_site_point(e, st->tri, bary, &site[i]);
		} else {
			rc = irdm_engine_site_node(e, st->row[i], &site[i]);
		}
		if (rc || (rc = irdm_engine_contact_begin(e, i, &site[i], IRDM_CONTACT_GRAB))) {
			printf("tick  %-14s %-16s %s  contact site failed (%d)\n", scene, repr,
			       kase_name[k], rc);
			irdm_session_close(ses);
			return fig;
		}
		cmd[i].mode = IRDM_CONTACT_GRAB;
	}
	/* a first contact needs a history: settle it in before timing */
	for (long t = -N_WARMUP; t < n_ticks && !rc; t++) {
		struct timespec t0, t1;
		double ph = 2 * M_PI * (double)(t + N_WARMUP) * img->meta->dt_s;
		for (unsigned i = 0; i < n_contacts; i++) {
			/* 2..4 mm into the surface, 1 mm stroke sideways */
			double depth = 0.003 + 0.001 * sin(2 * ph + i);
			for (int a = 0; a < 3; a++)
				cmd[i].target_m[a] = -depth * site[i].normal[a];
			cmd[i].target_m[0] += 0.001 * sin(ph);
		}
		if (t == 0)
			bench_count_begin();
		if (t >= 0 && t % PAUSE_EVERY == 0)
			pause_untimed();
		clock_gettime(CLOCK_MONOTONIC, &t0);
		rc = irdm_engine_tick(e, cmd);
		clock_gettime(CLOCK_MONOTONIC, &t1);
		if (t >= 0)
			samples[t] = bench_elapsed_ns(&t0, &t1) * 1e-3;
	}
	bench_count_end(name);
	if (rc) {
		printf("tick  %-14s %-16s %s  the engine faulted (%d): no figures\n", scene, repr,
		       kase_name[k], rc);
		irdm_session_close(ses);
		return fig;
	}
	bench_stats(samples, n_ticks, &bs);
	fig.median = bs.median;
	fig.p99 = bs.p99;
	fig.max = bs.max;
	fig.ok = true;
	const double *f = irdm_engine_contact(e, 0)->force_n;
	printf("tick  %-14s %-16s %s  median %6.2f us  p99 %6.2f us  max %7.2f us  (|F0| %.3f N, PC %llu%s%s)\n",
	       scene, repr, kase_name[k], fig.median, fig.p99, fig.max,
	       sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]),
	       (unsigned long long)irdm_engine_stats(e)->pc_activations,
	       img->meta->representation == IRDM_REPR_FIR ? ", FIR sum " : "",
	       img->meta->representation == IRDM_REPR_FIR ? irdm_engine_fir_sum_name(e) : "");
	fflush(stdout);
	irdm_session_close(ses);
	return fig;
}

static uint32_t all_modes; /* of the all-modes image */

/* One of repr's cases is selected (IRDM_BENCH_ONLY): its image is wanted,
 * and a missing one is worth minutes of precompute. */
static bool repr_selected(const char *repr)
{
	char name[64];

	for (int k = 0; k < K_COUNT; k++) {
		snprintf(name, sizeof(name), "%s %s", repr, kase_name[k]);
		if (bench_selected(name))
			return true;
	}
	return false;
}

/* The image at path if one of repr's cases is selected, made when missing. */
static bool want_image(const char *repr, const char *path, const char *scene_file,
		       const char *const *kv)
{
	return repr_selected(repr) && !bench_ensure_image("tick", path, scene_file, kv);
}

static void bench_image(const char *scene, const char *repr, const char *path,
			struct figures fig[K_COUNT])
{
	struct irdm_image img;
	struct sites st;
	char err[512];

	if (irdm_image_map(path, 0, &img, err, sizeof(err))) {
		printf("tick  %-14s %-16s skipped: %s\n", scene, repr, err);
		return;
	}
	pick_sites(&img, &st);
	all_modes = img.meta->n_modes;
	printf("tick  %-14s %-16s %u rows, %u columns, %u %s, dt %.0f ms%s%s\n", scene, repr,
	       img.meta->n_nodes, img.meta->n_cols,
	       img.meta->representation == IRDM_REPR_MODAL ? img.meta->n_modes : img.meta->fir_length,
	       img.meta->representation == IRDM_REPR_MODAL ? "modes" : "taps", img.meta->dt_s * 1e3,
	       img.corr_start ? ", static correction" : "",
	       img.locked ? ", locked" : "");
	for (int k = 0; k < K_COUNT; k++)
		fig[k] = bench_case(scene, repr, &img, &st, (enum kase)k);
	irdm_image_unmap(&img);
}

/* ---- real-time conditions ---- */

static void header(void)
{
	struct irdm_rt_report rep;
	struct utsname u;
	char line[256], model[128] = "unknown";
	long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
	int cpu = ncpu > BENCH_CPU ? BENCH_CPU : 0, rc;
	FILE *f;

	uname(&u);
	irdm_rt_report_get(&rep);
	f = fopen("/proc/cpuinfo", "r");
	while (f && fgets(line, sizeof(line), f))
		if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
			snprintf(model, sizeof(model), "%s", strchr(line, ':') + 2);
			model[strcspn(model, "\n")] = 0;
			break;
		}
	if (f)
		fclose(f);
	printf("tick  kernel %s %s (%s), %ld CPUs, %s\n", u.release, u.machine,
	       rep.preempt_rt ? "PREEMPT_RT" : "not PREEMPT_RT: latency figures are not real-time claims",
	       ncpu, model);

	rc = bench_counting() ? IRDM_EINVAL :
				irdm_rt_set_self(&(struct irdm_rt_sched){ SCHED_FIFO, FIFO_PRIO, cpu });
	if (rc)
		printf("tick  scheduling: SCHED_FIFO %d on CPU %d refused: %s\n", FIFO_PRIO, cpu,
		       irdm_strerror(rc));
	rc = irdm_rt_lock_memory();
	if (rc)
		printf("tick  memory: mlockall refused: %s: pages may fault\n", irdm_strerror(rc));
	/* what holds, read back */
	irdm_rt_report_get(&rep);
	irdm_rt_report_format(&rep, line, sizeof(line));
	printf("tick  %s%s\n", line, cpu == BENCH_CPU ? "" : " (only one CPU online)");
	f = fopen("/proc/sys/kernel/sched_rt_runtime_us", "r");
	if (f) {
		long rt = 0;
		if (fscanf(f, "%ld", &rt) == 1)
			printf("tick  RT throttling: sched_rt_runtime_us %ld%s\n", rt,
			       rt < 0 ? " (off)" : "");
		fclose(f);
	}

	/* the timer's own cost, which every figure below includes */
	struct timespec a, b;
	for (int i = 0; i < n_ticks; i++) {
		clock_gettime(CLOCK_MONOTONIC, &a);
		clock_gettime(CLOCK_MONOTONIC, &b);
		samples[i] = bench_elapsed_ns(&a, &b) * 1e-3;
	}
	struct bench_stats st;
	bench_stats(samples, n_ticks, &st);
	printf("tick  timer overhead (two clock_gettime): median %.3f us, max %.2f us\n",
	       st.median, st.max);
	printf("tick  %ld ticks timed one by one after %d warm-up ticks; %ld us pause every %d ticks (untimed); "
	       "haptic coupling %.0f N/m + passivity control, grab contacts\n",
	       n_ticks, N_WARMUP, PAUSE_NS / 1000, PAUSE_EVERY, DEVICE_K);
	fflush(stdout);
}

static void target(const char *what, double limit_us, const struct figures *f)
{
	if (!f->ok) {
		printf("tick  target %-46s <= %4.0f us: not measured\n", what, limit_us);
		return;
	}
	printf("tick  target %-46s <= %4.0f us: median %6.2f, p99 %6.2f, max %7.2f us -> %s\n", what,
	       limit_us, f->median, f->p99, f->max,
	       f->max <= limit_us ? "met (max)" : f->p99 <= limit_us ? "met at p99, not at max" :
								       "NOT met");
}

int main(void)
{
	static const char *const fir_kv[] = {
		"name",
		"cuboid-fir500-patch",
		"resolution",
		"11,11,22",
		"dt",
		"0.002",
		"representation",
		"fir:500",
		"fir_tail",
		"none",
		/* the paper's FIR, damped by the engine's r^s: not certified,
		 * but its tick costs what any FIR of 500 taps costs */
		"uncertified",
		"yes",
		"touch",
		"box:0.035,0.035,0.199,0.065,0.065,0.201",
		"display",
		"touch",
		NULL,
	};
	/* the hybrid: 300 modes and the other 9204's exact head of
	 * 128 samples (+ 128 tapered) at the same patch as the FIR, 1 ms */
	static const char *const hybrid_kv[] = {
		"name",
		"cuboid-hybrid128-patch",
		"resolution",
		"11,11,22",
		"representation",
		"modal:300",
		"exact_head",
		"128",
		"touch",
		"box:0.035,0.035,0.199,0.065,0.065,0.201",
		"display",
		"touch",
		NULL,
	};
	static const char *const all_kv[] = {
		"name",
		"cuboid-6x6x12-all",
		"resolution",
		"6,6,12",
		"representation",
		"modal:all",
		"modes",
		"all",
		"touch",
		"box:0.03,0.03,0.199,0.07,0.07,0.201",
		"display",
		"touch",
		NULL,
	};
	struct figures fir[K_COUNT] = { 0 }, fir_portable[K_COUNT] = { 0 }, m300[K_COUNT] = { 0 }, mall[K_COUNT] = { 0 };
	struct figures bunny[K_COUNT] = { 0 }, hybrid[K_COUNT] = { 0 };
	uint32_t mall_modes = 1;

	n_ticks = bench_ticks(N_TICKS);
	samples = malloc(n_ticks * sizeof(*samples));
	if (!samples)
		return 1;
	/*
	 * Images first (the precompute wants every core), then the real-time
	 * conditions.
	 *  - FIR T = 500 at the paper's 2 ms on the paper's mesh: the
	 *    precompute's stability check costs ~10 s of CPU per column at
	 *    T = 500 and the image 18 kB per (column, row) pair, so a 4 x 4
	 *    patch of the top face is touchable.  The tick reads only the
	 *    contact columns' blocks: its cost does not depend on how many
	 *    columns the image has.
	 *  - Modal with every mode: the paper's mesh has 9504; its stability
	 *    check is an eigenproblem of order 2 x 9504 per column (hours), so
	 *    the all-modes case uses the 6 x 6 x 12 cuboid (1764 modes), a 3 x 3
	 *    patch of the top touchable.  The modal tick is linear in the
	 *    number of modes.
	 */
	bool have_fir = (repr_selected("fir-500 portable") || repr_selected("fir-500 (2 ms)")) &&
			!bench_ensure_image("tick", "out/bench/cuboid-fir500-patch.img", NULL, fir_kv);
	bool have_m300 = want_image("modal-300+sc", "out/bench/cuboid-paper.img",
				    "scenes/cuboid-paper.scene", NULL);
	bool have_mall = want_image("modal-all", "out/bench/cuboid-6x6x12-all.img", NULL, all_kv);
	/* a dense eigensolve of the paper mesh's 9504 DoFs: minutes, once */
	bool have_hybrid = want_image("hybrid-300+128", "out/bench/cuboid-hybrid128-patch.img",
				      NULL, hybrid_kv);
	bool have_bunny = repr_selected("modal-300+sc") && bench_file_exists("out/bench/bunny.img");
	if (!have_bunny && repr_selected("modal-300+sc") && bench_file_exists("build/data/bunny.off"))
		have_bunny = !bench_ensure_image("tick", "out/bench/bunny.img", "scenes/bunny.scene",
						 NULL);

	header();
	if (have_fir) {
		bench_image("cuboid-paper", "fir-500 (2 ms)", "out/bench/cuboid-fir500-patch.img", fir);
		portable_sum = true;
		bench_image("cuboid-paper", "fir-500 portable", "out/bench/cuboid-fir500-patch.img",
			    fir_portable);
		portable_sum = false;
	}
	if (have_m300)
		bench_image("cuboid-paper", "modal-300+sc", "out/bench/cuboid-paper.img", m300);
	if (have_hybrid)
		bench_image("cuboid-paper", "hybrid-300+128", "out/bench/cuboid-hybrid128-patch.img",
			    hybrid);
	if (have_mall) {
		bench_image("cuboid-6x6x12", "modal-all", "out/bench/cuboid-6x6x12-all.img", mall);
		mall_modes = all_modes;
	}
	if (have_bunny)
		bench_image("bunny", "modal-300+sc", "out/bench/bunny.img", bunny);
	else if (repr_selected("modal-300+sc"))
		printf("tick  bunny skipped: neither out/bench/bunny.img nor build/data/bunny.off (make bench-precompute)\n");

	printf("tick  -- targets (figures include the timer overhead) --\n");
	target("FIR T=500, one point (node)", 10, &fir[K_NODE]);
	target("FIR T=500, one point (triangle)", 10, &fir[K_TRI]);
	target("FIR T=500, two points", 20, &fir[K_NODES]);
	target("FIR T=500, triangle, portable sum", 10, &fir_portable[K_TRI]);
	target("modal 300 + static corr, one point (node)", 5, &m300[K_NODE]);
	target("modal 300 + static corr, one point (triangle)", 5, &m300[K_TRI]);
	target("modal 300 + static corr, two points", 5, &m300[K_NODES]);
	target("hybrid 300 + head 128, one point (node)", 5, &hybrid[K_NODE]);
	target("hybrid 300 + head 128, one point (triangle)", 5, &hybrid[K_TRI]);
	if (mall[K_NODE].ok)
		printf("tick  modal all modes (6x6x12 cuboid, %u modes): one point median %.2f us, two points median %.2f us "
		       "(x %.1f for the paper mesh's 9504 modes if linear)\n",
		       mall_modes, mall[K_NODE].median, mall[K_NODES].median, 9504.0 / mall_modes);
	printf("tick  paper (Itanium2, FIR T=500): 78-105 us one point, 285-436 us two points\n");
	free(samples);
	return 0;
}
