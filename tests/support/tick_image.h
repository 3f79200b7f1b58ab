/* SPDX-License-Identifier: MIT */
/*
 * The image the tick-level tests run on: `make test` makes it (a 4x4x8 cm
 * box, modal:all) and names it in IRDM_TICK_IMAGE.  Header-only: the
 * tick-only tests link the firmware library alone.
 */
#ifndef IRDM_TESTS_TICK_IMAGE_H
#define IRDM_TESTS_TICK_IMAGE_H

#include <stdlib.h>

static inline const char *tick_image_path(void)
{
	const char *p = getenv("IRDM_TICK_IMAGE");

	if (!p || !*p)
		fail_msg("IRDM_TICK_IMAGE is not set: it names the image this test runs on "
			 "(make test makes it: build/data/tick.img)");
	return p;
}

#endif
