/* SPDX-License-Identifier: MIT */
/*
 * The force controller: one cyclic function, irdm_ctrl_tick(), that turns
 * this tick's encoder counts into joint torques through the device model,
 * the proxy on the deformed surface, the force engine and the safety state
 * machine (irdm/safety.h).
 *
 * Like the engine it is GIVEN everything (CANopenNode style): the counts,
 * the previous tick's wake-up latency and compute time, and a command word.
 * It reads no clock, does no I/O, takes no lock and never allocates: the
 * integrator's loop around it reads the HAL, times the tick, writes the
 * torques and feeds telemetry.  All its memory is struct irdm_ctrl, owned by
 * the caller; the engine and image are an already-open session's.
 *
 * The tick, in order (one file in firmware/controller/ each):
 *  1. timing: watchdog and overruns                 controller_limits.c
 *  2. commands that fault: signal, HAL flags         controller.c
 *  3. counts -> angles -> tip -> velocity            controller_input.c
 *     device frame -> object frame                   controller_placement.c
 *  4. encoder, workspace and velocity limits         controller_limits.c
 *  5. commands: shutdown, calibrate, reset,
 *     disable, enable                                controller.c
 *  6. proxy per device on the deformed surface,
 *     engine tick                                    controller_contact.c
 *  7. force -> device frame -> clamp -> J^T
 *     + gravity -> direction-keeping saturation      controller_force.c
 *  8. torque out: zero unless ENABLED                controller.c
 * A fault zeroes the torque in the tick that detects it.
 *
 * Re-engagement.  A touch deeper than one period at the tip speed limit
 * cannot have come from outside: the tool was inside when the forces came
 * on (enable, or enable after a fault's reset).  Its contact engages softly
 * (irdm_engine_contact_soften(): zero force at first, the full coupling
 * after the engine's engage_fade_s), so the hand is eased out rather than
 * struck by the spring's whole depth, and the push does not chatter.
 *
 * Overrun policy.  The loop reports the previous tick's wake-up latency and
 * compute time.  That tick overran when it ended after this tick's release
 * time: latency + compute > period.  A tick that follows an overrun still
 * runs every step (the engine keeps one sample per period, so a log replays
 * aligned) but commands the LAST SAFE torque again, the one the previous
 * tick commanded (zero if that was not ENABLED): a late tick never commands
 * a torque computed on inputs it cannot trust to be on time.  After
 * overrun_fault_count (K) consecutive overruns the controller faults
 * (OVERRUN); K - 1 do not.  Separately, a compute time above watchdog_us
 * faults at once (WATCHDOG).
 *
 * Frames.  Each device's tip is in its own device frame (irdm/device.h); the
 * per-device mount offset puts it in the shared device frame (two arms side
 * by side); the placement (rotation R, offset t) maps the shared device
 * frame to the object frame: p_obj = R (tip + mount) + t.  The engine's
 * force acts on the object (object frame); the device renders its negative,
 * rotated back: f_dev = -R^T F.  The workspace box is in each device's own
 * frame (it is the arm's reach).
 *
 * Encoders.  Counts are raw: calibration (command CALIBRATE in INIT, the
 * device held at its calibration pose) stores per joint the offset that
 * makes the raw count read as that pose.  A count of IRDM_CTRL_COUNT_NAN
 * (INT32_MIN) is the encoder's not-a-number (a back-end that cannot decode
 * a sample writes it): it faults ENCODER_NAN, as does a non-finite pose or
 * velocity; a calibrated count outside [count_min, count_max] faults
 * ENCODER_RANGE.
 */
#ifndef IRDM_CONTROLLER_H
#define IRDM_CONTROLLER_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/contact.h"
#include "irdm/device.h"
#include "irdm/engine.h"
#include "irdm/error.h"
#include "irdm/safety.h"
#include "irdm/session.h"

#define IRDM_CTRL_MAX_DEVICES 2
#define IRDM_CTRL_COUNT_NAN INT32_MIN

struct irdm_ctrl_device_config {
	struct irdm_device_config dev; /* the arm (irdm_device_config_check) */
	double mount_offset_m[3];      /* its frame's origin in the shared device frame */
	double calib_q_rad[3];         /* the known pose it is calibrated at */
};

struct irdm_ctrl_limits {
	double max_force_n;        /* |device force| clamp, > 0 */
	double workspace_min_m[3]; /* tip box, each device's own frame */
	double workspace_max_m[3];
	double max_tip_speed_m_per_s; /* > 0 */
	unsigned overrun_fault_count; /* K >= 1 consecutive overruns fault */
	uint32_t watchdog_us;         /* compute time that faults, > 0 */
};

/*
 * The limits and period a configuration has when nobody gives them, each
 * written as a board file writes it: irdm_ctrl_config_default() and the
 * board key table (its defaults, help and docs/boards.md) both expand
 * these, so a board that leaves a key out runs as the controller's default.
 */
#define IRDM_CTRL_DEFAULT_MAX_TIP_SPEED_M_PER_S 2
#define IRDM_CTRL_DEFAULT_OVERRUN_FAULT_COUNT 3
#define IRDM_CTRL_DEFAULT_WATCHDOG_US 5000
#define IRDM_CTRL_DEFAULT_PERIOD_US 1000

/*
 * The engine's own force limit, as a multiple of the controller's clamp
 * (limits.max_force_n).  The controller clamps the rendered force; the
 * engine's limit only guards against a runaway (it faults), so it sits
 * well above.
 */
#define IRDM_CTRL_ENGINE_FORCE_GUARD 4

struct irdm_ctrl_config {
	unsigned n_devices; /* 1..IRDM_CTRL_MAX_DEVICES; device i uses engine slot i */
	struct irdm_ctrl_device_config device[IRDM_CTRL_MAX_DEVICES];
	double obj_rot[9]; /* shared device frame -> object frame, row-major, proper rotation */
	double obj_offset_m[3];
	struct irdm_ctrl_limits limits;
	uint32_t period_us; /* the tick period: must equal the image's dt */
	/* the engine configuration the session was opened with (the caller
	 * picks the coupling: coupling_k_n_per_m = 0 is rigid); the controller
	 * checks max_contacts >= n_devices */
	struct irdm_engine_config engine;
	struct irdm_proxy_config proxy;
	unsigned velocity_window; /* adaptive windowing, 2..IRDM_VELOCITY_WINDOW_MAX */
};

/* Command word bits (struct irdm_ctrl_input.cmd), acted on in this order
 * after the faults of the tick: SHUTDOWN, CALIBRATE, RESET, DISABLE, ENABLE. */
enum irdm_ctrl_cmd {
	IRDM_CTRL_CMD_ENABLE = 1u << 0,    /* READY -> ENABLED */
	IRDM_CTRL_CMD_DISABLE = 1u << 1,   /* ENABLED -> READY */
	IRDM_CTRL_CMD_RESET = 1u << 2,     /* FAULT -> READY once the causes are gone */
	IRDM_CTRL_CMD_SHUTDOWN = 1u << 3,  /* -> OFF */
	IRDM_CTRL_CMD_SIGNAL = 1u << 4,    /* a signal asked the process to end: fault SIGNAL */
	IRDM_CTRL_CMD_CALIBRATE = 1u << 5, /* INIT -> READY: the device is at its calibration pose */
	/* set by the loop from the HAL's return codes */
	IRDM_CTRL_CMD_HAL_READ_FAILED = 1u << 6,  /* this tick's read failed: counts unusable */
	IRDM_CTRL_CMD_HAL_WRITE_FAILED = 1u << 7, /* the last write failed */
	IRDM_CTRL_CMD_HAL_FAULT = 1u << 8,        /* poll reported a latched fault */
};

struct irdm_ctrl_input {
	int32_t counts[IRDM_CTRL_MAX_DEVICES][3]; /* raw encoder counts */
	uint64_t prev_latency_ns;                 /* previous tick's wake-up latency */
	uint64_t prev_compute_ns;                 /* previous tick's compute time */
	uint32_t cmd;                             /* enum irdm_ctrl_cmd bits */
};

/* Per device, everything the telemetry record needs. */
struct irdm_ctrl_device_output {
	double torque_nm[3];   /* commanded: ZERO unless ENABLED */
	double q_rad[3];       /* joint angles (calibrated) */
	double tip_m[3];       /* tip, own device frame */
	double tip_obj_m[3];   /* tip, object frame */
	double vel_m_per_s[3]; /* tip velocity, own device frame */
	double speed_m_per_s;
	double force_obj_n[3]; /* engine force on the object, object frame */
	double force_n[3];     /* force rendered on the tip, device frame, after the clamp */
	double scale;          /* force clamp x torque saturation (1: none) */
	int proxy_event;       /* enum irdm_proxy_event of this tick */
	bool softened;         /* the contact began softly this tick
					 * (irdm_engine_contact_soften()) */
	bool contact;          /* the engine's contact is on after the tick */
	/*
	 * The proxy runs on the object as it is now (a floating object in its
	 * own, moved frame: irdm_engine_world_to_object()); its point and
	 * normal come out in the object frame as tip_obj_m is (the world
	 * frame, the object's at the start).
	 */
	uint32_t tri; /* proxy: SURFACE triangle, barycentrics, point */
	double bary[3];
	double proxy_m[3]; /* object frame */
	double normal[3];
	double depth_m;     /* <= 0 in contact */
	double target_m[3]; /* the engine's command (p_obj - site rest point) */
};

struct irdm_ctrl_output {
	uint64_t tick;        /* ticks run, this one included */
	int state;            /* enum irdm_safety_state after the tick */
	uint32_t faults;      /* latched fatal bits | CLAMP of this tick */
	uint32_t new_faults;  /* raised this tick */
	uint32_t cause;       /* the bit that entered FAULT (0 if none) */
	bool overrun;         /* the previous tick overran */
	bool held;            /* the torque is the previous tick's (overrun policy) */
	unsigned overrun_run; /* consecutive overruns so far */
	unsigned n_devices;
	struct irdm_ctrl_device_output dev[IRDM_CTRL_MAX_DEVICES];
};

/* Per-device working state (private). */
struct irdm_ctrl_dev {
	int32_t count_offset[3];
	struct irdm_velocity vel[3];
	struct irdm_proxy px;
	double rot_t[9];       /* R^T, for forces */
	double tau_last_nm[3]; /* the last torque commanded (the safe one to hold) */
	bool pose_ok;          /* this tick's q, tip, velocity are valid */
	struct irdm_contact_cmd cmd;
};

/*
 * The free displacement of the surface nodes the proxies look at this tick,
 * memoised: the closest-point query visits each candidate triangle's three
 * nodes, and each irdm_engine_node_disp() costs O(modes); the engine's state
 * does not change until its tick, so a node is computed once per tick.
 * Direct-mapped by row; a collision only recomputes.
 */
#define IRDM_CTRL_DISP_CACHE 1024
struct irdm_ctrl_disp_cache {
	uint64_t stamp;                        /* this tick's; 0 is never valid */
	uint64_t filled[IRDM_CTRL_DISP_CACHE]; /* the stamp a slot holds */
	uint32_t row[IRDM_CTRL_DISP_CACHE];
	double u_m[IRDM_CTRL_DISP_CACHE][3];
};

/* The controller: caller-owned, initialised by irdm_ctrl_init(). */
struct irdm_ctrl {
	struct irdm_ctrl_config cfg;
	struct irdm_session *s;
	struct irdm_contact_mesh cm;
	struct irdm_safety safety;
	struct irdm_ctrl_dev dev[IRDM_CTRL_MAX_DEVICES];
	uint64_t tick;
	unsigned overrun_run;
	uint64_t overruns;   /* total */
	uint64_t longest_ns; /* longest latency + compute seen */
	uint32_t active;     /* fault conditions that hold this tick */
	struct irdm_ctrl_disp_cache disp;
};

/*
 * Defaults: one default arm (irdm_device_config_default()) calibrated at
 * the home pose, identity placement, its 7.9 N, a workspace box of +-8 cm
 * around the home tip, the IRDM_CTRL_DEFAULT_* tip speed, K, watchdog and
 * period, the engine's haptic default for that arm at that period (its
 * force limit IRDM_CTRL_ENGINE_FORCE_GUARD times the clamp), the proxy's
 * default, a 32-sample window.
 */
void irdm_ctrl_config_default(struct irdm_ctrl_config *cfg);

/*
 * Return: IRDM_OK; IRDM_EINVAL if n_devices is not 1..IRDM_CTRL_MAX_DEVICES,
 * an arm fails irdm_device_config_check() or its calibration pose is not
 * finite or out of its encoder range, obj_rot is not a proper rotation (to
 * 1e-9), an offset is not finite, a limit is not positive (or the box
 * empty), period_us or watchdog_us is 0, overrun_fault_count is 0,
 * engine.max_contacts < n_devices, the proxy's radius, max_disp or max_walk
 * is out of range, or velocity_window is outside [2, IRDM_VELOCITY_WINDOW_MAX].
 */
int irdm_ctrl_config_check(const struct irdm_ctrl_config *cfg);

/*
 * Set up on an open session (borrowed until the caller stops ticking):
 * state INIT.  Nothing allocates here or later.
 * Return: IRDM_OK; IRDM_EINVAL if ctrl, cfg or s is NULL, the configuration
 * fails irdm_ctrl_config_check(), the image has no contact BVH, or period_us
 * differs from the image's dt by more than 1 us.
 */
int irdm_ctrl_init(struct irdm_ctrl *ctrl, const struct irdm_ctrl_config *cfg,
		   struct irdm_session *s);

/*
 * One tick (the order is at the top of this file).  *out is written in
 * full; out->dev[i].torque_nm is what the loop must write.
 * Return: IRDM_OK; IRDM_EFAULT if the controller is in FAULT after the tick
 * (the torque is zero: the loop should also safe-off the HAL);
 * IRDM_EINVAL if ctrl, in or out is NULL (nothing is done).
 */
int irdm_ctrl_tick(struct irdm_ctrl *ctrl, const struct irdm_ctrl_input *in,
		   struct irdm_ctrl_output *out);

#endif /* IRDM_CONTROLLER_H */
