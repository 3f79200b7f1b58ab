/* SPDX-License-Identifier: MIT */
/*
 * The force loop's clock: real time on CLOCK_MONOTONIC, paced by absolute
 * sleeps (a period never drifts by the loop's own work), or virtual time,
 * where a period passes the moment the loop asks for the next one, so a
 * minute of simulated interaction runs in seconds and every run is the same.
 *
 * The clock is the only part of the loop that reads time; the controller's
 * tick is given what the clock measured (wake-up latency, compute time).
 * In virtual time both are reported as 0: a log written in virtual time is
 * bit-identical run to run.
 */
#ifndef IRDM_CLOCK_H
#define IRDM_CLOCK_H

#include <stdint.h>
#include <time.h>

enum irdm_clock_mode {
	IRDM_CLOCK_REAL = 0,
	IRDM_CLOCK_VIRTUAL = 1,
};

struct irdm_clock {
	enum irdm_clock_mode mode;
	uint32_t period_ns;
	uint64_t tick;        /* periods started so far */
	struct timespec next; /* real: start of the next period */
	struct timespec wake; /* real: when this period's wait returned */
};

/*
 * Start at the next period boundary from now.
 * Return: IRDM_OK; IRDM_EINVAL if the mode is unknown or period_us is 0 or
 * over 1 s.
 */
int irdm_clock_start(struct irdm_clock *c, enum irdm_clock_mode mode, uint32_t period_us);

/*
 * Wait for the start of the next period and return the wake-up latency in
 * ns (how late the wait returned after the period's start; 0 in virtual
 * time).  A period already over is not slept for: the loop runs late, and
 * the latency says by how much.
 */
int64_t irdm_clock_wait(struct irdm_clock *c);

/* ns since this period's wait returned (the compute time so far; 0 virtual). */
int64_t irdm_clock_elapsed_ns(const struct irdm_clock *c);

/* Time of this period's start since the clock started, s (tick x period). */
double irdm_clock_time_s(const struct irdm_clock *c);

#endif /* IRDM_CLOCK_H */
