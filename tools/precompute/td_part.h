/* SPDX-License-Identifier: MIT */
/*
 * Time-domain partial results, so one scene's responses can be computed on
 * several processes or machines and merged.  A part holds inputs
 * [begin, end) of the scene's column DoFs: (end - begin) * T * n_out
 * doubles, tagged with the hash of the scene that made it.
 */
#ifndef IRDM_TOOLS_TD_PART_H
#define IRDM_TOOLS_TD_PART_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"

struct irdm_td_part {
	uint64_t scene_hash;
	uint64_t n_inputs; /* of the whole scene */
	uint64_t begin, end;
	uint64_t T, n_out; /* samples, output DoFs (3 * rows) */
	double *data;      /* (end - begin) * T * n_out */
};

/* Return: IRDM_OK; IRDM_EINVAL if the path is too long; IRDM_EIO. */
int irdm_td_part_write(const char *path, const struct irdm_td_part *p, char *err, size_t errlen);
/* Reads and validates (checksum, sizes); data is malloc'd.
 * Return: IRDM_OK; IRDM_EIO if it cannot be opened; IRDM_EFORMAT if it is
 * not a part, truncated or corrupted; IRDM_ENOMEM. */
int irdm_td_part_read(const char *path, struct irdm_td_part *p, char *err, size_t errlen);

#endif
