/* SPDX-License-Identifier: MIT */
/*
 * Where the object sits among the devices: a rigid transform from the
 * shared device frame to the object frame (irdm/controller.h, "Frames").
 * Positions go forward (p_obj = R (tip + mount) + t); forces come back by
 * the transpose (a rotation's inverse): the device renders -R^T F.
 */
#include <math.h>

#include "controller_priv.h"
#include "irdm/vec3.h"

#define ROT_TOL 1e-9

int ctrl_placement_check(const struct irdm_ctrl_config *cfg)
{
	const double *r = cfg->obj_rot;
	double det;

	for (unsigned a = 0; a < 3; a++)
		for (unsigned b = 0; b < 3; b++) {
			double d = irdm_v3_dot(&r[3 * a], &r[3 * b]) - (a == b);

			if (!(fabs(d) <= ROT_TOL))
				return IRDM_EINVAL;
		}
	/* rows orthonormal; a reflection would turn the object inside out */
	det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
	      r[2] * (r[3] * r[7] - r[4] * r[6]);
	if (!(det > 0) || !irdm_v3_finite(cfg->obj_offset_m))
		return IRDM_EINVAL;
	for (unsigned i = 0; i < cfg->n_devices; i++)
		if (!irdm_v3_finite(cfg->device[i].mount_offset_m))
			return IRDM_EINVAL;
	return IRDM_OK;
}

void ctrl_placement_init(struct irdm_ctrl *c)
{
	for (unsigned i = 0; i < IRDM_CTRL_MAX_DEVICES; i++)
		for (unsigned a = 0; a < 3; a++)
			for (unsigned b = 0; b < 3; b++)
				c->dev[i].rot_t[3 * a + b] = c->cfg.obj_rot[3 * b + a];
}

void ctrl_to_object(const struct irdm_ctrl *c, unsigned i, const double tip_m[3],
		    double p_obj_m[3])
{
	double p[3];

	irdm_v3_add(p, tip_m, c->cfg.device[i].mount_offset_m);
	for (unsigned a = 0; a < 3; a++)
		p_obj_m[a] = irdm_v3_dot(&c->cfg.obj_rot[3 * a], p) + c->cfg.obj_offset_m[a];
}

void ctrl_force_to_device(const struct irdm_ctrl *c, unsigned i, const double f_obj_n[3],
			  double f_dev_n[3])
{
	double f[3];

	for (unsigned a = 0; a < 3; a++)
		f[a] = -irdm_v3_dot(&c->dev[i].rot_t[3 * a], f_obj_n);
	f_dev_n[0] = f[0];
	f_dev_n[1] = f[1];
	f_dev_n[2] = f[2];
}
