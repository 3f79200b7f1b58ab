/* SPDX-License-Identifier: MIT */
/*
 * The reference checked by a second method that shares nothing with it
 * but the mesh and the material: the time-domain (Newmark) responses of
 * the step node (tools/timedomain/), untruncated over the run.
 */
#ifndef IRDM_TOOLS_REPORT_CHECK_H
#define IRDM_TOOLS_REPORT_CHECK_H

#include "report/report.h"

#define IRDM_REPORT_CHECK_SUBSTEPS 32

/*
 * Appends one irdm_report_check to res.  step: the step scenario, Fref its
 * reference forces.
 * Return: IRDM_OK; IRDM_ENOMEM; any error of the image build.
 */
int irdm_report_check_reference(const struct irdm_report_opts *o, const struct irdm_image *ref,
				double dt_s, const struct irdm_report_scenario *step,
				const double *Fref, struct irdm_report_result *res,
				char *err, size_t errlen);

#endif
