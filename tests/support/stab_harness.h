/* SPDX-License-Identifier: MIT */
/*
 * The stability harness: runs one stiff or extreme case on the
 * engine for N ticks and records what the stability suite asserts and
 * `make stability` tabulates -- the largest force, the held force against
 * the static force an independent sum of the image's responses predicts,
 * the work the tool did on the object (its minimum says whether the object
 * ever handed back more than it had received), NaN/Inf counts and the
 * refusal, if the engine refused.
 *
 * A case is a row of a table: the image (scene key/value pairs, built once
 * per test binary and cached), the coupling, the contacts and a target
 * function.  The test files hold the tables and the limits.
 */
#ifndef IRDM_TESTS_STAB_HARNESS_H
#define IRDM_TESTS_STAB_HARNESS_H

#include <stdbool.h>
#include <stddef.h>

#include "irdm/engine.h"
#include "irdm/image.h"

#define STAB_MAX_CONTACTS 2

/* A PHANToM-Desktop-class device (as tests/test_stability.c). */
#define STAB_DEVICE_K 1000.0
#define STAB_DEVICE_B 5.0

enum stab_coupling {
	STAB_HAPTIC = 0, /* irdm_engine_config_haptic(): coupling + passivity controller */
	STAB_RIGID = 1,  /* k = 0: the target is the displacement (eq. 8) */
};

enum stab_sites {
	STAB_ONE = 0,        /* one contact at the node nearest `at` */
	STAB_SAME_NODE = 1,  /* two contacts on that same node */
	STAB_NEIGHBOURS = 2, /* two contacts: that node and its nearest column */
};

struct stab_case;

/* The targets of tick t (cmd[] zeroed before; set mode and target_m). */
typedef void (*stab_target_fn)(const struct stab_case *c, unsigned long t, double dt_s,
			       struct irdm_contact_cmd *cmd);

struct stab_case {
	const char *name;
	const char *const *image; /* scene "key", "value", ..., NULL */
	enum stab_coupling coupling;
	double max_force_n; /* engine force limit (0: none) */
	enum stab_sites sites;
	enum irdm_contact_mode mode;
	double at_m[3];                    /* where the contacts go (object frame) */
	double depth_m[STAB_MAX_CONTACTS]; /* target along -z per contact (held) */
	stab_target_fn target;             /* NULL: stab_step (ramp in 50 ms, hold) */
	unsigned long ticks;
	unsigned long poison_tick; /* stab_poison: from this tick on ... */
	double poison_m;           /* ... target z is this (NaN, Inf, huge) */
	int reset_after_fault;     /* reset once after a refusal and go on */
	/* limits the test asserts (the table shows them beside the figures) */
	double max_f_limit_n;
	double static_rel_tol;      /* |held - static| / static; 0: not checked */
	double energy_tol_j;        /* -min W allowed */
	int expect_rc;              /* what the first refusal must be (0: none) */
	bool no_releases;           /* no push may be released (re-engagement) */
	double reset_max_f_limit_n; /* max sum |F| after the reset (reset_after_fault) */
};

struct stab_record {
	unsigned long ticks;           /* run */
	double max_f_n;                /* largest sum over contacts of |F| */
	double final_f_n;              /* mean sum |F| over the last 1 % of ticks */
	double static_f_n;             /* predicted static sum |F| (NAN: none) */
	double work_max_j, work_min_j; /* W(t) = sum F . du, on the object */
	double final_spread_n;         /* max - min of sum |F| over the last 1 % */
	double first_f_n;              /* sum |F| at the end of the first 10 % (drift) */
	double kinetic_j, spin_rad_s;  /* floating: the rigid body at the end */
	unsigned long nonfinite;       /* NaN/Inf forces or displacements seen */
	unsigned long subnormal;       /* subnormal forces, contact or free node
					 * displacements seen (denormal hazard) */
	int rc;                        /* first non-zero tick return (0: none) */
	unsigned long rc_tick;
	char refusal[96];       /* irdm_strerror(rc) */
	unsigned long singular; /* regularised coupled solves */
	unsigned long releases;
	double ns_per_tick_first, ns_per_tick_last; /* first and last 10 % */
	/* after a reset (reset_after_fault): the largest sum |F| and the work
	 * done on the object over the re-engagement fade, and the limit that
	 * work must stay under (irdm_engine_contact_soften()) */
	double reset_max_f_n, reset_work_j, reset_work_limit_j;
};

/* The default target: every contact ramps to depth_m along -z in 50 ms
 * and holds. */
void stab_step(const struct stab_case *c, unsigned long t, double dt_s,
	       struct irdm_contact_cmd *cmd);
/* stab_step, then from poison_tick on contact 0's z target is poison_m
 * (for that one tick if the case resets after the fault). */
void stab_poison(const struct stab_case *c, unsigned long t, double dt_s,
		 struct irdm_contact_cmd *cmd);

/* The image of a case, built in dir on first use and kept mapped for the
 * rest of the binary (stab_images_free() unmaps them). */
const struct irdm_image *stab_image(const char *dir, const char *const *kv);
void stab_images_free(void);

/* Run a case; fills rec.  The image must come from stab_image(). */
void stab_run(const char *dir, const struct stab_case *c, struct stab_record *rec);

/*
 * Assert the case's limits on rec: no NaN/Inf, max |F| within its limit,
 * W(t) >= -energy_tol_j, the held force within static_rel_tol of the
 * static prediction, the expected refusal (or none).  Also prints the row
 * and, with IRDM_STAB_OUT=DIR set, appends it to DIR/cases.tsv.
 */
void stab_check(const struct stab_case *c, const struct stab_record *rec);

/* Append a row to DIR/cases.tsv if IRDM_STAB_OUT is set (for cases a test
 * runs without stab_run: meshes, the soak, the spinning body). */
void stab_report(const char *name, const struct stab_record *rec, double max_f_limit_n,
		 double energy_tol_j, const char *note);

/* An environment knob: its value as a number, or def when unset. */
double stab_env(const char *name, double def);

/* Monotonic clock, nanoseconds. */
double stab_now_ns(void);

/*
 * The cmocka group set-up the stability tests share: a scratch directory
 * stab_dir for the images and traces, removed with the cached images.
 */
extern char stab_dir[64];
int stab_setup(void **state);
int stab_teardown(void **state);

#endif
