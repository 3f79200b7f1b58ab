/* SPDX-License-Identifier: MIT */
/* Inverse kinematics of an arm for tests and benchmarks (not the firmware's). */
#ifndef IRDM_TESTS_DEVICE_IK_H
#define IRDM_TESTS_DEVICE_IK_H

#include "irdm/device.h"

/* Joint angles that put the tip at p (device frame), by Newton from home;
 * no cmocka, so a strict-mode (seccomp) child may call it. */
void dik_angles(const struct irdm_device_config *dev, const double p[3], double q[3]);

#endif
