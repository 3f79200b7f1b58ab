/* SPDX-License-Identifier: MIT */
/*
 * What the benchmarks (tests/bench/) share: timing, order statistics of
 * the samples, and the paper-scale images they make in out/bench/ when
 * missing.
 */
#ifndef IRDM_TESTS_BENCH_UTIL_H
#define IRDM_TESTS_BENCH_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <time.h>

/* CLOCK_MONOTONIC now, in microseconds. */
double bench_now_us(void);

/* b - a in nanoseconds. */
double bench_elapsed_ns(const struct timespec *a, const struct timespec *b);

/* Median, 99th and 99.9th percentiles and maximum of n > 0 samples
 * (sorted in place). */
struct bench_stats {
	double median, p99, p999, max;
};
void bench_stats(double *samples, size_t n, struct bench_stats *st);

bool bench_file_exists(const char *path);

/*
 * The image at path (under out/bench/), precomputed when missing from a
 * scene file (NULL: the defaults) and the key/value pairs on top
 * (NULL-terminated, or NULL).  Progress and errors are printed with the
 * bench's tag ("tick", "deform").  Returns 0, or -1 with the reason printed.
 */
int bench_ensure_image(const char *tag, const char *path, const char *scene_file,
		       const char *const *kv);

/*
 * Selection and counting, for running a few cases under callgrind:
 * IRDM_BENCH_TICKS sets the number of timed ticks (default dflt);
 * IRDM_BENCH_ONLY, a comma-separated list of words, selects the cases
 * whose name contains one of them (unset: every case).  bench_count_begin()
 * and bench_count_end() bracket a case's timed loop: under callgrind
 * (valgrind --tool=callgrind --collect-atstart=no
 * --toggle-collect=irdm_ctrl_tick) each case is a dump of its own, named
 * after it, whose total is the instructions of its timed ticks; elsewhere
 * they do nothing.
 */
long bench_ticks(long dflt);
/* Under valgrind: time means nothing there, and a real-time priority
 * held that long would starve the CPU's other work. */
bool bench_counting(void);
bool bench_selected(const char *name);
void bench_count_begin(void);
void bench_count_end(const char *name);

#endif
