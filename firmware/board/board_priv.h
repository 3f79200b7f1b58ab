/* SPDX-License-Identifier: MIT */
/* Board files: what the loader's parts share (irdm/board.h is the API). */
#ifndef IRDM_BOARD_PRIV_H
#define IRDM_BOARD_PRIV_H

#include <stddef.h>

#include "irdm/board.h"
#include "irdm/options.h"

/*
 * After every line: required keys, the keys checked against each other, and
 * the derived fields.  f tells which keys were set and on which line.
 * Return: IRDM_OK; IRDM_EMISSING if a required key is absent; IRDM_EINVAL
 * if keys disagree (the message names the line of the key at fault).
 */
int irdm_board_finish(struct irdm_board *b, const struct irdm_opt_file *f, char *err,
		      size_t errlen);

/* R = Rz Ry Rx from object_rotation_deg into object_rotation. */
void irdm_board_set_rotation(struct irdm_board *b);

#endif /* IRDM_BOARD_PRIV_H */
