/* SPDX-License-Identifier: MIT */
/*
 * Telemetry (irdm/telemetry.h): the tick -> writer ring under two threads,
 * drop counting, histogram percentiles against exact order statistics of
 * the same samples (random and adversarial), the log file round trip bit
 * for bit (synchronous and through the writer thread), what a crash
 * leaves, the reader's refusals (truncated, wrong version, wrong sizes,
 * extra bytes), and `irdm log export` compared value by value with the
 * records written.  The tick side's objects are checked to need no stdio,
 * allocation or threads.
 *
 * Needs IRDM (the irdm binary, default build/irdm) and IRDM_BUILD (the
 * build directory, default build), as `make test` sets them.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <spawn.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/image.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "support/test_files.h"

extern char **environ;

/* ---- helpers ---- */

static char dir[256];

/* dir/name, in one of 8 rotating buffers */
static const char *in_dir(const char *name)
{
	static char buf[8][320];
	static int k;

	k = (k + 1) % 8;
	snprintf(buf[k], sizeof(buf[k]), "%s/%s", dir, name);
	return buf[k];
}

static bool exists(const char *path)
{
	struct stat st;

	return stat(path, &st) == 0;
}

/* How many temporaries beside name are there (NAME.irdm-tmp.XXXXXX)?  The
 * first one's path into first (if any). */
static size_t temporaries(const char *name, char *first, size_t len)
{
	char pattern[400];
	size_t n;
	glob_t g;

	snprintf(pattern, sizeof(pattern), "%s/%s%s*", dir, name, IRDM_OUTDIR_TMP);
	if (glob(pattern, 0, NULL, &g))
		return 0;
	n = g.gl_pathc;
	if (first && n)
		snprintf(first, len, "%s", g.gl_pathv[0]);
	globfree(&g);
	return n;
}

static uint64_t xorshift(uint64_t *s)
{
	*s ^= *s << 13;
	*s ^= *s >> 7;
	*s ^= *s << 17;
	return *s;
}

/* A finite double of any sign and a wide range of magnitudes. */
static double any_double(uint64_t *s)
{
	double m = (double)(xorshift(s) >> 11) / 9007199254740992.0; /* [0, 1) */
	int e = (int)(xorshift(s) % 81) - 40;

	return (xorshift(s) & 1 ? -1 : 1) * ldexp(m, e);
}

/* Record i, the same every time it is asked for (so a reader can check it). */
static void make_record(uint64_t i, struct irdm_tick_record *r)
{
	uint64_t s = 0x9e3779b97f4a7c15ull ^ (i * 0xbf58476d1ce4e5b9ull) ^ 1;

	memset(r, 0, sizeof(*r));
	r->tick = i;
	r->wake_latency_ns = (int32_t)(xorshift(&s) % 200000) - 1000;
	r->compute_ns = (uint32_t)xorshift(&s);
	r->fault_flags = (uint32_t)(xorshift(&s) & 0xfff);
	r->state = (uint8_t)(i % IRDM_TELEM_N_STATES);
	r->n_devices = 2;
	for (int d = 0; d < 2; d++) {
		struct irdm_tick_dev *v = &r->dev[d];
		double *vec[5] = { v->tip_pos_m, v->tip_vel_m_s, v->joint_angle_rad,
				   v->joint_torque_nm, v->force_n };

		for (int a = 0; a < 5; a++)
			for (int k = 0; k < 3; k++)
				vec[a][k] = any_double(&s);
		v->proxy = (uint8_t)((i + (uint64_t)d) % IRDM_TELEM_N_PROXY);
		v->contact_tri = (i + (uint64_t)d) % 7 == 0 ? IRDM_TELEM_NO_TRI : (uint32_t)(xorshift(&s) % 100000);
		v->site_tri = (i + (uint64_t)d) % 5 == 0 ? IRDM_TELEM_NO_TRI : (uint32_t)(xorshift(&s) % 100000);
		for (int k = 0; k < 3; k++) {
			v->site_bary[k] = any_double(&s);
			v->target_m[k] = any_double(&s);
		}
	}
	/* values a CSV round trip must carry too */
	if (i % 50 == 3) {
		r->dev[0].force_n[0] = -0.0;
		r->dev[0].force_n[1] = INFINITY;
		r->dev[1].tip_vel_m_s[2] = -INFINITY;
		r->dev[1].joint_torque_nm[0] = 4.9406564584124654e-324; /* smallest subnormal */
	}
}

static void *ring_mem(uint32_t capacity, struct irdm_telem_ring **ring)
{
	size_t size = irdm_telem_ring_mem_size(capacity);
	void *mem = malloc(size + 1);

	assert_non_null(mem);
	/* any alignment: start one byte in */
	assert_int_equal(irdm_telem_ring_init(ring, (char *)mem + 1, size, capacity), IRDM_OK);
	return mem;
}

static const struct irdm_log_info info2 = {
	.period_us = 1000,
	.n_devices = 2,
	.start_time_ns = 1234567890123456789LL,
	.board = "sim-phantom",
	.image = "out/cuboid-1khz.img",
};

/* Records 0..n-1 to path through the synchronous writer. */
static void write_log(const char *path, uint64_t n, uint64_t dropped)
{
	struct irdm_log_file *lf;
	struct irdm_tick_record r;
	char err[256];

	assert_int_equal(irdm_log_file_open(&lf, path, &info2, err, sizeof(err)), IRDM_OK);
	for (uint64_t i = 0; i < n; i++) {
		make_record(i, &r);
		assert_int_equal(irdm_log_file_append(lf, &r, 1, err, sizeof(err)), IRDM_OK);
	}
	assert_int_equal(irdm_log_file_close(lf, dropped, err, sizeof(err)), IRDM_OK);
}

/* Read path back and compare every record with make_record(first + k) bit for bit. */
static uint64_t read_log_check(const char *path, uint64_t first)
{
	struct irdm_log_reader *rd;
	struct irdm_tick_record got, want;
	char err[256];
	uint64_t n = 0;
	int rc;

	rc = irdm_log_open(&rd, path, err, sizeof(err));
	if (rc)
		fail_msg("irdm_log_open: %s", err);
	while ((rc = irdm_log_next(rd, &got, err, sizeof(err))) == 1) {
		make_record(first + n, &want);
		if (memcmp(&got, &want, sizeof(got)))
			fail_msg("record %llu differs from what was written", (unsigned long long)n);
		n++;
	}
	assert_int_equal(rc, 0);
	assert_int_equal(n, irdm_log_header(rd)->record_count);
	irdm_log_close(rd);
	return n;
}

/* ---- ring ---- */

#define SPSC_N 1000000u

struct spsc {
	struct irdm_telem_ring *ring;
	uint64_t full; /* pushes refused (the producer retried) */
};

static void *producer(void *arg)
{
	struct spsc *t = arg;
	struct irdm_tick_record r;

	memset(&r, 0, sizeof(r));
	for (uint64_t i = 0; i < SPSC_N; i++) {
		/* payload at both ends of the record, so a torn copy shows */
		r.tick = i;
		r.compute_ns = (uint32_t)(i * 2654435761u);
		r.dev[1].force_n[2] = (double)i * 0.5;
		r.dev[1].contact_tri = (uint32_t)~i;
		while (irdm_telem_ring_push(t->ring, &r) == IRDM_EBUSY) {
			t->full++;
			sched_yield();
		}
	}
	return NULL;
}

static void test_ring_spsc_two_threads(void **state)
{
	struct irdm_tick_record out[37]; /* an odd batch: pops cross the wrap at every offset */
	struct spsc t = { 0 };
	uint64_t next = 0;
	pthread_t tid;
	void *mem;

	(void)state;
	mem = ring_mem(256, &t.ring);
	assert_int_equal(pthread_create(&tid, NULL, producer, &t), 0);
	while (next < SPSC_N) {
		size_t n = irdm_telem_ring_pop(t.ring, out, 1 + next % 37);

		if (!n)
			sched_yield();
		for (size_t k = 0; k < n; k++, next++) {
			if (out[k].tick != next || out[k].compute_ns != (uint32_t)(next * 2654435761u) ||
			    out[k].dev[1].force_n[2] != (double)next * 0.5 ||
			    out[k].dev[1].contact_tri != (uint32_t)~next)
				fail_msg("record %llu: got tick %llu (lost, duplicated, reordered or torn)",
					 (unsigned long long)next, (unsigned long long)out[k].tick);
		}
	}
	assert_int_equal(pthread_join(tid, NULL), 0);
	assert_int_equal(irdm_telem_ring_pop(t.ring, out, 37), 0); /* nothing more: no duplicate */
	assert_int_equal(irdm_telem_ring_drops(t.ring), t.full);   /* every refusal counted */
	print_message("spsc: %u records in order, %llu pushes found the ring full\n", SPSC_N,
		      (unsigned long long)t.full);
	free(mem);
}

static void test_ring_drops_and_limits(void **state)
{
	struct irdm_telem_ring *ring;
	struct irdm_tick_record r, out[8];
	void *mem;

	(void)state;
	assert_int_equal(irdm_telem_ring_mem_size(3), 0);
	assert_int_equal(irdm_telem_ring_mem_size(1), 0);
	assert_int_equal(irdm_telem_ring_mem_size(IRDM_TELEM_RING_MAX * 2), 0);
	assert_true(irdm_telem_ring_mem_size(4) >= 4 * sizeof(struct irdm_tick_record));
	mem = malloc(irdm_telem_ring_mem_size(4));
	assert_non_null(mem);
	assert_int_equal(irdm_telem_ring_init(&ring, mem, irdm_telem_ring_mem_size(4) - 1, 4),
			 IRDM_ENOMEM);
	assert_null(ring);
	assert_int_equal(irdm_telem_ring_init(&ring, mem, irdm_telem_ring_mem_size(4), 6), IRDM_EINVAL);
	assert_int_equal(irdm_telem_ring_init(&ring, NULL, 1 << 20, 4), IRDM_EINVAL);
	assert_int_equal(irdm_telem_ring_init(&ring, mem, irdm_telem_ring_mem_size(4), 4), IRDM_OK);
	assert_int_equal(irdm_telem_ring_capacity(ring), 4);

	memset(&r, 0, sizeof(r));
	for (uint64_t i = 0; i < 10; i++) {
		r.tick = i;
		assert_int_equal(irdm_telem_ring_push(ring, &r), i < 4 ? IRDM_OK : IRDM_EBUSY);
	}
	assert_int_equal(irdm_telem_ring_drops(ring), 6);
	assert_int_equal(irdm_telem_ring_used(ring), 4);
	assert_int_equal(irdm_telem_ring_pop(ring, out, 2), 2);
	assert_int_equal(out[0].tick, 0);
	assert_int_equal(out[1].tick, 1);
	for (uint64_t i = 10; i < 13; i++) {
		r.tick = i;
		assert_int_equal(irdm_telem_ring_push(ring, &r), i < 12 ? IRDM_OK : IRDM_EBUSY);
	}
	assert_int_equal(irdm_telem_ring_drops(ring), 7);
	assert_int_equal(irdm_telem_ring_pop(ring, out, 8), 4); /* the kept ones, in order */
	assert_int_equal(out[0].tick, 2);
	assert_int_equal(out[1].tick, 3);
	assert_int_equal(out[2].tick, 10);
	assert_int_equal(out[3].tick, 11);
	assert_int_equal(irdm_telem_ring_used(ring), 0);
	assert_int_equal(irdm_telem_ring_pop(ring, out, 8), 0);
	free(mem);
}

/* ---- histograms ---- */

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;

	return (x > y) - (x < y);
}

/* r = 10^(1/50), computed apart from the code under test. */
static long double rel_width(void)
{
	return powl(10.0L, 1.0L / 50);
}

/*
 * The documented bound of a reported quantile against the exact one:
 * exact <= rep < r exact in [100 ns, 100 ms), exact <= rep < 100 ns below,
 * rep = max at or above 100 ms.  Returns rep / exact where it applies.
 */
static long double check_bound(int64_t exact, int64_t rep, int64_t max, const char *what)
{
	if (exact >= 100000000) {
		if (rep != max)
			fail_msg("%s: exact %lld >= 100 ms, reported %lld, max %lld", what,
				 (long long)exact, (long long)rep, (long long)max);
		return 1;
	}
	if (rep < exact || rep > max)
		fail_msg("%s: reported %lld below exact %lld or above max %lld", what, (long long)rep,
			 (long long)exact, (long long)max);
	if (exact < 100) {
		if (rep >= 100)
			fail_msg("%s: exact %lld < 100 ns, reported %lld", what, (long long)exact,
				 (long long)rep);
		return 1;
	}
	if (!((long double)rep < rel_width() * exact))
		fail_msg("%s: reported %lld >= r * exact %lld", what, (long long)rep, (long long)exact);
	return (long double)rep / exact;
}

static const uint32_t quantiles[] = {
	1,
	1000,
	100000,
	250000,
	500000,
	750000,
	900000,
	990000,
	999000,
	999900,
	999999,
	1000000,
};

/* Every quantile of h against the sorted samples v[0..n-1]; returns the worst ratio. */
static long double check_all_quantiles(const struct irdm_hist *h, int64_t *v, size_t n,
				       uint64_t *seed)
{
	long double worst = 1;
	char what[64];

	qsort(v, n, sizeof(*v), cmp_i64);
	assert_int_equal(h->n, n);
	assert_int_equal(h->min_ns, v[0]);
	assert_int_equal(h->max_ns, v[n - 1]);
	for (size_t q = 0; q < sizeof(quantiles) / sizeof(quantiles[0]) + 200; q++) {
		uint32_t pm = q < sizeof(quantiles) / sizeof(quantiles[0]) ? quantiles[q] : 1 + (uint32_t)(xorshift(seed) % 1000000);
		/* nearest rank, independently: k = ceil(p n) */
		size_t k = (size_t)ceil((double)pm * (double)n / 1e6);
		int64_t exact = v[(k < 1 ? 1 : k) - 1];
		long double ratio;

		snprintf(what, sizeof(what), "n %zu, p %u/1e6", n, pm);
		ratio = check_bound(exact, irdm_hist_quantile(h, pm), v[n - 1], what);
		if (ratio > worst)
			worst = ratio;
	}
	return worst;
}

/* The edges are what the header promises: every value of bin i in [100 r^i, 100 r^(i+1)). */
static void test_hist_edges(void **state)
{
	static struct irdm_hist h;

	(void)state;
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	assert_int_equal(h.edge_ns[0], IRDM_HIST_MIN_NS);
	assert_int_equal(h.edge_ns[IRDM_HIST_LOG_BINS], IRDM_HIST_MAX_NS);
	for (int i = 0; i < IRDM_HIST_LOG_BINS; i++) {
		long double lo = 100.0L * powl(10.0L, i / 50.0L);
		long double hi = 100.0L * powl(10.0L, (i + 1) / 50.0L);

		assert_true(h.edge_ns[i] < h.edge_ns[i + 1]); /* no empty bin */
		if (!((long double)h.edge_ns[i] >= lo * (1 - 1e-15L) &&
		      (long double)(h.edge_ns[i + 1] - 1) < hi))
			fail_msg("bin %d = [%u, %u) is not within [%.3Lf, %.3Lf)", i, h.edge_ns[i],
				 h.edge_ns[i + 1], lo, hi);
	}
	assert_true(fabsl(rel_width() - IRDM_HIST_REL_WIDTH) < 1e-15L);
	assert_int_equal(irdm_hist_init(&h, -1), IRDM_EINVAL);
	assert_int_equal(irdm_hist_init(NULL, 0), IRDM_EINVAL);
}

#define RANDOM_N 200000

static void test_hist_random_vs_exact(void **state)
{
	static struct irdm_hist h;
	static int64_t v[RANDOM_N];
	uint64_t seed = 42;
	long double worst;

	(void)state;
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	for (size_t i = 0; i < RANDOM_N; i++) {
		/* log-uniform over 20 ns .. 300 ms, with a few zeros and negatives */
		double u = (double)(xorshift(&seed) >> 11) / 9007199254740992.0;
		int64_t x = (int64_t)exp(log(20.0) + u * (log(3e8) - log(20.0)));

		if (i % 1000 == 0)
			x = -(int64_t)(xorshift(&seed) % 5000);
		if (i % 1000 == 1)
			x = 0;
		v[i] = x;
		assert_int_equal(irdm_hist_add(&h, x), 0);
	}
	worst = check_all_quantiles(&h, v, RANDOM_N, &seed);
	print_message("random: worst reported/exact %.5Lf (bound %.5f)\n", worst, IRDM_HIST_REL_WIDTH);
}

/* Clustered and edge-placed samples: where binning errs the most. */
static void test_hist_adversarial(void **state)
{
	static struct irdm_hist h;
	static int64_t v[4 * IRDM_HIST_LOG_BINS];
	uint64_t seed = 7;
	long double worst = 1, w;
	size_t n = 0;

	(void)state;
	/* 1: every sample at the bottom of its bin: the largest error there is */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	for (int i = 0; i < IRDM_HIST_LOG_BINS; i++) {
		v[n++] = h.edge_ns[i];
		irdm_hist_add(&h, h.edge_ns[i]);
	}
	w = check_all_quantiles(&h, v, n, &seed);
	worst = w > worst ? w : worst;
	/* the bound is nearly reached: the check above could see it exceeded */
	assert_true(worst > 1.04L);

	/* 2: every sample at the top of its bin (one below the next edge) */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	n = 0;
	for (int i = 1; i <= IRDM_HIST_LOG_BINS; i++) {
		v[n++] = h.edge_ns[i] - 1;
		irdm_hist_add(&h, h.edge_ns[i] - 1);
	}
	check_all_quantiles(&h, v, n, &seed);

	/* 3: one value repeated: every quantile is that value exactly (clamped to max) */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	for (n = 0; n < 1000; n++) {
		v[n] = 12345;
		irdm_hist_add(&h, 12345);
	}
	check_all_quantiles(&h, v, n, &seed);
	assert_int_equal(irdm_hist_quantile(&h, 500000), 12345);

	/* 4: two far clusters; p99.9 of 1000 is the 999th smallest exactly at the boundary */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	for (n = 0; n < 1000; n++) {
		v[n] = n < 999 ? 100 : 99999999;
		irdm_hist_add(&h, v[n]);
	}
	check_all_quantiles(&h, v, n, &seed);
	assert_true(irdm_hist_quantile(&h, 999000) < 105);
	assert_int_equal(irdm_hist_quantile(&h, 999001), 99999999);

	/* 5: one sample, below the range; then only samples past 100 ms */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	v[0] = -5;
	irdm_hist_add(&h, -5);
	check_all_quantiles(&h, v, 1, &seed);
	assert_int_equal(irdm_hist_quantile(&h, 500000), -5);
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	for (n = 0; n < 10; n++) {
		v[n] = 100000000 + (int64_t)n * 50000000;
		irdm_hist_add(&h, v[n]);
	}
	check_all_quantiles(&h, v, n, &seed);

	/* 6: an empty histogram reads 0 */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	assert_int_equal(irdm_hist_quantile(&h, 500000), 0);
	print_message("adversarial: worst reported/exact %.5Lf (bound %.5f)\n", worst,
		      IRDM_HIST_REL_WIDTH);
}

/* Counts past what p n fits in 64 bits: the rank must not overflow. */
static void test_hist_rank_without_overflow(void **state)
{
	static struct irdm_hist h;

	(void)state;
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	/* white box: 4e18 samples, half in the first bin of 1 us, half at 10 us */
	h.count[1 + 50] = 2000000000000000000ull;
	h.count[1 + 100] = 2000000000000000000ull;
	h.n = 4000000000000000000ull;
	h.min_ns = 1000;
	h.max_ns = 10000;
	assert_int_equal(irdm_hist_quantile(&h, 500000), h.edge_ns[51] - 1);
	assert_int_equal(irdm_hist_quantile(&h, 500001), 10000);
}

static void test_hist_overruns(void **state)
{
	static struct irdm_hist h;
	static const int64_t x[] = { 500, 1500, 1500, 800, 2000, 2000, 2000, 1000, 1001 };
	static const uint64_t run[] = { 0, 1, 2, 0, 1, 2, 3, 0, 1 };
	struct irdm_hist_summary s;

	(void)state;
	assert_int_equal(irdm_hist_init(&h, 1000), IRDM_OK); /* > 1000 ns overruns */
	for (size_t i = 0; i < sizeof(x) / sizeof(x[0]); i++)
		assert_int_equal(irdm_hist_add(&h, x[i]), run[i]);
	irdm_hist_summarize(&h, &s);
	assert_int_equal(s.n, 9);
	assert_int_equal(s.overruns, 6);
	assert_int_equal(s.longest_run, 3);
	assert_int_equal(s.max_ns, 2000);
	assert_int_equal(s.min_ns, 500);
	assert_int_equal(s.p50_ns, irdm_hist_quantile(&h, 500000));
	assert_int_equal(s.p999_ns, 2000);
	/* limit 0: nothing is an overrun */
	assert_int_equal(irdm_hist_init(&h, 0), IRDM_OK);
	assert_int_equal(irdm_hist_add(&h, 50000000), 0);
	irdm_hist_summarize(&h, &s);
	assert_int_equal(s.overruns, 0);
}

/* ---- the log file ---- */

static void test_log_round_trip(void **state)
{
	const char *path = in_dir("sync.log");
	struct irdm_log_reader *rd;
	char err[256];
	const struct irdm_log_header *h;

	(void)state;
	write_log(path, 1000, 17);
	assert_int_equal(temporaries("sync.log", NULL, 0), 0);
	assert_int_equal(read_log_check(path, 0), 1000);
	assert_int_equal(irdm_log_open(&rd, path, err, sizeof(err)), IRDM_OK);
	h = irdm_log_header(rd);
	assert_int_equal(h->version, IRDM_LOG_VERSION);
	assert_int_equal(h->period_us, 1000);
	assert_int_equal(h->n_devices, 2);
	assert_int_equal(h->start_time_ns, 1234567890123456789LL);
	assert_int_equal(h->dropped, 17);
	assert_string_equal(h->board, "sim-phantom");
	assert_string_equal(h->image, "out/cuboid-1khz.img");
	irdm_log_close(rd);
	/* the file is the header, four blocks of records with their ends, the
	 * trailer: nothing else */
	struct stat st;
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_size, IRDM_LOG_HEADER_SIZE + 1000 * IRDM_TICK_RECORD_SIZE +
					     4 * sizeof(struct irdm_log_block_end) +
					     sizeof(struct irdm_log_trailer));
	assert_int_equal(st.st_size, irdm_log_size(1000));
	/* bad arguments leave nothing on disk */
	struct irdm_log_file *lf;
	struct irdm_log_info bad = info2;
	bad.period_us = 0;
	assert_int_equal(irdm_log_file_open(&lf, in_dir("bad.log"), &bad, err, sizeof(err)), IRDM_EINVAL);
	bad = info2;
	bad.n_devices = 3;
	assert_int_equal(irdm_log_file_open(&lf, in_dir("bad.log"), &bad, err, sizeof(err)), IRDM_EINVAL);
	assert_int_equal(irdm_log_file_open(&lf, in_dir("no/such/dir.log"), &info2, err, sizeof(err)),
			 IRDM_EIO);
	assert_non_null(strstr(err, "no/such/dir.log"));
	assert_false(exists(in_dir("bad.log")) || temporaries("bad.log", NULL, 0));
}

#define THREAD_N 20000u

/* Threads of this process at nice 19 (field 19 of /proc/self/task/TID/stat). */
static int threads_at_nice_19(void)
{
	char line[512];
	int n = 0;
	FILE *p;

	/* by pid: in the shell, /proc/self would be the shell */
	snprintf(line, sizeof(line),
		 "for t in /proc/%d/task/*/stat; do sed 's/.*) //' $t | cut -d' ' -f17; done",
		 (int)getpid());
	p = popen(line, "r");
	assert_non_null(p);
	while (fgets(line, sizeof(line), p))
		n += atoi(line) == 19;
	pclose(p);
	return n;
}

static void test_log_writer_thread(void **state)
{
	const char *path = in_dir("thread.log");
	struct irdm_telem_ring *ring;
	struct irdm_log_writer *w;
	struct irdm_tick_record r;
	char err[256];
	int nice_19_before = threads_at_nice_19();
	void *mem;

	(void)state;
	mem = ring_mem(64, &ring);
	assert_int_equal(irdm_log_writer_start(&w, path, &info2, ring, NULL, err, sizeof(err)), IRDM_OK);
	for (uint64_t i = 0; i < THREAD_N; i++) {
		make_record(i, &r);
		while (irdm_telem_ring_push(ring, &r) == IRDM_EBUSY)
			sched_yield();
		if (i == THREAD_N / 2) {
			/* the writer runs at the lowest priority: nice 19 */
			assert_int_equal(threads_at_nice_19(), nice_19_before + 1);
			/* while it is written, only the temporary name exists */
			assert_false(exists(path));
			assert_int_equal(temporaries("thread.log", NULL, 0), 1);
		}
	}
	assert_int_equal(irdm_log_writer_stop(w, err, sizeof(err)), IRDM_OK);
	assert_int_equal(temporaries("thread.log", NULL, 0), 0);
	assert_int_equal(read_log_check(path, 0), THREAD_N);
	free(mem);
}

/* Drops are counted into the header: 20 pushed into 8 slots before the writer runs. */
static void test_log_writer_records_drops(void **state)
{
	const char *path = in_dir("drops.log");
	struct irdm_telem_ring *ring;
	struct irdm_log_writer *w;
	struct irdm_log_reader *rd;
	struct irdm_tick_record r;
	char err[256];
	void *mem;

	(void)state;
	mem = ring_mem(8, &ring);
	for (uint64_t i = 0; i < 20; i++) {
		make_record(i, &r);
		irdm_telem_ring_push(ring, &r);
	}
	assert_int_equal(irdm_log_writer_start(&w, path, &info2, ring, NULL, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_log_writer_stop(w, err, sizeof(err)), IRDM_OK);
	assert_int_equal(read_log_check(path, 0), 8);
	assert_int_equal(irdm_log_open(&rd, path, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_log_header(rd)->dropped, 12);
	irdm_log_close(rd);
	free(mem);
}

/* A writer that dies before closing leaves only its temporary, which the reader refuses. */
static void test_log_crash_leaves_no_final_file(void **state)
{
	const char *path = in_dir("crash.log");
	struct irdm_log_reader *rd;
	char err[256];
	int status;
	pid_t pid;

	(void)state;
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		struct irdm_log_file *lf;
		struct irdm_tick_record r;

		if (irdm_log_file_open(&lf, path, &info2, err, sizeof(err)))
			_exit(1);
		for (uint64_t i = 0; i < 100; i++) { /* 28 kB: part of it reaches the file */
			make_record(i, &r);
			irdm_log_file_append(lf, &r, 1, err, sizeof(err));
		}
		_exit(0); /* "crash": no close */
	}
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	char tmp[400];

	assert_false(exists(path));
	assert_int_equal(temporaries("crash.log", tmp, sizeof(tmp)), 1);
	assert_int_equal(irdm_log_open(&rd, tmp, err, sizeof(err)), IRDM_ETRUNC);
	assert_null(rd);
	assert_non_null(strstr(err, "never closed"));
	/* the next writer of the same log finds the dead one's temporary (no
	 * lock on it) and removes it; its own is the only one while it writes */
	{
		struct irdm_log_file *lf;

		assert_int_equal(irdm_log_file_open(&lf, path, &info2, err, sizeof(err)), IRDM_OK);
		assert_false(exists(tmp));
		assert_int_equal(temporaries("crash.log", NULL, 0), 1);
		assert_int_equal(irdm_log_file_close(lf, 0, err, sizeof(err)), IRDM_OK);
		assert_int_equal(temporaries("crash.log", NULL, 0), 0);
		assert_int_equal(read_log_check(path, 0), 0);
	}
}

/* Copy the first len bytes of src to dst, then patch `patch_len` bytes at `at` (if any). */
static void copy_patched(const char *src, const char *dst, long len, long at, const void *patch,
			 size_t patch_len)
{
	static char buf[IRDM_LOG_HEADER_SIZE + 700 * IRDM_TICK_RECORD_SIZE + 4096];
	FILE *f = fopen(src, "rb");
	size_t n;

	assert_non_null(f);
	n = fread(buf, 1, sizeof(buf), f);
	fclose(f);
	if (len >= 0 && (size_t)len < n)
		n = (size_t)len;
	if (patch)
		memcpy(buf + at, patch, patch_len);
	if (len > (long)n) {
		memset(buf + n, 0, (size_t)len - n);
		n = (size_t)len;
	}
	f = fopen(dst, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(buf, 1, n, f), n);
	fclose(f);
}

static void expect_refused(const char *path, int code, const char *needle)
{
	struct irdm_log_reader *rd;
	char err[256] = "";
	int rc = irdm_log_open(&rd, path, err, sizeof(err));

	if (rc != code || !strstr(err, needle) || !strstr(err, path))
		fail_msg("%s: expected %s with '%s', got %s: %s", path, irdm_errname(code), needle,
			 irdm_errname(rc), err);
	assert_null(rd);
}

/* Opens, then a record read fails: a block's checksum or its end. */
static void expect_read_refused(const char *path, int code, const char *needle)
{
	struct irdm_log_reader *rd;
	struct irdm_tick_record r;
	char err[256] = "";
	int rc = irdm_log_open(&rd, path, err, sizeof(err));
	uint64_t n = 0;

	if (rc)
		fail_msg("%s: open: %s", path, err);
	while ((rc = irdm_log_next(rd, &r, err, sizeof(err))) == 1)
		n++;
	irdm_log_close(rd);
	if (rc != code || !strstr(err, needle))
		fail_msg("%s: expected %s with '%s' after some records, got %s after %llu: %s",
			 path, irdm_errname(code), needle, irdm_errname(rc), (unsigned long long)n,
			 err);
	/* no record of the bad block was handed out */
	assert_int_equal(n % IRDM_LOG_BLOCK_RECORDS, 0);
}

/* Copy good to bad with len bytes of val at `at`, and the header's or the
 * trailer's checksum made right again: a forgery that passes the CRC. */
static void copy_forged(const char *good, const char *bad, long at, const void *val, size_t len,
			bool trailer)
{
	static char buf[IRDM_LOG_HEADER_SIZE + 700 * IRDM_TICK_RECORD_SIZE + 4096];
	FILE *f = fopen(good, "rb");
	size_t n;

	assert_non_null(f);
	n = fread(buf, 1, sizeof(buf), f);
	fclose(f);
	memcpy(buf + at, val, len);
	if (trailer) {
		struct irdm_log_trailer *t = (void *)(buf + n - sizeof(*t));
		t->crc32c = irdm_crc32c(t, offsetof(struct irdm_log_trailer, crc32c));
	} else {
		struct irdm_log_header *h = (void *)buf;
		h->header_crc32c = irdm_crc32c(h, offsetof(struct irdm_log_header, header_crc32c));
	}
	f = fopen(bad, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(buf, 1, n, f), n);
	fclose(f);
}

static void test_log_reader_refuses_bad_logs(void **state)
{
	const char *good = in_dir("many.log"), *bad = in_dir("bad.log");
	const long full = (long)irdm_log_size(600);
	const long block = IRDM_LOG_BLOCK_RECORDS * IRDM_TICK_RECORD_SIZE +
			   sizeof(struct irdm_log_block_end);
	const long trailer = full - (long)sizeof(struct irdm_log_trailer);
	const uint32_t v2 = 2, rs = 200, period = 999;
	const uint64_t count = 599;
	const char wrong_magic[8] = "IRDMIMG";
	const uint8_t flip = 0x10;
	uint8_t byte;

	(void)state;
	/* 600 records: blocks 0..255, 256..511 and 512..599 */
	write_log(good, 600, 0);
	copy_patched(good, bad, full, 0, NULL, 0);
	assert_int_equal(read_log_check(bad, 0), 600); /* the control: a copy reads */

	/* cut short: where it ends, named by block */
	copy_patched(good, bad, IRDM_LOG_HEADER_SIZE + block + 100, 0, NULL, 0);
	expect_refused(bad, IRDM_ETRUNC, "truncated: ends in block 1 of 3 (records 256..511;");
	copy_patched(good, bad, IRDM_LOG_HEADER_SIZE + 2 * block + 5 * IRDM_TICK_RECORD_SIZE, 0,
		     NULL, 0);
	expect_refused(bad, IRDM_ETRUNC, "truncated: ends in block 2 of 3 (records 512..599;");
	copy_patched(good, bad, full - 5, 0, NULL, 0);
	expect_refused(bad, IRDM_ETRUNC, "truncated: ends in the trailer");
	copy_patched(good, bad, 100, 0, NULL, 0);
	expect_refused(bad, IRDM_ETRUNC, "truncated: 100 bytes");
	copy_patched(good, bad, 0, 0, NULL, 0);
	expect_refused(bad, IRDM_EMAGIC, "too short");
	copy_patched(good, bad, full + 10, 0, NULL, 0);
	expect_refused(bad, IRDM_EFORMAT, "holds more (10 bytes after the trailer)");

	/* one bit flipped: in a record, a block end, the header, the trailer */
	byte = 0;
	copy_patched(good, bad, full, IRDM_LOG_HEADER_SIZE + block + 77 * IRDM_TICK_RECORD_SIZE + 40,
		     NULL, 0);
	{
		FILE *f = fopen(bad, "r+b");
		long at = IRDM_LOG_HEADER_SIZE + block + 77 * IRDM_TICK_RECORD_SIZE + 40;

		assert_non_null(f);
		assert_int_equal(fseek(f, at, SEEK_SET), 0);
		assert_int_equal(fread(&byte, 1, 1, f), 1);
		byte ^= flip;
		assert_int_equal(fseek(f, at, SEEK_SET), 0);
		assert_int_equal(fwrite(&byte, 1, 1, f), 1);
		fclose(f);
	}
	expect_read_refused(bad, IRDM_ECRC, "bad.log: block 1 (records 256..511): bad checksum");
	copy_patched(good, bad, full, IRDM_LOG_HEADER_SIZE + 2 * block - 12, &flip, 1);
	expect_read_refused(bad, IRDM_EFORMAT, "block 1 (records 256..511): its end is not");
	copy_patched(good, bad, full, offsetof(struct irdm_log_header, period_us), &period,
		     sizeof(period));
	expect_refused(bad, IRDM_ECRC, "header: bad checksum");
	copy_patched(good, bad, full, trailer + 12, &flip, 1);
	expect_refused(bad, IRDM_ECRC, "trailer: bad checksum");

	/* forged with the checksum made right: the fields are still checked */
	copy_forged(good, bad, offsetof(struct irdm_log_header, version), &v2, sizeof(v2), false);
	expect_refused(bad, IRDM_EVERSION, "log version 2, this build reads version 3");
	copy_forged(good, bad, offsetof(struct irdm_log_header, record_size), &rs, sizeof(rs), false);
	expect_refused(bad, IRDM_EFORMAT, "record size 200");
	copy_forged(good, bad, trailer + offsetof(struct irdm_log_trailer, record_count), &count,
		    sizeof(count), true);
	expect_refused(bad, IRDM_EFORMAT, "trailer: 599 records");
	copy_patched(good, bad, full, 0, wrong_magic, sizeof(wrong_magic));
	expect_refused(bad, IRDM_EMAGIC, "not an IRDM log");
	expect_refused(in_dir("missing.log"), IRDM_EIO, "cannot open");
}

/* ---- irdm log export ---- */

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

/* Run irdm with argv (after the program name, NULL-terminated); stderr into err_text. */
static int irdm_run(const char *const *args, char *err_text, size_t err_len)
{
	const char *argv[16] = { irdm_path() };
	char err_path[320];
	posix_spawn_file_actions_t fa;
	int status = 0;
	size_t n = 1;
	pid_t pid;
	FILE *f;

	for (; *args && n < 15; args++)
		argv[n++] = *args;
	argv[n] = NULL;
	snprintf(err_path, sizeof(err_path), "%s/stderr", dir);
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
	posix_spawn_file_actions_addopen(&fa, 2, err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	assert_int_equal(posix_spawn(&pid, argv[0], &fa, NULL, (char *const *)argv, environ), 0);
	posix_spawn_file_actions_destroy(&fa);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	f = fopen(err_path, "r");
	n = f ? fread(err_text, 1, err_len - 1, f) : 0;
	err_text[n] = 0;
	if (f)
		fclose(f);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* Next comma-separated field of *p (the line has no quotes). */
static const char *field(char **p)
{
	char *s = *p, *c = strchr(s, ',');

	if (c) {
		*c = 0;
		*p = c + 1;
	} else {
		s[strcspn(s, "\n")] = 0;
		*p = s + strlen(s);
	}
	return s;
}

static void expect_double(char **p, double want, uint64_t tick, const char *col)
{
	const char *s = field(p);
	char *end;
	double got = strtod(s, &end);

	if (*end || memcmp(&got, &want, sizeof(got)))
		fail_msg("tick %llu, %s: CSV '%s', record %.17g", (unsigned long long)tick, col, s, want);
}

static void expect_text(char **p, const char *want, uint64_t tick, const char *col)
{
	const char *s = field(p);

	if (strcmp(s, want))
		fail_msg("tick %llu, %s: CSV '%s', record '%s'", (unsigned long long)tick, col, s, want);
}

/* The faults column, rebuilt from the bits with the names the header documents. */
static void fault_names(uint32_t flags, char *buf, size_t len)
{
	static const char *const names[] = { "clamp", "workspace", "velocity", "watchdog", "overrun",
					     "encoder_nan", "encoder_range", "signal", "hal_read", "hal_write", "hal_fault", "engine" };

	buf[0] = 0;
	for (unsigned b = 0; b < 12; b++)
		if (flags & (1u << b))
			snprintf(buf + strlen(buf), len - strlen(buf), "%s%s", buf[0] ? "|" : "", names[b]);
}

static void check_csv_row(char *line, uint64_t i)
{
	static const char *const states[] = { "init", "ready", "enabled", "fault", "off" };
	static const char *const proxies[] = { "free", "touch", "slide", "release" };
	struct irdm_tick_record r;
	char want[256];
	char *p = line;

	make_record(i, &r);
	snprintf(want, sizeof(want), "%llu", (unsigned long long)r.tick);
	expect_text(&p, want, i, "tick");
	snprintf(want, sizeof(want), "%.3f", (double)r.tick * 1e-3); /* period 1 ms */
	assert_true(fabs(strtod(field(&p), NULL) - strtod(want, NULL)) < 1e-9);
	snprintf(want, sizeof(want), "%d", r.wake_latency_ns);
	expect_text(&p, want, i, "wake_latency_ns");
	snprintf(want, sizeof(want), "%u", r.compute_ns);
	expect_text(&p, want, i, "compute_ns");
	expect_text(&p, states[r.state], i, "state");
	snprintf(want, sizeof(want), "%u", r.fault_flags);
	expect_text(&p, want, i, "fault_flags");
	fault_names(r.fault_flags, want, sizeof(want));
	expect_text(&p, want, i, "faults");
	for (int d = 0; d < 2; d++) {
		const struct irdm_tick_dev *v = &r.dev[d];
		const double *vec[5] = { v->tip_pos_m, v->tip_vel_m_s, v->joint_angle_rad,
					 v->joint_torque_nm, v->force_n };

		for (int a = 0; a < 5; a++)
			for (int k = 0; k < 3; k++)
				expect_double(&p, vec[a][k], i, "device vector");
		expect_text(&p, proxies[v->proxy], i, "proxy");
		snprintf(want, sizeof(want), "%lld",
			 v->contact_tri == IRDM_TELEM_NO_TRI ? -1LL : (long long)v->contact_tri);
		expect_text(&p, want, i, "tri");
		snprintf(want, sizeof(want), "%lld",
			 v->site_tri == IRDM_TELEM_NO_TRI ? -1LL : (long long)v->site_tri);
		expect_text(&p, want, i, "site_tri");
		for (int k = 0; k < 3; k++)
			expect_double(&p, v->site_bary[k], i, "site barycentric");
		for (int k = 0; k < 3; k++)
			expect_double(&p, v->target_m[k], i, "target");
	}
	assert_int_equal(*p, 0); /* no column left over */
}

static void test_cli_export_matches_records(void **state)
{
	const char *log = in_dir("cli.log"), *csv = in_dir("cli.csv");
	const char *head = "tick,t_s,wake_latency_ns,compute_ns,state,fault_flags,faults,"
			   "d0_x_m,d0_y_m,d0_z_m,d0_vx_m_s,";
	char line[8192], err_text[2048];
	uint64_t rows = 0;
	FILE *f;

	(void)state;
	write_log(log, 120, 0);
	assert_int_equal(irdm_run((const char *[]){ "log", "export", log, "-o", csv, NULL },
				  err_text, sizeof(err_text)),
			 0);
	assert_int_equal(temporaries("cli.csv", NULL, 0), 0);
	f = fopen(csv, "r");
	assert_non_null(f);
	assert_non_null(fgets(line, sizeof(line), f));
	assert_true(!strncmp(line, head, strlen(head)));
	assert_non_null(strstr(line, ",d1_fz_n,d1_proxy,d1_tri,d1_site_tri,d1_b0,d1_b1,d1_b2,"
				     "d1_tx_m,d1_ty_m,d1_tz_m\n"));
	while (fgets(line, sizeof(line), f))
		check_csv_row(line, rows++);
	fclose(f);
	assert_int_equal(rows, 120);
}

static void test_cli_export_refuses_bad_logs(void **state)
{
	const char *good = in_dir("cli2.log"), *cut = in_dir("cut.log"), *csv = in_dir("out.csv");
	const uint32_t v9 = 9;
	char err_text[2048];
	int rc;

	(void)state;
	write_log(good, 10, 0);
	copy_patched(good, cut, IRDM_LOG_HEADER_SIZE + 7 * IRDM_TICK_RECORD_SIZE + 3, 0, NULL, 0);
	/* (cut in block 0) */
	rc = irdm_run((const char *[]){ "log", "export", cut, "-o", csv, NULL }, err_text,
		      sizeof(err_text));
	if (rc != 1 || strncmp(err_text, "irdm log export: ", 17) || !strstr(err_text, cut) ||
	    !strstr(err_text, "truncated") || !strstr(err_text, ": ETRUNC: ") || strchr(err_text, '\n') != err_text + strlen(err_text) - 1)
		fail_msg("exit %d, expected 1 and one line naming %s and 'truncated': %s", rc, cut,
			 err_text);
	assert_false(exists(csv) || temporaries("out.csv", NULL, 0));
	copy_patched(good, cut, -1, offsetof(struct irdm_log_header, version), &v9, sizeof(v9));
	rc = irdm_run((const char *[]){ "log", "export", cut, "-o", csv, NULL }, err_text,
		      sizeof(err_text));
	assert_int_equal(rc, 1);
	assert_non_null(strstr(err_text, "version 9"));
	assert_false(exists(csv) || temporaries("out.csv", NULL, 0));
	/* a block found bad half way: no CSV, and one that was there stays as it was */
	const uint8_t seven = 7;
	char old[64] = "";
	FILE *f = fopen(csv, "w");
	assert_non_null(f);
	fputs("earlier export\n", f);
	fclose(f);
	copy_patched(good, cut, -1, IRDM_LOG_HEADER_SIZE + 5 * IRDM_TICK_RECORD_SIZE + offsetof(struct irdm_tick_record, n_devices), &seven, 1);
	rc = irdm_run((const char *[]){ "log", "export", cut, "-o", csv, NULL }, err_text,
		      sizeof(err_text));
	assert_int_equal(rc, 1);
	assert_non_null(strstr(err_text, "block 0 (records 0..9): bad checksum"));
	assert_int_equal(temporaries("out.csv", NULL, 0), 0);
	f = fopen(csv, "r");
	assert_non_null(f);
	assert_non_null(fgets(old, sizeof(old), f));
	fclose(f);
	assert_string_equal(old, "earlier export\n");
	/* usage errors and --help */
	assert_int_equal(irdm_run((const char *[]){ "log", "export", good, NULL }, err_text,
				  sizeof(err_text)),
			 2);
	assert_int_equal(irdm_run((const char *[]){ "log", "export", "--help", NULL }, err_text,
				  sizeof(err_text)),
			 0);
	assert_int_equal(irdm_run((const char *[]){ "log", "--help", NULL }, err_text,
				  sizeof(err_text)),
			 0);
	assert_int_equal(irdm_run((const char *[]){ "log", "frobnicate", NULL }, err_text,
				  sizeof(err_text)),
			 2);
}

/* ---- the tick side stays free of stdio, allocation and threads ---- */

static const char *build_dir(void)
{
	const char *b = getenv("IRDM_BUILD");

	return b ? b : "build";
}

/* Undefined symbols of obj that contain any of the needles; fails if nm fails. */
static size_t count_undefined(const char *obj, const char *const *needles)
{
	char cmd[512], line[512];
	size_t hits = 0;
	FILE *p;

	snprintf(cmd, sizeof(cmd), "nm -u %s/obj/%s", build_dir(), obj);
	p = popen(cmd, "r");
	assert_non_null(p);
	while (fgets(line, sizeof(line), p)) {
		if (strstr(line, "__asan_") || strstr(line, "__ubsan_"))
			continue; /* a sanitizer build's own hooks */
		for (const char *const *n = needles; *n; n++)
			if (strstr(line, *n)) {
				print_message("%s needs %s", obj, line);
				hits++;
			}
	}
	assert_int_equal(pclose(p), 0);
	return hits;
}

static void test_tick_side_objects(void **state)
{
	static const char *const forbidden[] = { "pthread_", "sem_", "cblas_", "malloc", "calloc",
						 "free", "printf", "fwrite", "fopen", "fputs", "puts", "clock_", "nanosleep", NULL };

	(void)state;
	assert_int_equal(count_undefined("firmware/telemetry/telemetry_ring.o", forbidden), 0);
	assert_int_equal(count_undefined("firmware/telemetry/telemetry_hist.o", forbidden), 0);
	/* control: the writer does use them, so the check can see them */
	assert_true(count_undefined("platform/posix/telemetry/telemetry_writer.o", forbidden) >= 2);
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "telem");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ring_spsc_two_threads),
		cmocka_unit_test(test_ring_drops_and_limits),
		cmocka_unit_test(test_hist_edges),
		cmocka_unit_test(test_hist_random_vs_exact),
		cmocka_unit_test(test_hist_adversarial),
		cmocka_unit_test(test_hist_rank_without_overflow),
		cmocka_unit_test(test_hist_overruns),
		cmocka_unit_test(test_log_round_trip),
		cmocka_unit_test(test_log_writer_thread),
		cmocka_unit_test(test_log_writer_records_drops),
		cmocka_unit_test(test_log_crash_leaves_no_final_file),
		cmocka_unit_test(test_log_reader_refuses_bad_logs),
		cmocka_unit_test(test_cli_export_matches_records),
		cmocka_unit_test(test_cli_export_refuses_bad_logs),
		cmocka_unit_test(test_tick_side_objects),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
