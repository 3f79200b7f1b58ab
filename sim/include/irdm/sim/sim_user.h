/* SPDX-License-Identifier: MIT */
/*
 * The virtual user: up to two hands, each a spring-damper pulling a device
 * tip toward a scripted target (sim/README.md, "The virtual user").
 *
 * Script (a small text file, scenes/users/NAME.user).  One command a line;
 * '#' starts a comment; blank lines are ignored.  Positions are in the
 * OBJECT frame (the scene's mesh frame, metres, z up); the caller maps
 * device <-> object frames.  Times and durations in seconds, hands 1 and 2.
 *
 *   [at T] place H at X,Y,Z          the hand takes hold, its target at X,Y,Z
 *   [at T] place H at home           the same where the tip rests at the start
 *   [at T] move H to X,Y,Z over D    ease the target to X,Y,Z in D seconds
 *   [at T] move H by DX,DY,DZ over D the same, relative to the target
 *   [at T] hold H for D              keep the hand as it is for D seconds
 *   [at T] release H                 let go at once: zero force from T on
 *   [at T] stiffness H K             the hand's spring from T on, N/m
 *   [at T] damping H B               its damper from T on, N s/m
 *
 * Each hand keeps a clock: a command starts at T if given, else where the
 * hand's previous command ended (a move or hold lasts D, the others take no
 * time).  Rules, each a parse error naming file, line and reason:
 *  - 'at' times never decrease down the file, and a command may not start
 *    before its hand's previous move or hold has ended;
 *  - a hand is placed before it moves, and released before it is placed
 *    again (so its target is continuous while it holds);
 *  - every number is finite; T in [0, IRDM_SIM_USER_TIME_MAX_S]; D in
 *    (0, IRDM_SIM_USER_TIME_MAX_S]; coordinates (and move targets) within
 *    +-IRDM_SIM_USER_COORD_MAX_M; K in (0, IRDM_SIM_USER_K_MAX_N_PER_M];
 *    B in [0, IRDM_SIM_USER_B_MAX_NS_PER_M];
 *  - at most IRDM_SIM_USER_SEGMENTS_MAX segments a hand (each place, move,
 *    release, and stiffness or damping while placed, makes one), at most
 *    IRDM_SIM_USER_LINE_MAX - 2 characters a line before its newline, and
 *    at least one command.
 *
 * Motion.  A move eases with the minimum-jerk profile (Flash & Hogan 1985,
 * the shape of an unconstrained human reaching movement):
 *   s(u) = 10 u^3 - 15 u^4 + 6 u^5,  u = (t - t0) / D in [0, 1],
 *   target = from + s (to - from),  and exactly `to` from t0 + D on,
 * so position, velocity and acceleration are continuous and velocity and
 * acceleration are zero at both keyframes; the target is exact at them
 * (from at u = 0, to at u = 1, bit for bit) and a coordinate the move does
 * not change stays exactly constant.
 *
 * Home.  A device starts at rest at its calibration pose and stays there
 * until a hand takes it, so a hand first placed far from it would yank the
 * stylus across the workspace.  'home' names that point, which only the
 * caller knows (it depends on the board): a script that uses it is
 * resolved by irdm_sim_user_start() before it is evaluated, and 'move by'
 * from home stays relative to it.  irdm_sim_user_start() also refuses a
 * hand whose first place is more than IRDM_SIM_USER_GRASP_MAX_M from home.
 *
 * Hand.  force = K (target - tip) - B tip_vel while the hand holds, zero
 * when released or before it is first placed.  The damper acts on the
 * tip's own velocity (the hand's tissue resists motion of the stylus it
 * grips), not on the velocity relative to the target.  Defaults: K = 300
 * N/m, B = 2 N s/m, a relaxed grip: the order of the fingertip and
 * pen-grasp impedances reported in the haptics literature (Hajian & Howe
 * 1997, index fingertip: a few hundred N/m rising with grip force and a
 * few N s/m; Israr, Choi & Tan 2006, a hand holding a stylus), not a fit
 * to either.  The hand has no mass of its own: its inertia is the
 * device's.
 *
 * The script is read once, at load, into a caller-owned struct of fixed
 * size (about 45 kB: keep it static or on the heap, not on a tick's
 * stack); evaluation is pure arithmetic on it (no allocation, no system
 * call, no clock: the caller gives the time), safe to call every tick.
 */
#ifndef IRDM_SIM_USER_H
#define IRDM_SIM_USER_H

#include <stddef.h>

#define IRDM_SIM_USER_HANDS 2
#define IRDM_SIM_USER_SEGMENTS_MAX 256 /* per hand */
#define IRDM_SIM_USER_LINE_MAX 256     /* reader buffer: line, newline, NUL */
#define IRDM_SIM_USER_TIME_MAX_S 3600.0
#define IRDM_SIM_USER_COORD_MAX_M 1.0       /* a desktop device reaches ~0.2 m */
#define IRDM_SIM_USER_K_MAX_N_PER_M 10000.0 /* well above a clenched grip */
#define IRDM_SIM_USER_B_MAX_NS_PER_M 100.0
#define IRDM_SIM_USER_K_DEFAULT_N_PER_M 300.0
#define IRDM_SIM_USER_B_DEFAULT_NS_PER_M 2.0
#define IRDM_SIM_USER_GRASP_MAX_M 0.01 /* first place to home, at most */

/*
 * From t0_s on the hand is `active`; its target eases from from_m (at t0_s)
 * to to_m (at t1_s >= t0_s) and stays at to_m until the next segment.
 */
struct irdm_sim_user_seg {
	double t0_s, t1_s;
	double from_m[3], to_m[3];
	double k_n_per_m, b_ns_per_m;
	int active;
	int from_home, to_home; /* 1: that end is an offset from home */
};

struct irdm_sim_user_hand {
	unsigned n;     /* segments used, t0_s non-decreasing */
	int needs_home; /* 'home' used, not yet resolved */
	struct irdm_sim_user_seg seg[IRDM_SIM_USER_SEGMENTS_MAX];
};

struct irdm_sim_user {
	unsigned hands; /* 1 + the highest hand the script names */
	double end_s;   /* when the last command ends */
	struct irdm_sim_user_hand hand[IRDM_SIM_USER_HANDS];
};

/*
 * Load a script file into *u (overwritten; a failed load leaves it empty).
 * err (may be NULL) receives one line, "PATH:LINE: COMMAND: reason" for a
 * bad line, "PATH: reason" otherwise.
 * Return: IRDM_OK; IRDM_EINVAL if u or path is NULL; IRDM_EIO if the file
 * cannot be opened or read; IRDM_EFORMAT if a line is malformed, out of
 * range, out of order or too long, or the script has no command;
 * IRDM_ENOMEM if a hand needs more than IRDM_SIM_USER_SEGMENTS_MAX segments.
 */
int irdm_sim_user_load(struct irdm_sim_user *u, const char *path, char *err, size_t errlen);

/*
 * The same from a NUL-terminated text; name stands for the path in
 * messages.
 * Return: as irdm_sim_user_load(), without IRDM_EIO.
 */
int irdm_sim_user_parse(struct irdm_sim_user *u, const char *name, const char *text,
			char *err, size_t errlen);

/*
 * Tell hand `hand` (0-based) where its device's tip rests at the start
 * (object frame, m): 'home' in its segments becomes that point, and the
 * hand's first place must lie within IRDM_SIM_USER_GRASP_MAX_M of it.
 * Call once per hand the device serves, before evaluating; a hand the
 * script does not use passes.
 * err (may be NULL) receives one line, "NAME: hand H: reason".
 * Return: IRDM_OK; IRDM_EINVAL if an argument is NULL, hand >=
 * IRDM_SIM_USER_HANDS or home_m is not finite; IRDM_EFORMAT if a resolved
 * target lies beyond +-IRDM_SIM_USER_COORD_MAX_M or the first place is
 * too far from home (the hand is then left unresolved).
 */
int irdm_sim_user_start(struct irdm_sim_user *u, unsigned hand, const double home_m[3],
			const char *name, char *err, size_t errlen);

/*
 * Hand `hand` (0-based: the script's hand 1 is 0) at time t_s: its target
 * (object frame, m) and whether it holds (*active, 0 or 1).  A hand that
 * does not hold reports its last target (the origin before it was placed).
 * Return: IRDM_OK; IRDM_EINVAL if an argument is NULL, hand >=
 * IRDM_SIM_USER_HANDS, t_s is not finite, or the hand uses 'home' and
 * irdm_sim_user_start() has not resolved it.
 */
int irdm_sim_user_target(const struct irdm_sim_user *u, unsigned hand, double t_s,
			 double target_m[3], int *active);

/*
 * The force the hand puts on the tip at t_s (object frame, N):
 * K (target - tip_m) - B tip_vel_m_per_s, zero if the hand does not hold.
 * Return: IRDM_OK; IRDM_EINVAL as irdm_sim_user_target() or if tip_m,
 * tip_vel_m_per_s or force_n is NULL (force zeroed if it can be);
 * IRDM_EFAULT if the tip's position or velocity is not finite (force
 * zeroed: a hand does not push on garbage).
 */
int irdm_sim_user_hand_force(const struct irdm_sim_user *u, unsigned hand, double t_s,
			     const double tip_m[3], const double tip_vel_m_per_s[3],
			     double force_n[3]);

#endif /* IRDM_SIM_USER_H */
