/* SPDX-License-Identifier: MIT */
/*
 * Where the arms and the object sit in the device frame: each arm's
 * shoulder, and the object's placement (irdm/board.h states the
 * convention): p_dev = t + R p_obj with R = Rz Ry Rx.  R is computed once
 * when the board is loaded; the transforms are pure arithmetic and may run
 * in the tick.
 */
#include <math.h>
#include <string.h>

#include "board_priv.h"
#include "irdm/error.h"

#define DEG_TO_RAD (3.141592653589793 / 180.0)

int irdm_board_device(const struct irdm_board *b, unsigned i, struct irdm_device_config *cfg)
{
	if (i >= b->devices)
		return IRDM_EINVAL;
	*cfg = b->device;
	if (i == 1)
		memcpy(cfg->base_offset_m, b->device2_base_offset_m, sizeof(cfg->base_offset_m));
	return IRDM_OK;
}

void irdm_board_set_rotation(struct irdm_board *b)
{
	double cx = cos(b->object_rotation_deg[0] * DEG_TO_RAD);
	double sx = sin(b->object_rotation_deg[0] * DEG_TO_RAD);
	double cy = cos(b->object_rotation_deg[1] * DEG_TO_RAD);
	double sy = sin(b->object_rotation_deg[1] * DEG_TO_RAD);
	double cz = cos(b->object_rotation_deg[2] * DEG_TO_RAD);
	double sz = sin(b->object_rotation_deg[2] * DEG_TO_RAD);
	double *r = b->object_rotation;

	/* Rz(z) Ry(y) Rx(x), multiplied out */
	r[0] = cz * cy;
	r[1] = cz * sy * sx - sz * cx;
	r[2] = cz * sy * cx + sz * sx;
	r[3] = sz * cy;
	r[4] = sz * sy * sx + cz * cx;
	r[5] = sz * sy * cx - cz * sx;
	r[6] = -sy;
	r[7] = cy * sx;
	r[8] = cy * cx;
}

void irdm_board_vector_to_device(const struct irdm_board *b, const double v_obj[3],
				 double v_dev[3])
{
	const double *r = b->object_rotation;
	double v[3] = { v_obj[0], v_obj[1], v_obj[2] }; /* v_dev may alias v_obj */

	for (int i = 0; i < 3; i++)
		v_dev[i] = r[3 * i] * v[0] + r[3 * i + 1] * v[1] + r[3 * i + 2] * v[2];
}

/* R^T v: R is a rotation, its transpose is its inverse */
void irdm_board_vector_to_object(const struct irdm_board *b, const double v_dev[3],
				 double v_obj[3])
{
	const double *r = b->object_rotation;
	double v[3] = { v_dev[0], v_dev[1], v_dev[2] };

	for (int i = 0; i < 3; i++)
		v_obj[i] = r[i] * v[0] + r[3 + i] * v[1] + r[6 + i] * v[2];
}

void irdm_board_object_to_device(const struct irdm_board *b, const double p_obj[3],
				 double p_dev[3])
{
	irdm_board_vector_to_device(b, p_obj, p_dev);
	for (int i = 0; i < 3; i++)
		p_dev[i] += b->object_offset_m[i];
}

void irdm_board_device_to_object(const struct irdm_board *b, const double p_dev[3],
				 double p_obj[3])
{
	double d[3];

	for (int i = 0; i < 3; i++)
		d[i] = p_dev[i] - b->object_offset_m[i];
	irdm_board_vector_to_object(b, d, p_obj);
}
