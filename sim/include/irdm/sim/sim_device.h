/* SPDX-License-Identifier: MIT */
/*
 * A simulated PHANToM-like arm: the arm of irdm/device.h with its masses
 * moving, friction, motor saturation, encoders and an optional bus delay.
 * It stands in for the hardware on a host (sim/README.md).
 *
 * Model (stated choices):
 *  - Inertia: the FULL 3x3 mass matrix of the three point masses of
 *    irdm/device.h (M = sum m_b J_b^T J_b, J_b the Jacobian of body b's
 *    position), plus a constant joint-side inertia per joint on its diagonal
 *    (rotor and capstan drum seen through the gear ratio).  Coriolis and
 *    centrifugal torques come from the same point masses (exact for them).
 *  - Gravity along -y on the three bodies (the device config's g).
 *  - Friction per joint: viscous b q' and Coulomb with stick-slip (Karnopp):
 *    a joint slower than stick_velocity whose static torque (motor + hand -
 *    gravity) is within its Coulomb level sticks (velocity held at zero);
 *    otherwise it slips against a torque of the Coulomb level opposing its
 *    motion.  A joint whose velocity changes sign within a sub-step stops
 *    there and the next sub-step decides whether it sticks.
 *  - End stops: a real arm's travel ends at mechanical stops, and its
 *    encoders are fitted to cover that travel.  With end_stops set, each
 *    joint meets a stop stop_inset_rad inside the angle range its encoders
 *    can read ([count_min, count_max], irdm/device.h), a linear
 *    spring-damper (Kelvin-Voigt: stop_stiffness_nm_per_rad times the
 *    penetration plus stop_damping_nm_s_per_rad times the joint speed while
 *    it penetrates).  So a released arm that coasts ends at a stop, inside
 *    the encoders' range, as the hardware does; a count outside that range
 *    stays what it is on hardware, an encoder fault.  The stops' torque is
 *    applied like the motors' and the hand's (Karnopp sees it).
 *  - Motors: each joint's torque is clipped to +-torque_limit_nm (the
 *    amplifier's own limit; the controller's direction-keeping saturation
 *    comes before it).
 *  - Encoders: floor-quantised counts (irdm_device_counts_from_angles()).
 *  - Bus delay: commanded torques reach the motors write_delay_ticks ticks
 *    late and encoder samples reach the reader read_delay_ticks ticks late,
 *    through rings in the struct (fixed memory).
 *  - Integration: classical RK4 over `substeps` sub-steps per step(dt_s);
 *    torques and the hand force are held over the step (zero-order hold).
 *
 * A tick is one irdm_sim_device_step(): set the torque, step, read the
 * counts.  The caller gives dt_s; nothing here reads a clock, allocates or
 * makes a system call.
 */
#ifndef IRDM_SIM_DEVICE_H
#define IRDM_SIM_DEVICE_H

#include <stdint.h>

#include "irdm/device.h"

#define IRDM_SIM_DELAY_MAX 16 /* ticks, either direction */
#define IRDM_SIM_SUBSTEPS_MAX 1000
/* irdm_sim_params_default()'s, and the sim back-end's option defaults */
#define IRDM_SIM_DEFAULT_SUBSTEPS 10
#define IRDM_SIM_DEFAULT_END_STOPS 1
#define IRDM_SIM_DEFAULT_DELAY_TICKS 0

struct irdm_sim_params {
	double joint_inertia_kg_m2[3];    /* added to the mass matrix's diagonal, > 0 */
	double viscous_nm_s_per_rad[3];   /* >= 0 */
	double coulomb_nm[3];             /* >= 0 */
	double stick_velocity_rad_per_s;  /* > 0 */
	unsigned substeps;                /* RK4 steps per tick, 1..IRDM_SIM_SUBSTEPS_MAX */
	unsigned write_delay_ticks;       /* 0..IRDM_SIM_DELAY_MAX */
	unsigned read_delay_ticks;        /* 0..IRDM_SIM_DELAY_MAX */
	double q0_rad[3];                 /* initial pose, at rest */
	int end_stops;                    /* 1: stops inside the count range (above) */
	double stop_inset_rad;            /* >= 0; the range must be wider than 2x it */
	double stop_stiffness_nm_per_rad; /* > 0 */
	double stop_damping_nm_s_per_rad; /* >= 0 */
};

struct irdm_sim_device {
	struct irdm_device_config dev;
	struct irdm_sim_params p;
	double stop_lo_rad[3], stop_hi_rad[3]; /* the stops (+-inf without end_stops) */
	double q_rad[3];
	double qd_rad_per_s[3];
	double cmd_nm[3];   /* last command (clipped) */
	double motor_nm[3]; /* reaching the motors this tick */
	double hand_n[3];   /* external force on the tip */
	uint64_t ticks;
	double cmd_ring[IRDM_SIM_DELAY_MAX + 1][3];
	int32_t count_ring[IRDM_SIM_DELAY_MAX + 1][3];
	int count_status[IRDM_SIM_DELAY_MAX + 1];
};

/*
 * Defaults for the default device: joint inertia 2e-4 kg m^2, viscous
 * 2e-3 N m s/rad, Coulomb 5e-3 N m (figures of the right order for a
 * desktop arm, not measured), stick below 1e-3 rad/s, 10 sub-steps, no
 * delay, the home pose; end stops 0.02 rad (about 150 counts of the
 * default encoders) inside the count range, 500 N m/rad and 0.6 N m s/rad:
 * with the default arm's yaw inertia (about 1.3e-3 kg m^2) a 100 Hz
 * contact, damping ratio 0.38, stiff enough that the upper arm falling
 * 0.38 rad under gravity with the torque off (0.037 J) enters the stop by
 * 0.012 rad, inside the inset, and soft enough for 10 RK4 sub-steps of a
 * 1 ms tick (omega h = 0.06).
 */
void irdm_sim_params_default(struct irdm_sim_params *p);

/*
 * Set up at rest at p->q0_rad, zero torque, zero hand force.
 * Return: IRDM_OK; IRDM_EINVAL if irdm_device_config_check() rejects dev,
 * a parameter is out of its range (above), or with end_stops a joint's
 * count range is not wider than twice stop_inset_rad or q0_rad lies
 * outside the stops.
 */
int irdm_sim_device_init(struct irdm_sim_device *s, const struct irdm_device_config *dev,
			 const struct irdm_sim_params *p);

/*
 * Command joint torques (clipped per joint to the motors' limits).
 * Return: IRDM_OK; IRDM_EFAULT if one is not finite (the command becomes
 * zero).
 */
int irdm_sim_device_set_torque(struct irdm_sim_device *s, const double tau_nm[3]);

/* Cut the torque now, past the bus delay (the amplifiers' enable line). */
void irdm_sim_device_torque_off(struct irdm_sim_device *s);

/*
 * The virtual hand's force on the tip (device frame, N); the joints feel
 * J(q)^T f as the arm moves.
 * Return: IRDM_OK; IRDM_EFAULT if a component is not finite (the force
 * becomes zero).
 */
int irdm_sim_device_set_hand_force(struct irdm_sim_device *s, const double f_n[3]);

/*
 * Advance one tick of dt_s.
 * Return: IRDM_OK; IRDM_EINVAL if dt_s is not finite and positive;
 * IRDM_EFAULT if the state became non-finite (it is then left as it was).
 */
int irdm_sim_device_step(struct irdm_sim_device *s, double dt_s);

/*
 * The encoder counts the reader sees this tick (read_delay_ticks old),
 * beyond count_min..count_max too: an encoder counts on past the range the
 * controller accepts, and the controller's own check reports it.
 * Return: IRDM_OK; IRDM_EFAULT if that sample had no count (an angle not
 * finite or beyond 2^31 counts; counts untouched).
 */
int irdm_sim_device_read_counts(const struct irdm_sim_device *s, int32_t counts[3]);

/* The true joint state now (tests, the virtual user). */
void irdm_sim_device_state(const struct irdm_sim_device *s, double q_rad[3],
			   double qd_rad_per_s[3]);

/* The torque that reached the motors in the last tick (after delay, clip). */
void irdm_sim_device_motor_torque(const struct irdm_sim_device *s, double tau_nm[3]);

#endif /* IRDM_SIM_DEVICE_H */
