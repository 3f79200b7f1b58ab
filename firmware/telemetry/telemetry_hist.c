/* SPDX-License-Identifier: MIT */
/*
 * Latency and compute-time histograms in fixed memory (irdm/telemetry.h
 * states the bins and the error bound).  The bin edges are integers
 * computed once at init, so that adding a sample is integer work only: no
 * libm call and no floating-point rounding deciding a bin in the tick.
 */
#include <math.h>
#include <string.h>

#include "irdm/telemetry.h"

#define LAST_BIN (IRDM_HIST_BINS - 1)

int irdm_hist_init(struct irdm_hist *h, int64_t limit_ns)
{
	if (!h || limit_ns < 0)
		return IRDM_EINVAL;
	memset(h, 0, sizeof(*h));
	/*
	 * edge_ns[i] = ceil(100 r^i): every value in bin i is >= 100 r^i and
	 * < 100 r^(i+1), which is what the stated bound needs.  The decades
	 * (i a multiple of 50) are exact powers of ten.
	 */
	for (int i = 0; i <= IRDM_HIST_LOG_BINS; i++) {
		double e = IRDM_HIST_MIN_NS * pow(10.0, (double)i / IRDM_HIST_BINS_PER_DECADE);

		h->edge_ns[i] = (uint32_t)ceil(e);
	}
	h->limit_ns = limit_ns;
	return IRDM_OK;
}

/* Index into count[]: 0 below 100 ns, 1 + i for [edge i, edge i+1), LAST_BIN at or above 100 ms. */
static unsigned bin_of(const struct irdm_hist *h, int64_t v)
{
	unsigned lo = 0, hi = IRDM_HIST_LOG_BINS; /* edge_ns[lo] <= v < edge_ns[hi] */

	if (v < IRDM_HIST_MIN_NS)
		return 0;
	if (v >= IRDM_HIST_MAX_NS)
		return LAST_BIN;
	while (hi - lo > 1) {
		unsigned mid = (lo + hi) / 2;

		if ((int64_t)h->edge_ns[mid] <= v)
			lo = mid;
		else
			hi = mid;
	}
	return 1 + lo;
}

uint64_t irdm_hist_add(struct irdm_hist *h, int64_t v)
{
	h->count[bin_of(h, v)]++;
	if (!h->n || v > h->max_ns)
		h->max_ns = v;
	if (!h->n || v < h->min_ns)
		h->min_ns = v;
	h->n++;
	if (h->limit_ns > 0 && v > h->limit_ns) {
		h->overruns++;
		h->run++;
		if (h->run > h->longest_run)
			h->longest_run = h->run;
	} else {
		h->run = 0;
	}
	return h->run;
}

/* k = ceil(per_million n / 1e6) without overflowing 64 bits. */
static uint64_t rank_of(uint64_t n, uint32_t per_million)
{
	uint64_t q = n / 1000000, rem = n % 1000000;

	return q * per_million + (rem * per_million + 999999) / 1000000;
}

/* The largest value bin b can hold, or the maximum seen if less. */
static int64_t bin_top(const struct irdm_hist *h, unsigned b)
{
	int64_t top;

	if (b == LAST_BIN)
		return h->max_ns;
	/* bin b = 1 + i holds [edge_ns[i], edge_ns[i + 1]) = [.., edge_ns[b]) */
	top = b == 0 ? IRDM_HIST_MIN_NS - 1 : (int64_t)h->edge_ns[b] - 1;
	return top < h->max_ns ? top : h->max_ns;
}

int64_t irdm_hist_quantile(const struct irdm_hist *h, uint32_t per_million)
{
	uint64_t k, seen = 0;

	if (!h->n)
		return 0;
	if (per_million < 1)
		per_million = 1;
	if (per_million > 1000000)
		per_million = 1000000;
	k = rank_of(h->n, per_million);
	for (unsigned b = 0; b < LAST_BIN; b++) {
		seen += h->count[b];
		if (seen >= k)
			return bin_top(h, b);
	}
	return h->max_ns;
}

void irdm_hist_summarize(const struct irdm_hist *h, struct irdm_hist_summary *s)
{
	memset(s, 0, sizeof(*s));
	s->n = h->n;
	s->overruns = h->overruns;
	s->longest_run = h->longest_run;
	if (!h->n)
		return;
	s->p50_ns = irdm_hist_quantile(h, 500000);
	s->p99_ns = irdm_hist_quantile(h, 990000);
	s->p999_ns = irdm_hist_quantile(h, 999000);
	s->max_ns = h->max_ns;
	s->min_ns = h->min_ns;
}
