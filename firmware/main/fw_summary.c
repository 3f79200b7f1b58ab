/* SPDX-License-Identifier: MIT */
/*
 * What a run did, printed after the loop: the force, how the object rang
 * after release, the tick's timing, and how the run ended.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "irdm/rt.h"
#include "irdm/safety.h"

#include "fw.h"

int fw_trace_alloc(struct fw_trace *t, uint64_t ticks)
{
	t->n = 0;
	t->cap = ticks;
	t->force_n = calloc(ticks, sizeof(double));
	t->node_u_m = calloc(ticks, sizeof(double));
	t->contact = calloc(ticks, 1);
	return t->force_n && t->node_u_m && t->contact ? 0 : -1;
}

void fw_trace_free(struct fw_trace *t)
{
	free(t->force_n);
	free(t->node_u_m);
	free(t->contact);
}

/* The tick after the last contact ended, or t->n if none ended. */
static uint64_t last_release(const struct fw_trace *t)
{
	for (uint64_t k = t->n; k-- > 1;)
		if (t->contact[k - 1] && !t->contact[k])
			return k;
	return t->n;
}

/*
 * Dominant frequency of x[0..n) (mean removed) by a DFT scan from 0.5 to
 * 200 Hz in 0.01 Hz steps: the ringing is a few modes, and a scan finer
 * than the 1/T bins of an FFT places the peak without interpolation.  Only
 * the first RINGING_WINDOW_S are scanned: the ringing has decayed by then,
 * and a long run (make jitter: a minute) would otherwise cost a billion
 * sin/cos pairs.
 */
#define RINGING_WINDOW_S 5.0

static double dominant_hz(const double *x, uint64_t n, double dt_s)
{
	double mean = 0, best = 0, best_hz = 0;

	if ((double)n * dt_s > RINGING_WINDOW_S)
		n = (uint64_t)(RINGING_WINDOW_S / dt_s);

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
	double dt_s = fw->board.period_us * 1e-6, peak = 0;
	uint64_t at = 0, rel = last_release(t);
	struct irdm_hist_summary cs;

	for (uint64_t k = 0; k < t->n; k++)
		if (t->force_n[k] > peak) {
			peak = t->force_n[k];
			at = k;
		}
	printf("ticks: %llu at %u us (%.3f s of %s time)\n", (unsigned long long)t->n,
	       fw->board.period_us, (double)t->n * dt_s,
	       fw->args.clock == IRDM_CLOCK_VIRTUAL ? "virtual" : "real");
	printf("force: peak %.4f N at %.3f s on the object, %.4f N at %.3f s rendered (clamped, "
	       "saturated), final %.4f N\n", peak, (double)at * dt_s, fw->rendered_peak_n,
	       (double)fw->rendered_peak_tick * dt_s, t->n ? t->force_n[t->n - 1] : 0.0);
	if (rel + 100 <= t->n)
		printf("release ringing: %.2f Hz\n",
		       dominant_hz(t->node_u_m + rel, t->n - rel, dt_s));
	else
		printf("release ringing: none (no release followed by 0.1 s of motion)\n");
	if (fw->args.clock == IRDM_CLOCK_REAL)
		print_hist("tick wake-up latency", &fw->latency);
	else
		printf("tick wake-up latency: none in virtual time\n");
	print_hist("tick compute time", &fw->compute_measured);
	irdm_hist_summarize(&fw->compute_measured, &cs);
	printf("overruns: %llu (longest run %llu)\n", (unsigned long long)cs.overruns,
	       (unsigned long long)cs.longest_run);
	fw_frame_summary(fw);
	if (fw->last_state == IRDM_SAFETY_FAULT)
		printf("state: fault: %s (torque off)%s%s\n", irdm_safety_fault_name(fw->last_cause),
		       fw_hal_why(fw)[0] ? ": " : "", fw_hal_why(fw));
	else
		printf("state: %s\n", irdm_safety_state_name(fw->last_state));
}
