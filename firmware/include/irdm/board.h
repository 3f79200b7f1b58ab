/* SPDX-License-Identifier: MIT */
/*
 * Board files: one text file per haptic device set-up (boards/NAME.board,
 * docs/boards.md lists every key).  It names the HAL back-end and its
 * options, describes the arm (every field of struct irdm_device_config in
 * irdm/device.h), the safety limits, the force loop's scheduling, the
 * virtual coupling, where the object sits in the device's workspace and the
 * pose the encoders are calibrated at.
 *
 * Format: "key = value" lines, '#' starts a comment (irdm/options.h); a key
 * may appear once.  Lists are comma separated: x,y,z in the device frame
 * (irdm/device.h: y up, z toward the user) or one value per joint.  Keys
 * not given keep the defaults (irdm_board_default(): the arm of
 * irdm_device_config_default()); name, hal and the workspace box are
 * required.  Every error is one line naming the file, the line and the
 * reason: "boards/x.board:12: torque_limit_nm = 1.07,0,1.07: joint 2: must be > 0 N m".
 *
 * Object placement.  object_offset_m is the object frame's origin in the
 * device frame; object_rotation_deg = rx,ry,rz turns the object frame's
 * axes into the device frame's by rx about the device's x axis, then ry
 * about its y axis, then rz about its z axis (fixed axes, x then y then z;
 * the same as intrinsic z-y'-x'' by rz, ry, rx):
 *   p_dev = object_offset_m + R p_obj,  R = Rz(rz) Ry(ry) Rx(rx).
 * Forces and velocities turn by R alone.
 *
 * Loading reads the file with stdio and sets up the caller's struct: it
 * runs once at start, never in the tick.  The frame functions below are
 * pure arithmetic on a loaded board and may run in the tick.
 */
#ifndef IRDM_BOARD_H
#define IRDM_BOARD_H

#include <stdbool.h>
#include <stddef.h>

#include "irdm/device.h"
#include "irdm/engine.h"
#include "irdm/options.h"

#define IRDM_BOARD_DEVICES_MAX 2 /* two arms: the two-hand pinch */
#define IRDM_BOARD_NAME_MAX 64   /* bytes with the terminating NUL */
#define IRDM_BOARD_HAL_MAX 32
#define IRDM_BOARD_HAL_OPTIONS_MAX 256
#define IRDM_BOARD_LINE_MAX 512 /* longest line, with its newline */

struct irdm_board {
	char name[IRDM_BOARD_NAME_MAX];
	char hal[IRDM_BOARD_HAL_MAX];                 /* back-end name (irdm_hal_find) */
	unsigned hal_line;                            /* its line in the file (0: not given), for
					 * refusals naming it; set by the loader */
	char hal_options[IRDM_BOARD_HAL_OPTIONS_MAX]; /* handed to the back-end as is */
	unsigned hal_options_line;                    /* its line in the file (0: not given), for
					 * the back-end's messages; set by the loader */
	unsigned devices;                             /* 1 or 2 */

	/*
	 * The first arm (kinematics, encoders, torque limits, masses, and the
	 * limits the coupling is sized from).  A second arm is the same arm
	 * with its shoulder at device2_base_offset_m: irdm_board_device().
	 */
	struct irdm_device_config device;
	double device2_base_offset_m[3];

	/* safety limits (the torque limits are in .device) */
	double workspace_min_m[3]; /* every tip stays in this box */
	double workspace_max_m[3];
	double max_tip_speed_m_per_s;
	unsigned overrun_fault_count; /* this many overruns in a row fault */
	unsigned watchdog_us;         /* one tick longer than this faults */

	/* the loop */
	unsigned period_us;
	int force_priority;    /* SCHED_FIFO priority of the force thread */
	int cpu;               /* its CPU, -1 for any */
	double deform_rate_hz; /* deformation thread, 0: off */
	bool telemetry;

	/* virtual coupling: automatic from the device, or given */
	bool coupling_auto;
	double coupling_k_n_per_m; /* when !coupling_auto; 0,0 = rigid */
	double coupling_b_ns_per_m;
	/* Coulomb friction on the proxy: static, dynamic; 0,0 frictionless */
	double friction_mu[2];

	/* object placement (above) */
	double object_offset_m[3];
	double object_rotation_deg[3];
	double object_rotation[9]; /* R, row-major; set by the loader */

	double calibration_pose_rad[IRDM_DEVICE_JOINTS]; /* encoders zeroed here */
};

/* The defaults of every key, the .def of its entry in irdm_board_options()
 * (docs/boards.md); name, hal and the workspace box empty. */
void irdm_board_default(struct irdm_board *b);

/* The key table the parser uses, for help and docs/boards.md. */
const struct irdm_opt_table *irdm_board_options(void);

/*
 * Parse a board from text (NUL-terminated; name is for messages), then
 * check it as a whole and set the derived fields.  err gets one line.
 * Return: IRDM_OK; IRDM_EFORMAT for a line that is malformed, too long,
 * has an invalid value or repeats a key; IRDM_EINVAL for an unknown key or
 * a board whose keys disagree (workspace min >= max, two devices without
 * a second base, a coupling the device cannot keep passive, ...);
 * IRDM_EMISSING if a required key is absent.  *b is undefined on error.
 */
int irdm_board_parse(struct irdm_board *b, const char *name, const char *text,
		     char *err, size_t errlen);

/*
 * The reader irdm_board_parse() runs, for one that gets its lines
 * elsewhere (a file: irdm/posix/board_file.h): begin (the defaults into
 * *b), each line (its first len characters at s, no newline; counted for
 * messages), then irdm_board_finish().  Return: as irdm_board_parse().
 */
void irdm_board_read_begin(struct irdm_opt_file *f, struct irdm_board *b, const char *name);
int irdm_board_read_line(struct irdm_opt_file *f, const char *s, size_t len, char *err,
			 size_t errlen);

/*
 * After every line: required keys, the keys checked against each other, and
 * the derived fields.  f tells which keys were set and on which line.
 * Return: IRDM_OK; IRDM_EMISSING if a required key is absent; IRDM_EINVAL
 * if keys disagree (the message names the line of the key at fault).
 */
int irdm_board_finish(struct irdm_board *b, const struct irdm_opt_file *f, char *err,
		      size_t errlen);

/*
 * The configuration of arm i (0-based): .device, with the shoulder at
 * device2_base_offset_m for i = 1.
 * Return: IRDM_OK; IRDM_EINVAL if i >= b->devices.
 */
int irdm_board_device(const struct irdm_board *b, unsigned i, struct irdm_device_config *cfg);

/*
 * The engine configuration this board asks for: irdm_engine_config_haptic()
 * at period_us from the device's stiffness, damping and force limits, with
 * the coupling replaced by K,B when the board gives one.
 */
void irdm_board_engine_config(const struct irdm_board *b, struct irdm_engine_config *cfg);

/* Points between the device frame and the object frame (m). */
void irdm_board_device_to_object(const struct irdm_board *b, const double p_dev[3],
				 double p_obj[3]);
void irdm_board_object_to_device(const struct irdm_board *b, const double p_obj[3],
				 double p_dev[3]);

/* Vectors (forces, velocities, displacements): rotation only. */
void irdm_board_vector_to_object(const struct irdm_board *b, const double v_dev[3],
				 double v_obj[3]);
void irdm_board_vector_to_device(const struct irdm_board *b, const double v_obj[3],
				 double v_dev[3]);

#endif /* IRDM_BOARD_H */
