/* SPDX-License-Identifier: MIT */
/*
 * Rigid motion of a floating object (the paper's section 4; its place in
 * the tick: docs/architecture.md, "Where each step lives"): Newton-Euler
 * equations for the centre of mass and the rotation; IRDM holds only the
 * deformation on top of this pose.
 *
 * One struct owned by the caller, set up once by irdm_rigid_init();
 * irdm_rigid_step() then never allocates, blocks or makes a system call, and
 * it is *given* dt (it reads no clock).  Double precision throughout.
 *
 * Frames: the body frame is the object frame of the image translated to the
 * centre of mass (x_body = x_object - com_rest); q (w, x, y, z) rotates body
 * vectors into world vectors, and a body point x_body is at
 * com_m + R(q) x_body in the world.
 *
 * Forces follow docs/architecture.md ("Frames and signs", "Sample
 * convention"): a force is applied TO the object and held constant over
 * [t, t + dt) (zero-order hold), at a point fixed in the world over the
 * tick.  The forces of one tick are accumulated
 * (irdm_rigid_accumulate*) and consumed by the next irdm_rigid_step(), which
 * clears them.  Torques are about the centre of mass at the start of the
 * tick.
 *
 * Angular momentum is always the spin about the centre of mass.
 */
#ifndef IRDM_RIGID_H
#define IRDM_RIGID_H

#include "irdm/error.h"
#include "irdm/history.h"      /* struct irdm_pose */
#include "irdm/image_format.h" /* struct irdm_rigid (the image's section) */

#define IRDM_RIGID_MAX_NEWTON 8 /* bound on the iterations of one step */

struct irdm_rigid_params {
	double mass_kg;
	double inertia_body_kg_m2[9]; /* about the COM, body frame, row-major, SPD */
};

struct irdm_rigid_state {
	double com_m[3];            /* world position of the centre of mass */
	double vel_m_s[3];          /* world velocity of the centre of mass */
	double q[4];                /* w, x, y, z; body -> world, unit */
	double omega_body_rad_s[3]; /* angular velocity, body frame */
};

struct irdm_rigid_body {
	double mass_kg;
	double inertia_body_kg_m2[9];         /* symmetrised copy of the parameter */
	double inv_inertia_body_per_kg_m2[9]; /* its inverse (symmetric) */
	struct irdm_rigid_state s;
	double force_n[3];          /* this tick's accumulated force, world */
	double torque_n_m[3];       /* and torque about the COM, world */
	unsigned last_newton_iters; /* of the last step (telemetry) */
};

/* Mass and inertia of an image's rigid section (its com_m is the body origin). */
void irdm_rigid_params_from_image(const struct irdm_rigid *img, struct irdm_rigid_params *p);

/*
 * Validate and set up: mass finite and > 0; inertia finite, symmetric (to
 * 1e-12 of its largest entry) and positive definite (every L D L^T pivot
 * above 1e-12 of the trace); state finite; q not (near) zero: |q| < 1e-6 is
 * rejected, otherwise q is normalised.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if rb, p or s0 is NULL or any of the above fails (rb
 * untouched).
 */
int irdm_rigid_init(struct irdm_rigid_body *rb, const struct irdm_rigid_params *p,
		    const struct irdm_rigid_state *s0);

/* Forget the forces accumulated for this tick. */
void irdm_rigid_clear(struct irdm_rigid_body *rb);

/* Add a force f (N, world, on the object) acting at world point x (m). */
void irdm_rigid_accumulate(struct irdm_rigid_body *rb, const double f_world_n[3],
			   const double x_world_m[3]);

/* Add a pure torque (N m, world). */
void irdm_rigid_accumulate_torque(struct irdm_rigid_body *rb, const double tau_world_n_m[3]);

/*
 * Advance by dt under the accumulated forces and torques (then cleared,
 * whatever the outcome).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if dt is not finite and > 0;
 * IRDM_EFAULT if the forces or torques are not finite, or the new state
 * would not be finite: the caller faults.
 * On error the state is left as it was.
 */
int irdm_rigid_step(struct irdm_rigid_body *rb, double dt_s);

void irdm_rigid_get_state(const struct irdm_rigid_body *rb, struct irdm_rigid_state *s);
void irdm_rigid_pose(const struct irdm_rigid_body *rb, struct irdm_pose *pose);

/* Points: x_body relative to the COM, body frame <-> world. */
void irdm_rigid_body_to_world(const struct irdm_rigid_body *rb, const double x_body_m[3],
			      double x_world_m[3]);
void irdm_rigid_world_to_body(const struct irdm_rigid_body *rb, const double x_world_m[3],
			      double x_body_m[3]);

/* Free vectors: body -> world (rotate) and world -> body (rotate_inverse). */
void irdm_rigid_rotate(const struct irdm_rigid_body *rb, const double v_body[3],
		       double v_world[3]);
void irdm_rigid_rotate_inverse(const struct irdm_rigid_body *rb, const double v_world[3],
			       double v_body[3]);

/*
 * Linearised compliance over one tick, for the force solve of a floating
 * object: the displacement at t + dt of the material point at r2 (world
 * vector from the COM) per unit force held at r over [t, t + dt):
 *
 *   C = dt^2/(2m) E - dt^2/2 [r2]x I_world^-1 [r]x     (row-major 3x3)
 *
 * Exact for the integrator (to first order in the force) when the body does
 * not spin; with spin w the gyroscopic coupling it leaves out is O(|w| dt)
 * relative.  C(r, r2) = C(r2, r)^T (reciprocity), symmetric positive
 * definite for r2 = r (made exactly symmetric then).
 */
void irdm_rigid_point_compliance(const struct irdm_rigid_body *rb, const double r_world_m[3],
				 const double r2_world_m[3], double dt_s, double c_m_per_n[9]);

/*
 * Free motion: where the material point at body position x_body will be at
 * t + dt if no force acts -- exactly what irdm_rigid_step() would give.
 */
void irdm_rigid_predict_point(const struct irdm_rigid_body *rb, const double x_body_m[3],
			      double dt_s, double x_world_m[3]);

double irdm_rigid_kinetic_energy_j(const struct irdm_rigid_body *rb);
void irdm_rigid_linear_momentum_world(const struct irdm_rigid_body *rb, double p_kg_m_s[3]);
/* Spin angular momentum about the COM, world frame. */
void irdm_rigid_angular_momentum_world(const struct irdm_rigid_body *rb, double l_kg_m2_s[3]);

#endif
