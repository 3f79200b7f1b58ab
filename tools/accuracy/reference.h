/* SPDX-License-Identifier: MIT */
/*
 * Contact forces by direct convolution in double, from an image's
 * responses read back (tools/image/image_response.c), not by the engine:
 *   sum_v w_iv sum_{s=0}^{t} sum_n R_{v n}[s] f_n[t-s] = target_i[t]
 * at every active contact i (its nodes v, barycentric weights w), the
 * forces spread to nodes by the same weights.  On the exact full model's
 * image this is the report's reference; on a truncated FIR image with
 * n_resp = T it is that FIR's recorded recursion without the engine's
 * tail damping.
 */
#ifndef IRDM_TOOLS_ACCURACY_REFERENCE_H
#define IRDM_TOOLS_ACCURACY_REFERENCE_H

#include <stddef.h>

#include "irdm/image.h"
#include "accuracy/scenario.h"

struct irdm_report_conv {
	const struct irdm_image *img;
	const struct irdm_report_cmd *cmds; /* N x m, tick-major */
	unsigned m;                         /* contacts */
	size_t N;                           /* ticks */
	size_t n_resp;                      /* samples of R used (past it: 0) */
	unsigned disp_every;                /* 0: no displayed-node output */
};

struct irdm_report_conv_out {
	double *F;     /* N x 3m: each contact's force on the object */
	double *disp;  /* n_eval x n_nodes x 3: u of every image node */
	size_t n_eval; /* ticks disp_every - 1, 2 disp_every - 1, ... */
};

/*
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_ECONTACT if a contact's system is
 * singular (a contact on fixed nodes only); IRDM_EINVAL if a site uses more
 * columns than IRDM_REPORT_MAX_COLS.  Free with irdm_report_conv_free().
 */
#define IRDM_REPORT_MAX_COLS 64
int irdm_report_convolve(const struct irdm_report_conv *c, struct irdm_report_conv_out *out,
			 char *err, size_t errlen);
void irdm_report_conv_free(struct irdm_report_conv_out *out);

/* The displayed-node tick of evaluation k (k = 0 .. n_eval-1). */
static inline size_t irdm_report_disp_tick(unsigned every, size_t k)
{
	return (k + 1) * every - 1;
}

#endif
