/* SPDX-License-Identifier: MIT */
/*
 * What a run did, printed after the loop: the force, how the object rang
 * after release, the tick's timing, and how the run ended.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/posix/rt.h"
#include "irdm/safety.h"

#include "fw.h"

/*
 * The ringing after release: the dominant frequency of the watched node's
 * motion (mean removed) by a DFT scan from 0.5 to 200 Hz in 0.01 Hz steps:
 * the ringing is a few modes, and a scan finer than the 1/T bins of an FFT
 * places the peak without interpolation.  Only the first RINGING_WINDOW_S
 * after the release are kept and scanned: the ringing has decayed by then,
 * and the window is what bounds the trace's memory.
 */
#define RINGING_WINDOW_S 5.0

int fw_trace_alloc(struct fw_trace *t, uint64_t ticks, uint32_t period_us)
{
	memset(t, 0, sizeof(*t));
	t->cap = ticks;
	t->ring_max = (uint64_t)(RINGING_WINDOW_S / (period_us * 1e-6));
	if (t->ring_max < 1)
		t->ring_max = 1;
	t->ring_u_m = calloc(t->ring_max, sizeof(double));
	return t->ring_u_m ? 0 : -1;
}

void fw_trace_free(struct fw_trace *t)
{
	free(t->ring_u_m);
	t->ring_u_m = NULL;
}

void fw_trace_add(struct fw_trace *t, double force_n, double node_u_m, bool contact)
{
	if (t->n >= t->cap)
		return;
	if (force_n > t->peak_n) {
		t->peak_n = force_n;
		t->peak_at = t->n;
	}
	t->final_n = force_n;
	/* a new release starts the window again: the latest one is reported */
	if (t->n && t->contact && !contact) {
		t->released = true;
		t->release_at = t->n;
		t->ring_n = 0;
	}
	if (t->released && t->ring_n < t->ring_max)
		t->ring_u_m[t->ring_n++] = node_u_m;
	t->contact = contact;
	t->n++;
}

static double dominant_hz(const double *x, uint64_t n, double dt_s)
{
	double mean = 0, best = 0, best_hz = 0;

	for (uint64_t k = 0; k < n; k++)
		mean += x[k] / (double)n;
	for (double f = 0.5; f <= 200.0; f += 0.01) {
		double c = 0, s = 0, w = 2 * M_PI * f * dt_s;
		for (uint64_t k = 0; k < n; k++) {
			c += (x[k] - mean) * cos(w * (double)k);
			s += (x[k] - mean) * sin(w * (double)k);
		}
		if (c * c + s * s > best) {
			best = c * c + s * s;
			best_hz = f;
		}
	}
	return best_hz;
}

/* Locked and peak resident memory (kB, /proc/self/status), -1 if unknown. */
static void memory_kb(long *locked, long *peak)
{
	char line[256];
	FILE *f = fopen("/proc/self/status", "r");

	*locked = *peak = -1;
	while (f && fgets(line, sizeof(line), f)) {
		sscanf(line, "VmLck: %ld kB", locked);
		sscanf(line, "VmHWM: %ld kB", peak);
	}
	if (f)
		fclose(f);
}

static void print_hist(const char *what, const struct irdm_hist *h)
{
	struct irdm_hist_summary s;

	irdm_hist_summarize(h, &s);
	printf("%s: p50 %.2f us, p99 %.2f us, p99.9 %.2f us, max %.2f us (%llu ticks)\n", what,
	       s.p50_ns * 1e-3, s.p99_ns * 1e-3, s.p999_ns * 1e-3, s.max_ns * 1e-3,
	       (unsigned long long)s.n);
}

const char *fw_hal_why(const struct fw *fw)
{
	for (unsigned i = 0; i < IRDM_BOARD_DEVICES_MAX; i++)
		if (fw->hal_open[i] && fw->hal[i].why[0])
			return fw->hal[i].why;
	return "";
}

void fw_summary_print(const struct fw *fw)
{
	const struct fw_trace *t = &fw->trace;
	double dt_s = fw->board.period_us * 1e-6;
	struct irdm_hist_summary cs;
	long locked, peak;

	printf("ticks: %llu at %u us (%.3f s of %s time)\n", (unsigned long long)t->n,
	       fw->board.period_us, (double)t->n * dt_s,
	       fw->args.clock == IRDM_CLOCK_VIRTUAL ? "virtual" : "real");
	printf("force: peak %.4f N at %.3f s on the object, %.4f N at %.3f s rendered (clamped, "
	       "saturated), final %.4f N\n",
	       t->peak_n, (double)t->peak_at * dt_s,
	       fw->rendered_peak_n, (double)fw->rendered_peak_tick * dt_s, t->final_n);
	if (t->released && t->release_at + 100 <= t->n)
		printf("release ringing: %.2f Hz\n", dominant_hz(t->ring_u_m, t->ring_n, dt_s));
	else
		printf("release ringing: none (no release followed by 0.1 s of motion)\n");
	memory_kb(&locked, &peak);
	printf("memory: locked %ld kB, peak resident %ld kB (the summary's trace: %llu kB, "
	       "whatever the run's length)\n",
	       locked, peak,
	       (unsigned long long)((t->ring_max * sizeof(double) + 1023) / 1024));
	if (fw->args.clock == IRDM_CLOCK_REAL)
		print_hist("tick wake-up latency", &fw->latency);
	else
		printf("tick wake-up latency: none in virtual time\n");
	print_hist("tick compute time", &fw->compute_measured);
	irdm_hist_summarize(&fw->compute_measured, &cs);
	printf("overruns: %llu (longest run %llu)\n", (unsigned long long)cs.overruns,
	       (unsigned long long)cs.longest_run);
	fw_frame_summary(fw);
	if (fw->monitor.lost)
		printf("monitor: %llu ticks lost to this summary and the frames (its thread fell "
		       "4 s behind)\n",
		       (unsigned long long)fw->monitor.lost);
	if (fw->last_state == IRDM_SAFETY_FAULT)
		printf("state: fault: %s (torque off)%s%s\n", irdm_safety_fault_name(fw->last_cause),
		       fw_hal_why(fw)[0] ? ": " : "", fw_hal_why(fw));
	else
		printf("state: %s\n", irdm_safety_state_name(fw->last_state));
}
