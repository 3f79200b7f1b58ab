/* SPDX-License-Identifier: MIT */
/*
 * Kinematic and dynamic model of a PHANToM-like 3-DoF arm (the device the
 * engine's haptic defaults describe: irdm_engine_config_haptic()).
 *
 * The arm.  A base turns about a vertical axis (joint 1, yaw theta1).  On it
 * sit two motors whose axes coincide on one horizontal "shoulder" axis.  The
 * first drives the upper arm (length l1) directly: theta2 is the angle of the
 * upper arm above the horizontal.  The second drives the forearm (length l2,
 * hinged at the far end of the upper arm) through a parallelogram linkage,
 * so theta3 is the forearm's ABSOLUTE angle from the downward vertical, not
 * an angle relative to the upper arm: each motor moves one link, and both
 * motors stay at the base.  The tip is the end of the forearm (the gimbal's
 * centre).
 *
 * In the arm's vertical plane, with the shoulder at the origin,
 *   reach  r = l1 cos(theta2) + l2 sin(theta3)    (horizontal, away from base)
 *   height h = l1 sin(theta2) - l2 cos(theta3)
 * and the yaw turns that plane about the vertical:
 *   tip = base_offset + (r sin(theta1), h, r cos(theta1)).
 *
 * Device frame (metres): y up (gravity is -y), z horizontal from the base
 * toward the user, x = y cross z (the user's right as they face the
 * device): right-handed.  theta1 > 0 turns the arm toward +x (a right-hand
 * turn about +y); theta2 > 0 lifts the elbow; theta3 > 0 swings the tip away
 * from the base.  base_offset_m is where the shoulder (yaw and shoulder axes'
 * crossing) sits in the device frame; the default puts the tip at the
 * origin in the home pose theta = (0, 0, 0) (upper arm level, forearm
 * hanging straight down), the pose the device is calibrated at.
 *
 * Mass.  Three lumped bodies, each a point mass:
 *   0: the upper arm, at com_m[0] along the upper arm from the shoulder;
 *   1: the forearm (with the gimbal), at com_m[1] along the forearm from the
 *      elbow;
 *   2: what turns rigidly with theta3 about the shoulder (the parallelogram's
 *      drive crank and counterweight), at the signed distance com_m[2] along
 *      the forearm's direction from the shoulder (negative: behind it).
 * The base turns about the vertical, so gravity does no work on theta1.
 *
 * Encoders.  Joint i reads a signed count; the joint angle is
 *   theta = angle_offset_rad + sign * 2 pi (count + 1/2) / (counts_per_rev * gear_ratio)
 * counts_per_rev counts per MOTOR turn (after quadrature), gear_ratio motor
 * turns per joint turn (the capstan).  The half count takes the centre of
 * the count's cell: an encoder floors, so the true angle lies anywhere in
 * the cell and its centre is the unbiased estimate (error <= half a count).
 *
 * Everything here is pure arithmetic on caller memory: no allocation, no
 * system call, no clock.  It runs in the force tick.
 */
#ifndef IRDM_DEVICE_H
#define IRDM_DEVICE_H

#include <stdint.h>

#define IRDM_DEVICE_JOINTS 3

struct irdm_device_config {
	/* kinematics */
	double l1_m;             /* upper arm: shoulder to elbow */
	double l2_m;             /* forearm: elbow to tip */
	double base_offset_m[3]; /* shoulder in the device frame */

	/* encoders, per joint */
	double counts_per_rev[IRDM_DEVICE_JOINTS];   /* per motor turn, > 0 */
	double gear_ratio[IRDM_DEVICE_JOINTS];       /* motor turns per joint turn, > 0 */
	double angle_offset_rad[IRDM_DEVICE_JOINTS]; /* angle at the start of count 0's cell */
	int sign[IRDM_DEVICE_JOINTS];                /* +1 or -1 */
	int32_t count_min[IRDM_DEVICE_JOINTS];       /* valid counts: [min, max] */
	int32_t count_max[IRDM_DEVICE_JOINTS];

	/* actuation */
	double torque_limit_nm[IRDM_DEVICE_JOINTS]; /* joint side, > 0 */

	/* mass (see the comment above for the three bodies) */
	double mass_kg[3];
	double com_m[3];
	double gravity_m_per_s2; /* along -y; >= 0 */

	/* the device as the engine's coupling sees it (irdm_engine_config_haptic) */
	double max_force_n;
	double k_max_n_per_m;
	double b_device_ns_per_m;
};

/*
 * The default arm's figures, one macro per field, each written as a board
 * file writes it: irdm_device_config_default() and the board key table
 * (its defaults, help and docs/boards.md) both expand them.  Lists give
 * one value per joint (or per body, for mass and centre of mass).
 */
#define IRDM_DEVICE_DEFAULT_L1_M 0.135
#define IRDM_DEVICE_DEFAULT_L2_M 0.135
#define IRDM_DEVICE_DEFAULT_BASE_OFFSET_M 0, 0.135, -0.135 /* home-pose tip at 0 */
/* 4000 counts per motor turn (1000 lines, quadrature) through 11.6:1:
 * 1.35e-4 rad, 18 um at the tip per count. */
#define IRDM_DEVICE_DEFAULT_COUNTS_PER_REV 4000, 4000, 4000
#define IRDM_DEVICE_DEFAULT_GEAR_RATIO 11.6, 11.6, 11.6
#define IRDM_DEVICE_DEFAULT_ANGLE_OFFSET_RAD 0, 0, 0
#define IRDM_DEVICE_DEFAULT_SIGN 1, 1, -1 /* the third motor turns against its joint */
/* The counts of the joint ranges -0.42..0.42, -0.40..0.40 and -0.35..0.45
 * rad (tests/test_device.c derives them from those angles). */
#define IRDM_DEVICE_DEFAULT_COUNT_MIN -3102, -2954, -3324
#define IRDM_DEVICE_DEFAULT_COUNT_MAX 3101, 2953, 2584
/* 7.9 N along any axis at the home pose: 7.9 N * 0.135 m */
#define IRDM_DEVICE_DEFAULT_TORQUE_LIMIT_NM 1.07, 1.07, 1.07
#define IRDM_DEVICE_DEFAULT_MASS_KG 0.06, 0.045, 0.09
#define IRDM_DEVICE_DEFAULT_COM_M 0.065, 0.08, -0.03
#define IRDM_DEVICE_DEFAULT_GRAVITY_M_PER_S2 9.81
#define IRDM_DEVICE_DEFAULT_MAX_FORCE_N 7.9
#define IRDM_DEVICE_DEFAULT_K_MAX_N_PER_M 1000
#define IRDM_DEVICE_DEFAULT_B_DEVICE_NS_PER_M 5

/*
 * Defaults: a PHANToM Desktop-like arm (l1 = l2 = 0.135 m, 4000 counts per
 * motor turn through an 11.6:1 capstan, 1000 N/m, 7.9 N, 5 N s/m: the
 * macros above).  The figures are plausible, not measured on a device; the
 * joint ranges give a workspace of about 16 x 12 x 12 cm
 * (tests/test_device.c measures it).
 */
void irdm_device_config_default(struct irdm_device_config *cfg);

/*
 * Check a configuration before use (the board loader calls it once).
 * Return: IRDM_OK; IRDM_EINVAL if a length, count scale, gear ratio or
 * torque limit is not finite and positive, a sign is not +-1, a count range
 * is empty, a mass is negative or a force/stiffness figure is not finite
 * and positive.
 */
int irdm_device_config_check(const struct irdm_device_config *cfg);

/* Tip position (device frame, m) of the joint angles q (rad). */
void irdm_device_fk(const struct irdm_device_config *cfg, const double q_rad[3], double tip_m[3]);

/* Jacobian d tip / d q, row-major: j[3 * row + col], row = x, y, z (m/rad). */
void irdm_device_jacobian(const struct irdm_device_config *cfg, const double q_rad[3],
			  double j[9]);

/* Joint torques that put the force f_n on the tip: tau = J(q)^T f. */
void irdm_device_force_to_torque(const struct irdm_device_config *cfg, const double q_rad[3],
				 const double f_n[3], double tau_nm[3]);

/*
 * Torques the motors must apply to hold the arm still against gravity
 * (dU/dq, U the potential energy of the three bodies): add them to the
 * commanded torques for gravity compensation.
 */
void irdm_device_gravity_torque(const struct irdm_device_config *cfg, const double q_rad[3],
				double tau_nm[3]);

/*
 * Saturate by scaling, not clipping: tau_out = s tau_in with the largest
 * s <= 1 that puts every joint within its limit, so the tip force keeps its
 * direction (clipping joints one by one would turn it).  *scale (may be
 * NULL) receives s.
 * Return: IRDM_OK; IRDM_EFAULT if a torque is not finite: tau_out is then
 * zero and *scale 0.
 */
int irdm_device_torque_saturate(const struct irdm_device_config *cfg, const double tau_in_nm[3],
				double tau_out_nm[3], double *scale);

/*
 * Encoder counts -> joint angles (the centre of each count's cell).
 * Return: IRDM_OK; IRDM_EFAULT if a count lies outside [count_min,
 * count_max] or an angle comes out non-finite (q is then untouched).
 */
int irdm_device_angles_from_counts(const struct irdm_device_config *cfg, const int32_t counts[3],
				   double q_rad[3]);

/*
 * Joint angles -> the counts an ideal encoder reads: the floor of the
 * angle in counts (the simulator's quantiser; the inverse of the above to
 * within half a count).
 * Return: IRDM_OK; IRDM_EFAULT if an angle is not finite or its count lies
 * outside [count_min, count_max] (counts is then untouched).
 */
int irdm_device_counts_from_angles(const struct irdm_device_config *cfg, const double q_rad[3],
				   int32_t counts[3]);

/* Radians per count of joint i. */
double irdm_device_rad_per_count(const struct irdm_device_config *cfg, unsigned i);

/*
 * Velocity from quantised positions: first-order adaptive windowing
 * (Janabi-Sharifi, Hayward & Chen 2000, the least-squares variant): the
 * velocity is the slope of the least-squares line through the longest
 * window of newest samples whose line stays within +-band of every sample
 * in it.  Slow motion thus averages over many samples (quantisation noise
 * falls as the window grows) and fast motion over few (little lag).  band
 * is the position uncertainty: for an encoder, about one count.
 *
 * The search starts from the previous sample's window (grow while one
 * longer fits, else shrink until one fits) instead of growing from two
 * samples every time as the paper does: windows change slowly, so a sample
 * costs a few O(window) fits instead of O(window^2) (tests/test_velocity.c
 * compares it with the paper's search).
 *
 * Fixed memory (IRDM_VELOCITY_WINDOW_MAX samples); the caller gives the
 * sample period; no clock.
 */
#define IRDM_VELOCITY_WINDOW_MAX 64

struct irdm_velocity {
	double period_s;
	double band;
	unsigned window;                        /* longest window, samples */
	unsigned count;                         /* samples held, <= window */
	unsigned head;                          /* slot of the newest sample */
	unsigned last_window;                   /* window the last estimate used */
	double y[2 * IRDM_VELOCITY_WINDOW_MAX]; /* ring of the newest samples, twice */
};

/*
 * Return: IRDM_OK; IRDM_EINVAL if period_s or band is not finite and
 * positive or window is outside [2, IRDM_VELOCITY_WINDOW_MAX].
 */
int irdm_velocity_init(struct irdm_velocity *v, double period_s, double band, unsigned window);

/* Forget the samples (after a fault or a re-calibration jump). */
void irdm_velocity_reset(struct irdm_velocity *v);

/*
 * Add the newest position sample and estimate the velocity (position units
 * per second; 0 until two samples are held).
 * Return: IRDM_OK; IRDM_EFAULT if the position is not finite (the sample is
 * dropped, *vel is 0).
 */
int irdm_velocity_update(struct irdm_velocity *v, double position, double *vel);

#endif /* IRDM_DEVICE_H */
