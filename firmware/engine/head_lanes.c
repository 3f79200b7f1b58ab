/* SPDX-License-Identifier: MIT */
/*
 * A hybrid image's force history by column (struct head_lanes): what the
 * head sum reads in place of the ring of ticks.  The ring holds, per tick,
 * the few columns that had a force; summing it means finding, for every
 * (tick, column) pair, the block of that column and laying its force out
 * for the block, hundreds of times a tick.  A lane holds one column's
 * samples in the block's pattern, one per tick, so the sum of one kept
 * block over the ages is one pass over two contiguous arrays.
 *
 * A lane is taken when its column first has a force and freed once its
 * newest force is older than the head (every sample it holds is then
 * zero).  A force that finds no free lane (more than HEAD_LANES columns
 * within H ticks) is in the ring only: the sums read the ring until it is
 * older than the head.
 */
#include <string.h>

#include "engine_priv.h"

static double *sample(const struct irdm_engine *e, uint32_t lane, uint32_t pos)
{
	return &e->lanes.f[((size_t)lane * e->H + pos) * HEAD_SAMPLE];
}

/* The place of the sample of age 1 (the newest): one before the previous
 * one, so that age s is s - 1 places after it (mod H). */
static uint32_t newest_pos(const struct irdm_engine *e)
{
	return e->H - 1 - e->ring.head;
}

void irdm_head_lanes_init(struct irdm_engine *e, double *f, const void *zeros)
{
	e->lanes.f = f;
	e->lanes.zeros = zeros;
	irdm_head_lanes_reset(e);
}

void irdm_head_lanes_reset(struct irdm_engine *e)
{
	struct head_lanes *L = &e->lanes;

	L->applied = 0;
	L->complete_from = 0;
	for (uint32_t i = 0; i < HEAD_LANES; i++)
		L->lane[i].col = NO_COL;
}

/* The lane of col, taken if it has none; HEAD_LANES if none is free. */
static uint32_t lane_of(struct irdm_engine *e, uint32_t col, uint32_t pos)
{
	struct head_lanes *L = &e->lanes;
	uint32_t free = HEAD_LANES;

	for (uint32_t i = 0; i < HEAD_LANES; i++) {
		if (L->lane[i].col == col)
			return i;
		if (L->lane[i].col == NO_COL && free == HEAD_LANES)
			free = i;
	}
	if (free < HEAD_LANES) {
		L->lane[free].col = col;
		L->lane[free].first = L->applied;
		memset(sample(e, free, pos), 0, HEAD_SAMPLE * sizeof(double));
	}
	return free;
}

/* After the ring took f (its head is f's slot). */
void irdm_head_lanes_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
	struct head_lanes *L = &e->lanes;
	uint32_t pos = newest_pos(e);
	uint64_t t = L->applied;

	for (uint32_t i = 0; i < HEAD_LANES; i++)
		if (L->lane[i].col != NO_COL)
			memset(sample(e, i, pos), 0, HEAD_SAMPLE * sizeof(double));
	for (uint32_t n = 0; n < f->n; n++) {
		uint32_t i = lane_of(e, f->col[n], pos);
		if (i == HEAD_LANES) {
			L->complete_from = t + e->H; /* then older than the head */
			continue;
		}
		double *p = sample(e, i, pos);
		for (int j = 0; j < HEAD_SAMPLE; j++)
			p[j] += f->f_n[n][j % 3];
		L->lane[i].last_force = t;
	}
	L->applied = t + 1;
	for (uint32_t i = 0; i < HEAD_LANES; i++)
		if (L->lane[i].col != NO_COL && L->applied - L->lane[i].last_force >= e->H)
			L->lane[i].col = NO_COL; /* its forces are older than the head */
}

/*
 * Ages lo .. hi of a lane: from its newest force to its first sample or
 * the head's end.  Samples between hold zero where the column had no
 * force; they are summed (a zero adds nothing) to keep the runs whole.
 */
static void lane_span(const struct irdm_engine *e, const struct head_lane *l, struct head_span *sp)
{
	uint64_t now = e->lanes.applied;
	uint32_t lo = (uint32_t)(now - l->last_force);
	uint32_t hi = now - l->first < e->H - 1 ? (uint32_t)(now - l->first) : e->H - 1;
	uint32_t p = (newest_pos(e) + lo - 1) % e->H, n = hi - lo + 1;
	uint32_t n0 = n < e->H - p ? n : e->H - p;

	sp->col = l->col;
	sp->run[0] = (struct head_run){ sample(e, (uint32_t)(l - e->lanes.lane), p), lo, n0 };
	sp->n_runs = 1;
	if (n0 < n)
		sp->run[sp->n_runs++] = (struct head_run){ sample(e, (uint32_t)(l - e->lanes.lane), 0),
							   lo + n0, n - n0 };
}

int irdm_head_spans(const struct irdm_engine *e, struct head_span *sp)
{
	const struct head_lanes *L = &e->lanes;
	int n = 0;

	if (L->applied < L->complete_from)
		return -1;
	for (uint32_t i = 0; i < HEAD_LANES; i++)
		if (L->lane[i].col != NO_COL)
			lane_span(e, &L->lane[i], &sp[n++]);
	return n;
}
