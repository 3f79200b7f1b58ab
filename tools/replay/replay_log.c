/* SPDX-License-Identifier: MIT */
/*
 * An irdm-fw log as irdm replay's inputs: what the controller commanded
 * its engine each tick (the site and the target the log records for
 * `irdm replay --sites`), and the forces it got, to compare with.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "replay/replay_priv.h"

static int alloc_tables(struct replay_log *lg, size_t n, unsigned dev)
{
	struct trajectory *t[4] = { &lg->tr, &lg->sites, &lg->forces, &lg->softened };
	size_t cols[4] = { 1 + 3 * (size_t)dev, 1 + 4 * (size_t)dev, 1 + 3 * (size_t)dev,
			   1 + (size_t)dev };

	for (int k = 0; k < 4; k++) {
		t[k]->n_rows = n;
		t[k]->n_cols = cols[k];
		t[k]->v = malloc((n ? n : 1) * cols[k] * sizeof(double));
		if (!t[k]->v)
			return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

/* One record into row k of the tables; -1 if a site is not a triangle. */
static int put_record(struct replay_log *lg, size_t k, const struct irdm_tick_record *rec,
		      double t, uint32_t n_tris)
{
	double *u = &lg->tr.v[k * lg->tr.n_cols], *s = &lg->sites.v[k * lg->sites.n_cols];
	double *f = &lg->forces.v[k * lg->forces.n_cols];
	double *g = &lg->softened.v[k * lg->softened.n_cols];

	u[0] = s[0] = f[0] = g[0] = t;
	for (unsigned d = 0; d < lg->n_devices; d++) {
		const struct irdm_tick_dev *dv = &rec->dev[d];
		bool on = dv->site_tri != IRDM_TELEM_NO_TRI;

		if (on && dv->site_tri >= n_tris)
			return -1;
		s[1 + 4 * d] = on ? (double)dv->site_tri : -1.0;
		g[1 + d] = on && dv->softened ? 1.0 : 0.0;
		for (int a = 0; a < 3; a++) {
			s[2 + 4 * d + a] = on ? dv->site_bary[a] : 0.0;
			u[1 + 3 * d + a] = on ? dv->target_m[a] : NAN;
			f[1 + 3 * d + a] = dv->force_n[a];
		}
	}
	return 0;
}

static int check_header(const char *path, const struct irdm_log_header *h, double dt,
			char *err, size_t errlen)
{
	if (fabs(h->period_us * 1e-6 - dt) > 1e-9 * dt) {
		snprintf(err, errlen, "%s: period %u us, but the image's dt is %g s", path,
			 h->period_us, dt);
		return IRDM_EINVAL;
	}
	if (h->dropped) {
		snprintf(err, errlen, "%s: %llu records were dropped while logging: the run "
				      "cannot be replayed",
			 path, (unsigned long long)h->dropped);
		return IRDM_EFORMAT;
	}
	if (!h->n_devices || !h->record_count) {
		snprintf(err, errlen, "%s: no %s", path, h->n_devices ? "records" : "devices");
		return IRDM_EFORMAT;
	}
	return IRDM_OK;
}

int read_log(const char *path, double dt, uint32_t n_tris, struct replay_log *lg, char *err,
	     size_t errlen)
{
	struct irdm_log_reader *r;
	const struct irdm_log_header *h;
	struct irdm_tick_record rec;
	size_t k = 0;
	int ret, got;

	memset(lg, 0, sizeof(*lg));
	ret = irdm_log_open(&r, path, err, errlen);
	if (ret)
		return ret;
	h = irdm_log_header(r);
	ret = check_header(path, h, dt, err, errlen);
	if (ret)
		goto out_close;
	lg->n_devices = h->n_devices;
	snprintf(lg->board, sizeof(lg->board), "%s", h->board);
	ret = alloc_tables(lg, h->record_count, h->n_devices);
	if (ret) {
		snprintf(err, errlen, "%s: out of memory for %llu records", path,
			 (unsigned long long)h->record_count);
		goto out_free;
	}
	while ((got = irdm_log_next(r, &rec, err, errlen)) == 1 && k < h->record_count) {
		if (rec.tick != k || put_record(lg, k, &rec, (double)k * dt, n_tris)) {
			snprintf(err, errlen, "%s: record %zu: %s", path, k,
				 rec.tick != k ? "tick out of sequence" : "site is not a surface triangle of the image");
			ret = IRDM_EFORMAT;
			goto out_free;
		}
		k++;
	}
	ret = got < 0 ? got : IRDM_OK;
	if (ret)
		goto out_free;
	goto out_close;
out_free:
	replay_log_free(lg);
out_close:
	irdm_log_close(r);
	return ret;
}

void replay_log_free(struct replay_log *lg)
{
	irdm_trajectory_free(&lg->tr);
	irdm_trajectory_free(&lg->sites);
	irdm_trajectory_free(&lg->forces);
	irdm_trajectory_free(&lg->softened);
}
