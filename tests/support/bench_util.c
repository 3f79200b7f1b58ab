/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#if defined(__has_include)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define HAVE_CALLGRIND 1
#endif
#endif

#include "irdm/posix/rt.h"

#include "bench_util.h"
#include "precompute/precompute.h"

double bench_elapsed_ns(const struct timespec *a, const struct timespec *b)
{
	return (double)irdm_rt_timespec_diff_ns(a, b);
}

double bench_now_us(void)
{
	static const struct timespec zero;
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return bench_elapsed_ns(&zero, &ts) * 1e-3;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return (x > y) - (x < y);
}

void bench_stats(double *t, size_t n, struct bench_stats *st)
{
	qsort(t, n, sizeof(*t), cmp_double);
	st->median = t[n / 2];
	st->p99 = t[n * 99 / 100];
	st->p999 = t[n * 999 / 1000];
	st->max = t[n - 1];
}

bool bench_file_exists(const char *path)
{
	struct stat st;

	return !stat(path, &st);
}

int bench_ensure_image(const char *tag, const char *path, const char *scene_file,
		       const char *const *kv)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { .out_path = path };
	struct irdm_precompute_report rep;
	char err[1024];
	struct timespec t0, t1;

	if (bench_file_exists(path))
		return 0;
	if ((mkdir("out", 0777) && errno != EEXIST) || (mkdir("out/bench", 0777) && errno != EEXIST)) {
		fprintf(stderr, "%s  cannot create out/bench: %s\n", tag, strerror(errno));
		return -1;
	}
	irdm_scene_defaults(&sc);
	sc.max_error = 0; /* benchmarks time the tick, not the accuracy */
	if (scene_file && irdm_scene_load(&sc, scene_file, err, sizeof(err)))
		goto fail;
	for (; kv && kv[0]; kv += 2)
		if (irdm_scene_set(&sc, kv[0], kv[1], "bench", err, sizeof(err)))
			goto fail;
	if (irdm_scene_check(&sc, err, sizeof(err)))
		goto fail;
	printf("%s  precomputing %s ...\n", tag, path);
	fflush(stdout);
	clock_gettime(CLOCK_MONOTONIC, &t0);
	if (irdm_precompute(&sc, &o, &rep, err, sizeof(err)))
		goto fail;
	clock_gettime(CLOCK_MONOTONIC, &t1);
	printf("%s  precomputed %s in %.0f s (%zu modes of %zu, %zu columns)\n", tag, path,
	       bench_elapsed_ns(&t0, &t1) * 1e-9, rep.modes, rep.modes_total, rep.cols);
	return 0;
fail:
	fprintf(stderr, "%s  %s: %s\n", tag, path, err);
	return -1;
}

long bench_ticks(long dflt)
{
	const char *s = getenv("IRDM_BENCH_TICKS");
	long n = s ? strtol(s, NULL, 10) : 0;

	return n > 0 ? n : dflt;
}

bool bench_selected(const char *name)
{
	const char *s = getenv("IRDM_BENCH_ONLY");
	char word[64];

	if (!s || !*s)
		return true;
	while (*s) {
		size_t n = strcspn(s, ",");

		if (n && n < sizeof(word)) {
			memcpy(word, s, n);
			word[n] = '\0';
			if (strstr(name, word))
				return true;
		}
		s += n + (s[n] == ',');
	}
	return false;
}

bool bench_counting(void)
{
#ifdef HAVE_CALLGRIND
	return RUNNING_ON_VALGRIND;
#else
	return false;
#endif
}

void bench_count_begin(void)
{
#ifdef HAVE_CALLGRIND
	CALLGRIND_ZERO_STATS;
#endif
}

void bench_count_end(const char *name)
{
#ifdef HAVE_CALLGRIND
	CALLGRIND_DUMP_STATS_AT(name);
#else
	(void)name;
#endif
}
