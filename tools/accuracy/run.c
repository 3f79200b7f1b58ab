/* SPDX-License-Identifier: MIT */
/* The representation under test runs in the force engine, as in the firmware. */
#define _GNU_SOURCE
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "irdm/posix/deform_worker.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "modal/lapack.h"
#include "accuracy/run.h"

/* The sites of every tick, made before the run so the timed loop holds
 * only what the firmware's tick does (a site moves when it changes). */
static int make_sites(const struct irdm_engine *eng, const struct irdm_report_cmd *cmds,
		      size_t n, struct irdm_contact_site *sites)
{
	for (size_t i = 0; i < n; i++) {
		const struct irdm_report_cmd *c = &cmds[i];
		int ret;

		memset(&sites[i], 0, sizeof(sites[i]));
		if (!c->active)
			continue;
		ret = c->on_node ? irdm_engine_site_node(eng, c->row, &sites[i]) :
				   irdm_engine_site_point(eng, c->tri, c->bary, &sites[i]);
		if (ret)
			return ret;
	}
	return IRDM_OK;
}

static bool same_site(const struct irdm_contact_site *a, const struct irdm_contact_site *b)
{
	return a->n_nodes == b->n_nodes && !memcmp(a->row, b->row, sizeof(a->row)) &&
	       !memcmp(a->weight, b->weight, sizeof(a->weight));
}

static double now_us(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return 1e6 * (double)ts.tv_sec + 1e-3 * (double)ts.tv_nsec;
}

/* One tick's contacts and the tick; returns the engine's code. */
static int step(struct irdm_engine *eng, const struct irdm_report_cmd *cmds,
		const struct irdm_contact_site *sites, unsigned m, size_t t, double *F)
{
	struct irdm_contact_cmd cc[IRDM_MAX_CONTACTS];
	int ret;

	memset(cc, 0, sizeof(cc));
	for (unsigned i = 0; i < m; i++) {
		const struct irdm_report_cmd *c = &cmds[t * m + i];
		const struct irdm_contact_state *st = irdm_engine_contact(eng, i);

		if (!c->active)
			continue;
		if (st->mode == IRDM_CONTACT_OFF || !same_site(&st->site, &sites[t * m + i]))
			irdm_engine_contact_begin(eng, i, &sites[t * m + i], IRDM_CONTACT_GRAB);
		cc[i].mode = IRDM_CONTACT_GRAB;
		memcpy(cc[i].target_m, c->target_m, sizeof(cc[i].target_m));
	}
	ret = irdm_engine_tick(eng, cc);
	for (unsigned i = 0; i < m; i++)
		memcpy(&F[3 * i], irdm_engine_contact(eng, i)->force_n, 3 * sizeof(double));
	return ret;
}

static int open_session(struct irdm_session **s, const struct irdm_image *img, unsigned m,
			unsigned publish_every, char *err, size_t errlen)
{
	struct irdm_session_config sc = { .deform = publish_every > 0 };

	irdm_engine_config_default(&sc.engine);
	sc.engine.max_contacts = m;
	sc.engine.publish_every = publish_every;
	return irdm_session_open_image(s, img, &sc, err, errlen);
}

/* The run that gives the displayed nodes (and warms the image's pages). */
static int run_deform(const struct irdm_image *img, const struct irdm_report_cmd *cmds,
		      const struct irdm_contact_site *sites, unsigned m, size_t N,
		      unsigned every, struct irdm_report_engine_out *out, char *err, size_t errlen)
{
	struct irdm_session *s = NULL;
	size_t n_nodes = img->meta->n_nodes;
	double F[3 * IRDM_MAX_CONTACTS], *pos = malloc(n_nodes * 3 * sizeof(double));
	int ret = IRDM_ENOMEM;

	if (!pos)
		goto out;
	ret = open_session(&s, img, m, every, err, errlen);
	if (!ret)
		ret = irdm_session_deform_open(s, err, errlen);
	if (ret)
		goto out;
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
	for (size_t t = 0; t < N && !out->faulted; t++) {
		uint64_t tk;

		out->faulted = step(s->eng, cmds, sites, m, t, F) != IRDM_OK;
		if ((t + 1) % every || !irdm_deform_update(s->worker, pos, &tk))
			continue;
		for (size_t r = 0; r < n_nodes; r++)
			for (int a = 0; a < 3; a++)
				out->disp[((t / every) * n_nodes + r) * 3 + a] =
					pos[3 * r + a] - img->nodes[r].pos_m[a];
	}
out:
	irdm_session_close(s);
	free(pos);
	return ret;
}

/* The timed run, pinned to the last CPU like the firmware's force loop. */
static int run_timed(const struct irdm_image *img, const struct irdm_report_cmd *cmds,
		     const struct irdm_contact_site *sites, unsigned m, size_t N,
		     struct irdm_report_engine_out *out, char *err, size_t errlen)
{
	struct irdm_session *s;
	cpu_set_t old, one;
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);
	bool pinned;
	int ret = open_session(&s, img, m, 0, err, errlen);

	if (ret)
		return ret;
	CPU_ZERO(&one);
	CPU_SET(cpus > 1 ? cpus - 1 : 0, &one);
	pinned = !pthread_getaffinity_np(pthread_self(), sizeof(old), &old) &&
		 !pthread_setaffinity_np(pthread_self(), sizeof(one), &one);
	for (size_t t = 0; t < N; t++) {
		double t0 = now_us();
		int rc = step(s->eng, cmds, sites, m, t, &out->F[t * 3 * m]);

		out->tick_us[t] = now_us() - t0;
		if (rc) {
			out->faulted = true;
			for (size_t k = t * 3 * m; k < N * 3 * m; k++)
				out->F[k] = NAN;
			break;
		}
	}
	if (pinned)
		pthread_setaffinity_np(pthread_self(), sizeof(old), &old);
	irdm_session_close(s);
	return IRDM_OK;
}

int irdm_report_engine_run(const struct irdm_image *img, const struct irdm_report_cmd *cmds,
			   unsigned m, size_t N, unsigned disp_every,
			   struct irdm_report_engine_out *out, char *err, size_t errlen)
{
	struct irdm_session *s = NULL;
	struct irdm_contact_site *sites = malloc(N * m * sizeof(*sites));
	size_t n_nodes = img->meta->n_nodes;
	int ret;

	memset(out, 0, sizeof(*out));
	out->n_eval = disp_every ? N / disp_every : 0;
	out->F = malloc(N * 3 * m * sizeof(double));
	out->disp = calloc((out->n_eval ? out->n_eval : 1) * n_nodes * 3, sizeof(double));
	out->tick_us = malloc(N * sizeof(double));
	if (!sites || !out->F || !out->disp || !out->tick_us) {
		snprintf(err, errlen, "engine run: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	ret = open_session(&s, img, m, 0, err, errlen);
	if (ret)
		goto out_free;
	ret = make_sites(s->eng, cmds, N * m, sites);
	irdm_session_close(s);
	if (ret) {
		snprintf(err, errlen, "engine run: a scenario's contact site is not touchable");
		goto out_free;
	}
	/* without displayed nodes, the timed run alone */
	ret = disp_every ? run_deform(img, cmds, sites, m, N, disp_every, out, err, errlen) : 0;
	if (!ret)
		ret = run_timed(img, cmds, sites, m, N, out, err, errlen);
	if (!ret)
		goto out_sites;
out_free:
	irdm_report_engine_free(out);
out_sites:
	free(sites);
	return ret;
}

void irdm_report_engine_free(struct irdm_report_engine_out *out)
{
	free(out->F);
	free(out->disp);
	free(out->tick_us);
	memset(out, 0, sizeof(*out));
}

struct irdm_report_runner {
	struct irdm_session *s;
	unsigned m;
	struct irdm_contact_site *sites;
	size_t n_sites;
};

int irdm_report_runner_open(struct irdm_report_runner **rp, const struct irdm_image *img,
			    unsigned m, char *err, size_t errlen)
{
	struct irdm_report_runner *r = calloc(1, sizeof(*r));
	int ret;

	*rp = NULL;
	if (!r) {
		snprintf(err, errlen, "engine run: out of memory");
		return IRDM_ENOMEM;
	}
	r->m = m;
	ret = open_session(&r->s, img, m, 0, err, errlen);
	if (ret) {
		free(r);
		return ret;
	}
	*rp = r;
	return IRDM_OK;
}

int irdm_report_runner_run(struct irdm_report_runner *r, const struct irdm_report_cmd *cmds,
			   size_t N, double *F, bool *faulted, char *err, size_t errlen)
{
	size_t n = N * r->m;
	int ret;

	if (n > r->n_sites) {
		struct irdm_contact_site *sites = realloc(r->sites, n * sizeof(*sites));
		if (!sites) {
			snprintf(err, errlen, "engine run: out of memory");
			return IRDM_ENOMEM;
		}
		r->sites = sites;
		r->n_sites = n;
	}
	ret = make_sites(r->s->eng, cmds, n, r->sites);
	if (ret) {
		snprintf(err, errlen, "engine run: a scenario's contact site is not touchable");
		return ret;
	}
	irdm_engine_reset(r->s->eng);
	*faulted = false;
	for (size_t t = 0; t < N; t++)
		if (step(r->s->eng, cmds, r->sites, r->m, t, &F[t * 3 * r->m])) {
			*faulted = true;
			for (size_t k = t * 3 * r->m; k < n * 3; k++)
				F[k] = NAN;
			break;
		}
	irdm_engine_reset(r->s->eng);
	return IRDM_OK;
}

void irdm_report_runner_close(struct irdm_report_runner *r)
{
	if (!r)
		return;
	irdm_session_close(r->s);
	free(r->sites);
	free(r);
}
