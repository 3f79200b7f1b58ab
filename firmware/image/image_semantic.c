/* SPDX-License-Identifier: MIT */
/*
 * Semantic validation: every known section checked against the meta data,
 * in a fixed order.  This file sits on top of the checks: it calls them,
 * none calls it; the rules they share are image_rules.c's.
 */
#include <stddef.h>

#include "image_priv.h"

int img_check_contents(struct parse *p)
{
	int (*const step[])(struct parse *) = {
		img_check_meta,
		img_check_provenance,
		img_check_nodes,
		img_check_columns,
		img_check_surface,
		img_check_stability,
		img_check_rigid,
		img_check_col_scale,
	};
	int ret;

	for (size_t i = 0; i < sizeof(step) / sizeof(step[0]); i++) {
		ret = step[i](p);
		if (ret)
			return ret;
	}
	if (p->meta.representation == IRDM_REPR_FIR)
		ret = img_check_fir(p);
	else
		ret = img_check_modal(p);
	if (ret)
		return ret;
	return img_check_contact_bvh(p);
}
