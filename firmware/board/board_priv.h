/* SPDX-License-Identifier: MIT */
/* Board files: what the loader's parts share (irdm/board.h is the API). */
#ifndef IRDM_BOARD_PRIV_H
#define IRDM_BOARD_PRIV_H

#include <stddef.h>

#include "irdm/board.h"
#include "irdm/options.h"

/* R = Rz Ry Rx from object_rotation_deg into object_rotation. */
void irdm_board_set_rotation(struct irdm_board *b);

#endif /* IRDM_BOARD_PRIV_H */
