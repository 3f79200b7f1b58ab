/* SPDX-License-Identifier: MIT */
/* A scenario through the force engine on one image, timed tick by tick. */
#ifndef IRDM_TOOLS_ACCURACY_RUN_H
#define IRDM_TOOLS_ACCURACY_RUN_H

#include <stdbool.h>
#include <stddef.h>

#include "irdm/image.h"
#include "accuracy/scenario.h"

struct irdm_report_engine_out {
	double *F;    /* N x 3m */
	double *disp; /* n_eval x n_nodes x 3 (deformation worker) */
	size_t n_eval;
	double *tick_us; /* N: irdm_engine_tick() and any site move */
	bool faulted;
};

/*
 * Two runs on fresh engines (rigid coupling, grab contacts, coupled
 * solve): one publishing to the deformation worker every disp_every ticks
 * (the displayed nodes; none when disp_every is 0), one timed without
 * publishing, on the last CPU.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL or IRDM_ECONTACT from the
 * session or a site.  Free with irdm_report_engine_free().
 */
int irdm_report_engine_run(const struct irdm_image *img, const struct irdm_report_cmd *cmds,
			   unsigned m, size_t N, unsigned disp_every,
			   struct irdm_report_engine_out *out, char *err, size_t errlen);
void irdm_report_engine_free(struct irdm_report_engine_out *out);

/*
 * Many untimed runs on one engine, reset between them: the engine's
 * set-up reads the whole image (the head's bounds), which on a large
 * image costs more than a run.  Forces as irdm_report_engine_run()'s,
 * without the displayed nodes or the tick times.
 */
struct irdm_report_runner;

/* Return: IRDM_OK; IRDM_ENOMEM; the session's errors. */
int irdm_report_runner_open(struct irdm_report_runner **r, const struct irdm_image *img,
			    unsigned m, char *err, size_t errlen);

/*
 * One run of N ticks of cmds (N x m) from rest: F (N x 3m) its forces,
 * NaN from a faulted tick on (*faulted).  Return: IRDM_OK; IRDM_ENOMEM;
 * IRDM_EINVAL or IRDM_ECONTACT from a site.
 */
int irdm_report_runner_run(struct irdm_report_runner *r, const struct irdm_report_cmd *cmds,
			   size_t N, double *F, bool *faulted, char *err, size_t errlen);
void irdm_report_runner_close(struct irdm_report_runner *r);

#endif
