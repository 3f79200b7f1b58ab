/* SPDX-License-Identifier: MIT */
/*
 * The controller tick (irdm/controller.h) on the real engine and a small
 * image: the safety cases, the device model in the loop, contacts, the
 * rigid-coupling reproduction of the engine, and the real-time proof of
 * the whole tick.
 *
 * The image comes from IRDM_TICK_IMAGE (a 4 x 4 x 8 cm box, modal, bottom
 * fixed, top touchable; make test makes it; without it the tests fail).
 * The object stands with its top face GAP_M below the device's home tip:
 * object z is the device's y (up), object y its -z.  Devices are driven
 * open loop through their encoder counts (the test's own inverse
 * kinematics), or closed loop through the simulated arm (sim_device.h).
 */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <linux/seccomp.h>

#include <cmocka.h>

#include "support/tick_image.h"

#include "irdm/board.h"
#include "irdm/controller.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/session.h"
#include "irdm/sim/sim_device.h"
#include "irdm/vec3.h"
#include "support/alloc_count.h"
#include "support/device_ik.h"
#include "support/strict_mode.h"
#include "support/engine_fixture.h"

#define GAP_M 0.002 /* home tip above the top face */
#define PERIOD_US 1000
#define PERIOD_NS (PERIOD_US * 1000ull)

static const double rot[9] = { 1, 0, 0, 0, 0, -1, 0, 1, 0 }; /* device -> object */

struct rig {
	struct irdm_session *s;
	struct irdm_ctrl_config cfg;
	struct irdm_ctrl ctrl;
	struct irdm_ctrl_input in;
	struct irdm_ctrl_output out;
	double top_z, cx, cy; /* object: top face height, centre of the top */
	int rc;
	const char *path; /* the image; NULL: IRDM_TICK_IMAGE */
};

/* ---- geometry helpers (the test's own, not the controller's) ---- */

/* Device i's tip (own frame) for the object-frame point p: R^T (p - t) - mount. */
static void dev_point(const struct rig *r, unsigned i, const double p[3], double d[3])
{
	double v[3];

	for (int a = 0; a < 3; a++)
		v[a] = p[a] - r->cfg.obj_offset_m[a];
	for (int a = 0; a < 3; a++)
		d[a] = rot[a] * v[0] + rot[3 + a] * v[1] + rot[6 + a] * v[2] -
		       r->cfg.device[i].mount_offset_m[a];
}

/* Put device i's tip at the object-frame point p (as counts); no cmocka,
 * so the strict-mode child can call it. */
static int put_counts(struct rig *r, unsigned i, const double p[3])
{
	double d[3], q[3];

	dev_point(r, i, p, d);
	dik_angles(&r->cfg.device[i].dev, d, q);
	return irdm_device_counts_from_angles(&r->cfg.device[i].dev, q, r->in.counts[i]);
}

static void put(struct rig *r, unsigned i, const double p[3])
{
	assert_int_equal(put_counts(r, i, p), IRDM_OK);
}

/* The object-frame tip the counts of device i stand for (test's own chain). */
static void tip_of_counts(const struct rig *r, unsigned i, double p_obj[3], double tip[3],
			  double q[3])
{
	double v[3];

	assert_int_equal(irdm_device_angles_from_counts(&r->cfg.device[i].dev, r->in.counts[i], q),
			 IRDM_OK);
	irdm_device_fk(&r->cfg.device[i].dev, q, tip);
	for (int a = 0; a < 3; a++)
		v[a] = tip[a] + r->cfg.device[i].mount_offset_m[a];
	for (int a = 0; a < 3; a++)
		p_obj[a] = rot[3 * a] * v[0] + rot[3 * a + 1] * v[1] + rot[3 * a + 2] * v[2] +
			   r->cfg.obj_offset_m[a];
}

/* Object-frame point above the top face: dx, dy from its centre, height dz. */
static void at(const struct rig *r, double dx, double dy, double dz, double p[3])
{
	p[0] = r->cx + dx;
	p[1] = r->cy + dy;
	p[2] = r->top_z + dz;
}

/* ---- the rig ---- */

static void box_of(const struct irdm_image *img, struct rig *r)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };

	for (uint32_t k = 0; k < img->meta->n_nodes; k++)
		for (int a = 0; a < 3; a++) {
			lo[a] = fmin(lo[a], img->nodes[k].pos_m[a]);
			hi[a] = fmax(hi[a], img->nodes[k].pos_m[a]);
		}
	r->cx = 0.5 * (lo[0] + hi[0]);
	r->cy = 0.5 * (lo[1] + hi[1]);
	r->top_z = hi[2];
}

/* The default configuration, the object under the home tip. */
static void rig_config(struct rig *r, unsigned n_devices)
{
	memset(r, 0, sizeof(*r));
	irdm_ctrl_config_default(&r->cfg);
	r->cfg.n_devices = n_devices;
	memcpy(r->cfg.obj_rot, rot, sizeof(rot));
	if (n_devices == 2) {
		r->cfg.device[0].mount_offset_m[0] = -0.01;
		r->cfg.device[1].mount_offset_m[0] = 0.01;
	}
}

static void rig_open(struct rig *r)
{
	struct irdm_session_config sc = { .deform = false };
	char err[512];

	sc.engine = r->cfg.engine;
	if (irdm_session_open(&r->s, r->path ? r->path : tick_image_path(), &sc, err, sizeof(err)))
		fail_msg("session: %s", err);
	box_of(r->s->img, r);
	r->cfg.obj_offset_m[0] = r->cx;
	r->cfg.obj_offset_m[1] = r->cy;
	r->cfg.obj_offset_m[2] = r->top_z + GAP_M;
	assert_int_equal(irdm_ctrl_init(&r->ctrl, &r->cfg, r->s), IRDM_OK);
	/* at the calibration pose exactly: the offsets come out zero, so the
	 * test's own counts -> tip chain needs none */
	for (unsigned i = 0; i < r->cfg.n_devices; i++)
		assert_int_equal(irdm_device_counts_from_angles(&r->cfg.device[i].dev,
								r->cfg.device[i].calib_q_rad,
								r->in.counts[i]),
				 IRDM_OK);
}

static void rig_close(struct rig *r)
{
	irdm_session_close(r->s);
	r->s = NULL;
}

/* One tick with r->in; the command word is one-shot. */
static int tick(struct rig *r)
{
	r->rc = irdm_ctrl_tick(&r->ctrl, &r->in, &r->out);
	r->in.cmd = 0;
	r->in.prev_latency_ns = 0;
	r->in.prev_compute_ns = 0;
	return r->rc;
}

static int tick_cmd(struct rig *r, uint32_t cmd)
{
	r->in.cmd = cmd;
	return tick(r);
}

/* Calibrate at home and enable. */
static void rig_enable(struct rig *r)
{
	assert_int_equal(tick_cmd(r, IRDM_CTRL_CMD_CALIBRATE), IRDM_OK);
	assert_int_equal(r->out.state, IRDM_SAFETY_READY);
	assert_int_equal(tick_cmd(r, IRDM_CTRL_CMD_ENABLE), IRDM_OK);
	assert_int_equal(r->out.state, IRDM_SAFETY_ENABLED);
}

static bool torque_zero(const struct rig *r)
{
	for (unsigned i = 0; i < r->cfg.n_devices; i++)
		for (int j = 0; j < 3; j++)
			if (r->out.dev[i].torque_nm[j] != 0.0)
				return false;
	return true;
}

/* Glide device i at the home height from over its home to (dx, dy), 1 mm
 * per 50 ticks (20 mm/s: far below the speed limit). */
static void approach(struct rig *r, unsigned i, double dx, double dy)
{
	double x0 = r->cfg.device[i].mount_offset_m[0];
	int n = (int)(hypot(dx - x0, dy) / 2e-5) + 1;

	for (int k = 1; k <= n; k++) {
		double p[3];
		at(r, x0 + (dx - x0) * k / n, dy * k / n, GAP_M, p);
		put(r, i, p);
		assert_int_equal(tick(r), IRDM_OK);
	}
}

/* Press device i down to depth_m below the top face over n ticks, at dx. */
static void press(struct rig *r, unsigned i, double dx, double depth_m, int n)
{
	for (int k = 1; k <= n; k++) {
		double p[3];
		at(r, dx, 0, GAP_M - (GAP_M + depth_m) * k / n, p);
		put(r, i, p);
		assert_int_equal(tick(r), IRDM_OK);
	}
}

/* ---- configuration ---- */

/*
 * The controller's defaults are a default board's: the arm, its force
 * limit, the tip speed, overrun count, watchdog and period a board file
 * that leaves those keys out gives irdm-fw.
 */
static void test_defaults_are_the_board_defaults(void **state)
{
	struct irdm_ctrl_config c;
	struct irdm_board b;
	(void)state;

	irdm_board_default(&b);
	irdm_ctrl_config_default(&c);
	assert_memory_equal(&c.device[0].dev, &b.device, sizeof(b.device));
	assert_true(c.limits.max_force_n == b.device.max_force_n);
	assert_true(c.limits.max_tip_speed_m_per_s == b.max_tip_speed_m_per_s);
	assert_int_equal(c.limits.overrun_fault_count, b.overrun_fault_count);
	assert_int_equal(c.limits.watchdog_us, b.watchdog_us);
	assert_int_equal(c.period_us, b.period_us);
	assert_true(c.engine.max_force_n == IRDM_CTRL_ENGINE_FORCE_GUARD * b.device.max_force_n);
}

static void test_config_errors(void **state)
{
	struct irdm_ctrl_config c;
	struct rig r;
	(void)state;

	irdm_ctrl_config_default(&c);
	assert_int_equal(irdm_ctrl_config_check(&c), IRDM_OK);
#define BAD(stmt) \
	do { \
		irdm_ctrl_config_default(&c); \
		stmt; \
		assert_int_equal(irdm_ctrl_config_check(&c), IRDM_EINVAL); \
	} while (0)
	BAD(c.n_devices = 0);
	BAD(c.n_devices = 3);
	BAD(c.obj_rot[8] = -1);  /* a reflection */
	BAD(c.obj_rot[1] = 0.1); /* not orthonormal */
	BAD(c.obj_offset_m[2] = NAN);
	BAD(c.device[0].mount_offset_m[0] = INFINITY);
	BAD(c.device[0].calib_q_rad[1] = 10); /* outside the encoder range */
	BAD(c.device[0].dev.l1_m = 0);
	BAD(c.limits.max_force_n = 0);
	BAD(c.limits.max_tip_speed_m_per_s = -1);
	BAD(c.limits.workspace_min_m[1] = c.limits.workspace_max_m[1]);
	BAD(c.limits.overrun_fault_count = 0);
	BAD(c.limits.watchdog_us = 0);
	BAD(c.period_us = 0);
	BAD(c.engine.max_contacts = 1; c.n_devices = 2);
	BAD(c.proxy.max_walk = 0);
	BAD(c.velocity_window = 1);
#undef BAD
	assert_int_equal(irdm_ctrl_config_check(NULL), IRDM_EINVAL);

	/* init: the period must be the image's */
	rig_config(&r, 1);
	rig_open(&r);
	r.cfg.period_us = 2000;
	assert_int_equal(irdm_ctrl_init(&r.ctrl, &r.cfg, r.s), IRDM_EINVAL);
	r.cfg.period_us = PERIOD_US;
	assert_int_equal(irdm_ctrl_init(&r.ctrl, &r.cfg, NULL), IRDM_EINVAL);
	assert_int_equal(irdm_ctrl_init(NULL, &r.cfg, r.s), IRDM_EINVAL);
	assert_int_equal(irdm_ctrl_init(&r.ctrl, &r.cfg, r.s), IRDM_OK);
	assert_int_equal(irdm_ctrl_tick(&r.ctrl, NULL, &r.out), IRDM_EINVAL);
	assert_int_equal(irdm_ctrl_tick(&r.ctrl, &r.in, NULL), IRDM_EINVAL);
	rig_close(&r);
}

/* ---- the state machine through the tick ---- */

static void expect_state(struct rig *r, uint32_t cmd, int state, bool zero)
{
	tick_cmd(r, cmd);
	assert_int_equal(r->out.state, state);
	if (zero)
		assert_true(torque_zero(r));
	else
		assert_false(torque_zero(r));
}

static void test_transitions_through_the_tick(void **state)
{
	struct rig r;
	(void)state;

	rig_config(&r, 1);
	rig_open(&r);
	/* INIT: no torque, enabling refused until calibrated */
	expect_state(&r, 0, IRDM_SAFETY_INIT, true);
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_INIT, true);
	expect_state(&r, IRDM_CTRL_CMD_RESET, IRDM_SAFETY_INIT, true);
	expect_state(&r, IRDM_CTRL_CMD_CALIBRATE, IRDM_SAFETY_READY, true);
	expect_state(&r, IRDM_CTRL_CMD_CALIBRATE, IRDM_SAFETY_READY, true);
	/* READY <-> ENABLED: gravity compensation makes the torque non-zero */
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_ENABLED, false);
	expect_state(&r, 0, IRDM_SAFETY_ENABLED, false);
	expect_state(&r, IRDM_CTRL_CMD_DISABLE, IRDM_SAFETY_READY, true);
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_ENABLED, false);
	/* a fault; the loop keeps asking to enable: it never does by itself */
	expect_state(&r, IRDM_CTRL_CMD_HAL_FAULT, IRDM_SAFETY_FAULT, true);
	assert_int_equal(r.rc, IRDM_EFAULT);
	for (int k = 0; k < 10; k++)
		expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_FAULT, true);
	expect_state(&r, IRDM_CTRL_CMD_DISABLE, IRDM_SAFETY_FAULT, true);
	expect_state(&r, IRDM_CTRL_CMD_CALIBRATE, IRDM_SAFETY_FAULT, true);
	/* reset refused while the cause holds, accepted once it is gone */
	expect_state(&r, IRDM_CTRL_CMD_RESET | IRDM_CTRL_CMD_HAL_FAULT, IRDM_SAFETY_FAULT, true);
	expect_state(&r, IRDM_CTRL_CMD_RESET, IRDM_SAFETY_READY, true);
	assert_int_equal(r.out.faults, 0);
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_ENABLED, false);
	/* shutdown from ENABLED; OFF is final */
	expect_state(&r, IRDM_CTRL_CMD_SHUTDOWN, IRDM_SAFETY_OFF, true);
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_OFF, true);
	expect_state(&r, IRDM_CTRL_CMD_RESET, IRDM_SAFETY_OFF, true);
	expect_state(&r, IRDM_CTRL_CMD_CALIBRATE, IRDM_SAFETY_OFF, true);
	expect_state(&r, IRDM_CTRL_CMD_SIGNAL, IRDM_SAFETY_OFF, true);
	rig_close(&r);

	/* a fault before calibration: reset leads back to INIT */
	rig_config(&r, 1);
	rig_open(&r);
	expect_state(&r, IRDM_CTRL_CMD_HAL_READ_FAILED, IRDM_SAFETY_FAULT, true);
	expect_state(&r, IRDM_CTRL_CMD_RESET, IRDM_SAFETY_INIT, true);
	expect_state(&r, IRDM_CTRL_CMD_ENABLE, IRDM_SAFETY_INIT, true);
	/* shutdown from READY and from INIT */
	expect_state(&r, IRDM_CTRL_CMD_CALIBRATE, IRDM_SAFETY_READY, true);
	expect_state(&r, IRDM_CTRL_CMD_SHUTDOWN, IRDM_SAFETY_OFF, true);
	rig_close(&r);
	rig_config(&r, 1);
	rig_open(&r);
	expect_state(&r, IRDM_CTRL_CMD_SHUTDOWN, IRDM_SAFETY_OFF, true);
	rig_close(&r);
}

/* ---- safety cases: each ends with zero torque within one tick ---- */

/* The tip speed limit, m/s. */
static void slow_limit(struct irdm_ctrl_config *cfg, double v)
{
	cfg->limits.max_tip_speed_m_per_s = v;
}

/* Enabled, device 0 pressed 1.5 mm into the top face for 100 ticks. */
static void contact_rig(struct rig *r, void (*tweak)(struct irdm_ctrl_config *, double), double v)
{
	rig_config(r, 1);
	if (tweak)
		tweak(&r->cfg, v);
	rig_open(r);
	rig_enable(r);
	press(r, 0, 0, 0.0015, 100);
	for (int k = 0; k < 50; k++)
		assert_int_equal(tick(r), IRDM_OK);
	assert_int_equal(r->out.state, IRDM_SAFETY_ENABLED);
	assert_true(r->out.dev[0].contact);
	assert_int_equal(r->out.dev[0].proxy_event, IRDM_PROXY_SLIDE);
	assert_true(irdm_v3_norm(r->out.dev[0].force_n) > 0);
	assert_false(torque_zero(r));
}

/* The tick just run faulted for `flag`: torque zero, the reason logged, the
 * contact ended; and it stays so, whatever the loop asks but a reset. */
static void assert_faulted(struct rig *r, uint32_t flag)
{
	assert_int_equal(r->rc, IRDM_EFAULT);
	assert_int_equal(r->out.state, IRDM_SAFETY_FAULT);
	assert_true(torque_zero(r));
	assert_true(r->out.new_faults & flag);
	assert_true(r->out.faults & flag);
	assert_int_equal(r->out.cause, flag);
	assert_string_equal(irdm_safety_fault_name(r->out.cause), irdm_safety_fault_name(flag));
	assert_false(r->out.dev[0].contact);
	assert_int_equal(irdm_engine_contact(r->s->eng, 0)->mode, IRDM_CONTACT_OFF);
	for (int k = 0; k < 5; k++) {
		tick_cmd(r, IRDM_CTRL_CMD_ENABLE);
		assert_int_equal(r->out.state, IRDM_SAFETY_FAULT);
		assert_true(torque_zero(r));
	}
}

static void test_signal_mid_contact(void **state)
{
	struct rig r;
	(void)state;

	contact_rig(&r, NULL, 0);
	tick_cmd(&r, IRDM_CTRL_CMD_SIGNAL);
	assert_faulted(&r, IRDM_FAULT_SIGNAL);
	/* the process is stopping: no reset, then off */
	tick_cmd(&r, IRDM_CTRL_CMD_RESET);
	assert_int_equal(r.out.state, IRDM_SAFETY_FAULT);
	tick_cmd(&r, IRDM_CTRL_CMD_SHUTDOWN);
	assert_int_equal(r.out.state, IRDM_SAFETY_OFF);
	assert_true(torque_zero(&r));
	rig_close(&r);
}

static void test_hal_failures(void **state)
{
	static const struct {
		uint32_t cmd, flag;
	} c[] = {
		{ IRDM_CTRL_CMD_HAL_READ_FAILED, IRDM_FAULT_HAL_READ },
		{ IRDM_CTRL_CMD_HAL_WRITE_FAILED, IRDM_FAULT_HAL_WRITE },
		{ IRDM_CTRL_CMD_HAL_FAULT, IRDM_FAULT_HAL_FAULT },
	};
	(void)state;

	for (size_t k = 0; k < sizeof(c) / sizeof(c[0]); k++) {
		struct rig r;

		contact_rig(&r, NULL, 0);
		tick_cmd(&r, c[k].cmd);
		assert_faulted(&r, c[k].flag);
		/* refused while the loop still reports it, then back in contact */
		tick_cmd(&r, IRDM_CTRL_CMD_RESET | c[k].cmd);
		assert_int_equal(r.out.state, IRDM_SAFETY_FAULT);
		tick_cmd(&r, IRDM_CTRL_CMD_RESET);
		assert_int_equal(r.out.state, IRDM_SAFETY_READY);
		assert_int_equal(r.out.faults, 0);
		/* up out of the object (READY: no force), enable, press again */
		for (int s = 1; s <= 200; s++) {
			double p[3];
			at(&r, 0, 0, -0.0015 + (GAP_M + 0.0015) * s / 200, p);
			put(&r, 0, p);
			assert_int_equal(tick(&r), IRDM_OK);
		}
		tick_cmd(&r, IRDM_CTRL_CMD_ENABLE);
		assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
		press(&r, 0, 0, 0.0015, 100);
		assert_true(r.out.dev[0].contact);
		rig_close(&r);
	}
}

/*
 * Forces back on with the tool 1.5 mm inside (a HAL fault, a reset, enable
 * without moving): the contact engages softly.  The first enabled tick
 * renders no force; the force then grows over the engine's fade
 * (IRDM_ENGINE_ENGAGE_FADE_S) without a release, each tick's step within
 * 1.5 % of the held force (measured 1.3 %: the fade's own steepest step is
 * 0.6 %, the soft object's ringing adds the rest), and ends at the force
 * held before the fault.  A hard engagement renders 1.64 N at the first
 * tick, 34 times the held force, and the push chatters.
 */
static void test_enable_inside_fades_in(void **state)
{
	struct rig r;
	unsigned fade = (unsigned)ceil(IRDM_ENGINE_ENGAGE_FADE_S / 1e-3 - 1e-9);
	double held, f_prev = 0, max_step = 0;
	(void)state;

	/* at 1 m/s a period's travel is 1 mm: 1.5 mm deep cannot come from outside */
	contact_rig(&r, slow_limit, 1.0);
	for (int k = 0; k < 2000; k++) /* settle: the held force */
		assert_int_equal(tick(&r), IRDM_OK);
	held = irdm_v3_norm(r.out.dev[0].force_obj_n);
	tick_cmd(&r, IRDM_CTRL_CMD_HAL_FAULT);
	assert_faulted(&r, IRDM_FAULT_HAL_FAULT);
	tick_cmd(&r, IRDM_CTRL_CMD_RESET);
	assert_int_equal(r.out.state, IRDM_SAFETY_READY);
	for (int k = 0; k < 2000; k++) /* the object relaxes under the tool */
		assert_int_equal(tick(&r), IRDM_OK);
	tick_cmd(&r, IRDM_CTRL_CMD_ENABLE);
	assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	assert_int_equal(r.out.dev[0].proxy_event, IRDM_PROXY_TOUCH);
	assert_true(irdm_v3_norm(r.out.dev[0].force_obj_n) <= 1e-9 * held);
	for (unsigned k = 0; k < fade + 500; k++) {
		double f;

		assert_int_equal(tick(&r), IRDM_OK);
		assert_int_equal(r.out.dev[0].proxy_event, IRDM_PROXY_SLIDE);
		f = irdm_v3_norm(r.out.dev[0].force_obj_n);
		max_step = fmax(max_step, fabs(f - f_prev));
		f_prev = f;
	}
	print_message("re-engaged 1.5 mm inside: held %.4f N before the fault, %.4f N after the "
		      "fade; largest step %.3e N per tick (the fade's steepest %.3e)\n",
		      held, f_prev, max_step, M_PI / 2 * held / fade);
	assert_true(max_step <= 0.015 * held);
	assert_true(fabs(f_prev - held) <= 1e-3 * held);
	assert_int_equal(irdm_engine_stats(r.s->eng)->releases, 0);
	rig_close(&r);
}

static void test_encoder_nan_and_range(void **state)
{
	struct rig r;
	(void)state;

	contact_rig(&r, NULL, 0);
	r.in.counts[0][1] = IRDM_CTRL_COUNT_NAN;
	tick(&r);
	assert_faulted(&r, IRDM_FAULT_ENCODER_NAN);
	rig_close(&r);

	contact_rig(&r, NULL, 0);
	int32_t keep = r.in.counts[0][2];
	r.in.counts[0][2] = r.cfg.device[0].dev.count_max[2] + 1;
	tick(&r);
	assert_faulted(&r, IRDM_FAULT_ENCODER_RANGE);
	/* back in range: the reset is accepted */
	r.in.counts[0][2] = keep;
	tick_cmd(&r, IRDM_CTRL_CMD_RESET);
	assert_int_equal(r.out.state, IRDM_SAFETY_READY);
	rig_close(&r);
}

static void test_watchdog(void **state)
{
	struct rig r;
	(void)state;

	contact_rig(&r, NULL, 0);
	/* exactly the watchdog: an overrun (held), not a watchdog fault */
	r.in.prev_compute_ns = r.cfg.limits.watchdog_us * 1000ull;
	tick(&r);
	assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	assert_true(r.out.held);
	r.in.prev_compute_ns = r.cfg.limits.watchdog_us * 1000ull + 1;
	tick(&r);
	assert_faulted(&r, IRDM_FAULT_WATCHDOG);
	tick_cmd(&r, IRDM_CTRL_CMD_RESET);
	assert_int_equal(r.out.state, IRDM_SAFETY_READY);
	rig_close(&r);
}

static void test_overruns(void **state)
{
	unsigned K;
	double held[3];
	uint64_t ticks0;
	struct rig r;
	(void)state;

	contact_rig(&r, NULL, 0);
	K = r.cfg.limits.overrun_fault_count;
	assert_true(K >= 2);
	for (int round = 0; round < 2; round++) {
		/* K - 1 overruns: the torque of the last normal tick, held */
		memcpy(held, r.out.dev[0].torque_nm, sizeof(held));
		ticks0 = irdm_engine_stats(r.s->eng)->ticks;
		for (unsigned k = 1; k < K; k++) {
			r.in.prev_latency_ns = 20000;
			r.in.prev_compute_ns = PERIOD_NS - 20000 + 1;
			assert_int_equal(tick(&r), IRDM_OK);
			assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
			assert_true(r.out.overrun);
			assert_true(r.out.held);
			assert_int_equal(r.out.overrun_run, k);
			assert_memory_equal(r.out.dev[0].torque_nm, held, sizeof(held));
		}
		/* the engine kept one sample per period */
		assert_int_equal(irdm_engine_stats(r.s->eng)->ticks, ticks0 + K - 1);
		/* on time again: a fresh torque, the run starts over */
		r.in.prev_latency_ns = 20000;
		r.in.prev_compute_ns = PERIOD_NS - 20000;
		assert_int_equal(tick(&r), IRDM_OK);
		assert_false(r.out.overrun);
		assert_false(r.out.held);
		assert_int_equal(r.out.overrun_run, 0);
	}
	for (unsigned k = 1; k <= K; k++) {
		r.in.prev_compute_ns = PERIOD_NS + 1;
		tick(&r);
		if (k < K)
			assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	}
	assert_faulted(&r, IRDM_FAULT_OVERRUN);
	print_message("  %u consecutive overruns fault, %u hold the torque\n", K, K - 1);
	rig_close(&r);
}

static void narrow_floor(struct irdm_ctrl_config *cfg, double y)
{
	cfg->limits.workspace_min_m[1] = y;
}

static void test_workspace(void **state)
{
	double floor_y = -(GAP_M + 0.003);
	int k;
	struct rig r;
	(void)state;

	contact_rig(&r, narrow_floor, floor_y);
	/* down 20 um a tick: the fault comes on the first tick below the floor */
	for (k = 1; k < 400; k++) {
		double p[3], p_obj[3], tip[3], q[3];
		at(&r, 0, 0, -0.0015 - 2e-5 * k, p);
		put(&r, 0, p);
		tip_of_counts(&r, 0, p_obj, tip, q);
		tick(&r);
		if (tip[1] < floor_y)
			break;
		assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	}
	assert_true(k < 400);
	assert_faulted(&r, IRDM_FAULT_WORKSPACE);
	rig_close(&r);
}

/*
 * Slide in contact at speed_m_per_s along the object-frame direction
 * (ux, uy) for n ticks.  Returns the ticks until a fault (stop_on_fault),
 * else the largest speed estimate; *vec_err gets the largest error of the
 * estimated velocity VECTOR (device frame) after the first 50 ticks.
 */
static double slide(struct rig *r, double *x, double *y, double ux, double uy,
		    double speed_m_per_s, int n, bool stop_on_fault, double *vec_err)
{
	const double v_obj[3] = { speed_m_per_s * ux, speed_m_per_s * uy, 0 };
	double vmax = 0, v_dev[3];

	for (int a = 0; a < 3; a++) /* R^T v */
		v_dev[a] = rot[a] * v_obj[0] + rot[3 + a] * v_obj[1] + rot[6 + a] * v_obj[2];
	for (int k = 0; k < n; k++) {
		double p[3], e[3];
		*x += v_obj[0] * PERIOD_US * 1e-6;
		*y += v_obj[1] * PERIOD_US * 1e-6;
		at(r, *x, *y, -0.0015, p);
		put(r, 0, p);
		tick(r);
		if (stop_on_fault && r->out.state == IRDM_SAFETY_FAULT)
			return k + 1;
		vmax = fmax(vmax, r->out.dev[0].speed_m_per_s);
		irdm_v3_sub(e, r->out.dev[0].vel_m_per_s, v_dev);
		if (vec_err && k >= 50)
			*vec_err = fmax(*vec_err, irdm_v3_norm(e));
	}
	return vmax;
}

static void test_velocity(void **state)
{
	const double limit = 0.05, u = sqrt(0.5);
	double x = -0.012, y = -0.012, vmax, ticks, err = 0;
	struct rig r;
	(void)state;

	contact_rig(&r, slow_limit, limit);
	/* re-place the press at (-12, -12) mm, at 25 mm/s */
	for (int k = 1; k <= 680; k++) {
		double p[3];
		at(&r, x * k / 680, y * k / 680, -0.0015, p);
		put(&r, 0, p);
		tick(&r);
	}
	/* diagonally across the top: every joint moves */
	vmax = slide(&r, &x, &y, u, u, 0.7 * limit, 500, false, &err);
	print_message("  sliding at %.3f m/s: largest estimate %.4f m/s, vector error <= %.4f m/s (limit %.3f)\n",
		      0.7 * limit, vmax, err, limit);
	assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	assert_true(r.out.dev[0].contact);
	assert_true(fabs(vmax - 0.7 * limit) < 0.1 * limit);
	assert_true(err < 0.04 * limit);
	ticks = slide(&r, &x, &y, u, u, 1.5 * limit, 50, true, NULL);
	print_message("  at %.3f m/s the velocity fault came after %.0f ticks\n", 1.5 * limit, ticks);
	assert_true(ticks <= 10);
	assert_faulted(&r, IRDM_FAULT_VELOCITY);
	rig_close(&r);
}

static void small_force(struct irdm_ctrl_config *cfg, double f)
{
	cfg->limits.max_force_n = f;
}

static void weak_motors(struct irdm_ctrl_config *cfg, double nm)
{
	for (int j = 0; j < 3; j++)
		cfg->device[0].dev.torque_limit_nm[j] = nm;
}

static double cosine(const double a[3], const double b[3])
{
	return irdm_v3_dot(a, b) / (irdm_v3_norm(a) * irdm_v3_norm(b));
}

/* Clamps are flags, not faults: the force or torque at the limit, its direction kept. */
static void test_clamp(void **state)
{
	const double f_lim = 1e-3;
	double want[3], q[3], tip[3], p_obj[3], g[3], tau[3], worst = 0;
	struct rig r;
	(void)state;

	/* the force clamp */
	contact_rig(&r, small_force, f_lim);
	const struct irdm_ctrl_device_output *o = &r.out.dev[0];
	assert_true(irdm_v3_norm(o->force_obj_n) > 2 * f_lim); /* it did bind */
	assert_true(r.out.faults & IRDM_FAULT_CLAMP);
	assert_false(r.out.new_faults & IRDM_FAULT_CLAMP);
	assert_int_equal(r.ctrl.safety.faults, 0);
	assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	assert_true(fabs(irdm_v3_norm(o->force_n) - f_lim) <= 1e-12 * f_lim);
	/* along -R^T F: the object's force, turned back into the device frame */
	for (int a = 0; a < 3; a++)
		want[a] = -(rot[a] * o->force_obj_n[0] + rot[3 + a] * o->force_obj_n[1] +
			    rot[6 + a] * o->force_obj_n[2]);
	assert_true(cosine(o->force_n, want) > 1 - 1e-12);
	assert_true(o->scale < 0.5);
	rig_close(&r);

	/* the torque saturation: below the gravity torque, so it binds at once */
	contact_rig(&r, weak_motors, 0.01);
	o = &r.out.dev[0];
	tip_of_counts(&r, 0, p_obj, tip, q);
	irdm_device_force_to_torque(&r.cfg.device[0].dev, q, o->force_n, tau);
	irdm_device_gravity_torque(&r.cfg.device[0].dev, q, g);
	for (int j = 0; j < 3; j++) {
		tau[j] += g[j];
		worst = fmax(worst, fabs(o->torque_nm[j]) / 0.01);
	}
	assert_true(r.out.faults & IRDM_FAULT_CLAMP);
	assert_int_equal(r.out.state, IRDM_SAFETY_ENABLED);
	assert_true(fabs(worst - 1) <= 1e-12);
	assert_true(cosine(o->torque_nm, tau) > 1 - 1e-12);
	rig_close(&r);
}

/* ---- the device model in the loop ---- */

static void no_gravity(struct irdm_ctrl_config *cfg, double unused)
{
	(void)unused;
	cfg->device[0].dev.gravity_m_per_s2 = 0;
}

/*
 * Virtual work: tau . dq = f . dx for every dq, so tau_i is f dotted with
 * the central difference of FK along joint i (gravity off, so the torque
 * is the contact's alone).  At several contact points over the top face.
 */
static void test_force_to_torque_virtual_work(void **state)
{
	static const double where[][2] = { { 0, 0 }, { -0.012, 0.008 }, { 0.013, -0.01 }, { 0.006, 0.014 } };
	const double h = 1e-6;
	double worst = 0;
	(void)state;

	for (size_t w = 0; w < sizeof(where) / sizeof(where[0]); w++) {
		double q[3], tip[3], p_obj[3];
		struct rig r;

		contact_rig(&r, no_gravity, 0);
		/* over to the point, then 1.5 mm in */
		for (int k = 1; k <= 400; k++) {
			double p[3];
			at(&r, where[w][0] * k / 400, where[w][1] * k / 400, -0.0015, p);
			put(&r, 0, p);
			assert_int_equal(tick(&r), IRDM_OK);
		}
		const struct irdm_ctrl_device_output *o = &r.out.dev[0];
		assert_true(o->contact);
		assert_true(o->scale == 1);
		tip_of_counts(&r, 0, p_obj, tip, q);
		for (int j = 0; j < 3; j++) {
			double qp[3], qm[3], xp[3], xm[3], dx[3], ref;
			memcpy(qp, q, sizeof(qp));
			memcpy(qm, q, sizeof(qm));
			qp[j] += h;
			qm[j] -= h;
			irdm_device_fk(&r.cfg.device[0].dev, qp, xp);
			irdm_device_fk(&r.cfg.device[0].dev, qm, xm);
			for (int a = 0; a < 3; a++)
				dx[a] = (xp[a] - xm[a]) / (2 * h);
			ref = irdm_v3_dot(o->force_n, dx);
			worst = fmax(worst, fabs(o->torque_nm[j] - ref) /
						    (irdm_v3_norm(o->force_n) * 0.27));
		}
		rig_close(&r);
	}
	print_message("  J^T f against finite differences of FK: worst %.2e of |f| x reach\n", worst);
	assert_true(worst < 1e-9);
}

/*
 * Gravity compensation holds the simulated arm still: away from the object
 * (no contact), at a pose where gravity pulls on both elbow joints,
 * without Coulomb friction (it would hold the arm by itself), 3 s.  The
 * same run with the torque off lets it fall: the test can fail.
 */
static double hold_drift(bool enable)
{
	const double q0[3] = { 0.2, 0.3, 0.4 };
	struct irdm_sim_params sp;
	struct irdm_sim_device sim;
	double tip0[3], drift = 0;
	struct rig r;

	rig_config(&r, 1);
	memcpy(r.cfg.device[0].calib_q_rad, q0, sizeof(q0));
	rig_open(&r);
	r.cfg.obj_offset_m[2] += 1.0; /* the object a metre away */
	assert_int_equal(irdm_ctrl_init(&r.ctrl, &r.cfg, r.s), IRDM_OK);
	irdm_sim_params_default(&sp);
	memcpy(sp.q0_rad, q0, sizeof(q0));
	for (int j = 0; j < 3; j++)
		sp.coulomb_nm[j] = 0;
	assert_int_equal(irdm_sim_device_init(&sim, &r.cfg.device[0].dev, &sp), IRDM_OK);
	irdm_device_fk(&r.cfg.device[0].dev, q0, tip0);
	for (int k = 0; k < 3000; k++) {
		double q[3], qd[3], tip[3], d[3];
		assert_int_equal(irdm_sim_device_read_counts(&sim, r.in.counts[0]), IRDM_OK);
		r.in.cmd = k == 0 ? IRDM_CTRL_CMD_CALIBRATE : (k == 1 && enable ? IRDM_CTRL_CMD_ENABLE : 0);
		assert_int_equal(tick(&r), IRDM_OK);
		assert_int_equal(irdm_sim_device_set_torque(&sim, r.out.dev[0].torque_nm), IRDM_OK);
		if (k == 0)
			continue; /* held in its calibration rest until enabled */
		assert_int_equal(irdm_sim_device_step(&sim, PERIOD_US * 1e-6), IRDM_OK);
		irdm_sim_device_state(&sim, q, qd);
		irdm_device_fk(&r.cfg.device[0].dev, q, tip);
		irdm_v3_sub(d, tip, tip0);
		drift = fmax(drift, irdm_v3_norm(d));
		if (drift > 0.02)
			break; /* fallen: before it leaves the encoders' range */
	}
	assert_int_equal(r.out.state, enable ? IRDM_SAFETY_ENABLED : IRDM_SAFETY_READY);
	assert_false(r.out.dev[0].contact);
	rig_close(&r);
	return drift;
}

static void test_gravity_compensation_holds_the_arm(void **state)
{
	double held, fell;
	(void)state;

	held = hold_drift(true);
	fell = hold_drift(false);
	print_message("  tip drift over 3 s: %.3g m compensated, %.3g m with the torque off\n",
		      held, fell);
	assert_true(fell > 0.01);
	assert_true(held < 5e-5);
}

/* ---- contacts in the loop ---- */

/*
 * Down onto the top face, across it, and off: FREE above, TOUCH on the
 * first tick at or below the surface, the proxy on the surface under the
 * device while it slides (its triangle changes), RELEASE on the first tick
 * above, and no force after.
 */
static void test_proxy_follows_and_releases(void **state)
{
	int touch_at = -1, release_at = -1, tri_changes = 0, k = 0, bounces = 0, settled_at = 0;
	uint32_t tri = UINT32_MAX;
	double worst_xy = 0;
	struct rig r;
	(void)state;

	rig_config(&r, 1);
	rig_open(&r);
	rig_enable(&r);
	approach(&r, 0, -0.012, 0.004);
	/* 1: down at 10 mm/s from the gap to 1.5 mm deep */
	for (; k < 350; k++) {
		double p[3], p_obj[3], tip[3], q[3];
		at(&r, -0.012, 0.004, GAP_M - 1e-5 * (k + 1), p);
		put(&r, 0, p);
		tip_of_counts(&r, 0, p_obj, tip, q);
		assert_int_equal(tick(&r), IRDM_OK);
		int ev = r.out.dev[0].proxy_event;
		if (touch_at < 0) {
			/* the surface has not moved yet: free response zero */
			if (p_obj[2] > r.top_z) {
				assert_int_equal(ev, IRDM_PROXY_FREE);
				assert_false(r.out.dev[0].contact);
			} else {
				assert_int_equal(ev, IRDM_PROXY_TOUCH);
				touch_at = k;
			}
		} else if (ev != IRDM_PROXY_SLIDE) {
			/* the light surface first bounces off the coupling:
			 * release and touch alternate until it settles */
			assert_true(ev == IRDM_PROXY_RELEASE || ev == IRDM_PROXY_TOUCH);
			bounces += ev == IRDM_PROXY_RELEASE;
			settled_at = k + 1;
		}
	}
	assert_true(touch_at > 0);
	print_message("  touch after %d ticks, %d bounces, settled %d ticks after the touch\n",
		      touch_at, bounces, settled_at - touch_at);
	assert_true(settled_at - touch_at <= 60);
	assert_true(k - settled_at >= 60); /* then in contact for good */
	assert_true(r.out.dev[0].contact);
	/* pushed: the object is pushed down, the device up (device +y) */
	assert_true(r.out.dev[0].force_obj_n[2] < 0);
	assert_true(r.out.dev[0].force_n[1] > 0);
	/* 2: across, 24 mm at 20 mm/s */
	for (int s = 1; s <= 1200; s++, k++) {
		double p[3], p_obj[3], tip[3], q[3], d;
		at(&r, -0.012 + 2e-5 * s, 0.004, -0.0015, p);
		put(&r, 0, p);
		tip_of_counts(&r, 0, p_obj, tip, q);
		assert_int_equal(tick(&r), IRDM_OK);
		const struct irdm_ctrl_device_output *o = &r.out.dev[0];
		assert_int_equal(o->proxy_event, IRDM_PROXY_SLIDE);
		assert_true(o->contact);
		assert_true(o->depth_m < 0);
		d = hypot(o->proxy_m[0] - p_obj[0], o->proxy_m[1] - p_obj[1]);
		worst_xy = fmax(worst_xy, d);
		if (o->tri != tri)
			tri_changes += tri != UINT32_MAX;
		tri = o->tri;
	}
	print_message("  sliding: %d triangle changes, proxy within %.3g m of the device across the surface\n",
		      tri_changes, worst_xy);
	assert_true(tri_changes >= 2);
	assert_true(worst_xy < 2e-4);
	/* 3: up and away, 10 um a tick to 2 mm above the top face */
	for (int s = 1; s <= 350; s++, k++) {
		double p[3];
		at(&r, 0.012, 0.004, -0.0015 + 1e-5 * s, p);
		put(&r, 0, p);
		assert_int_equal(tick(&r), IRDM_OK);
		int ev = r.out.dev[0].proxy_event;
		if (release_at < 0 && ev == IRDM_PROXY_RELEASE) {
			release_at = s;
			/* the push ended in the tick that saw the device leave */
			assert_false(r.out.dev[0].contact);
			for (int a = 0; a < 3; a++)
				assert_true(r.out.dev[0].force_n[a] == 0 &&
					    r.out.dev[0].force_obj_n[a] == 0);
		} else if (release_at < 0) {
			assert_int_equal(ev, IRDM_PROXY_SLIDE);
		} else if (p[2] > r.top_z + 0.001) {
			/* clear of the (rebounding) surface: free, no force */
			assert_int_equal(ev, IRDM_PROXY_FREE);
			assert_false(r.out.dev[0].contact);
			assert_true(irdm_v3_norm(r.out.dev[0].force_n) == 0);
		}
	}
	assert_true(release_at > 0);
	print_message("  released %d ticks (%.2f mm) into the lift\n", release_at, 1e-2 * release_at);
	rig_close(&r);
}

/* Two devices, two contacts: each device renders its own slot's force. */
static void engine_disp(const void *ctx, uint32_t row, double u_m[3])
{
	irdm_engine_node_disp(ctx, row, u_m);
}

/*
 * The proxy's closest-point query grows the BVH boxes by the engine's
 * per-tick bound on |u| (irdm_engine_disp_bound) instead of the configured
 * 5 cm: every free tick must answer exactly as the configured bound does.
 * Pressed, pulled off (the surface rings), then lowered elsewhere onto the
 * ringing surface, bouncing: before each tick with the proxy inactive, the
 * query with the configured bound on the same engine state is the reference.
 */
static void test_free_query_matches_the_configured_bound(void **state)
{
	struct rig r;
	int compared = 0, touches_moving = 0;

	(void)state;
	rig_config(&r, 1);
	rig_open(&r);
	rig_enable(&r);
	press(&r, 0, 0, 0.004, 300);
	for (int k = 0; k < 2600; k++) {
		double p[3], p_obj[3], tip[3], q[3], dz;
		struct irdm_contact_hit hit;
		const struct irdm_contact_disp disp = { .fn = engine_disp, .ctx = r.s->eng };

		/* up 4 mm + 1 mm in 50 ticks, across 15 mm, then down 20 um a tick */
		if (k < 50)
			dz = -0.004 + 0.005 * (k + 1) / 50;
		else
			dz = fmax(0.001 - 2e-5 * (k > 300 ? k - 300 : 0), -0.003);
		at(&r, k < 300 ? 0.015 * k / 300 : 0.015, 0, dz, p);
		put(&r, 0, p);
		tip_of_counts(&r, 0, p_obj, tip, q);
		bool inactive = !r.ctrl.dev[0].px.active;
		double bound = irdm_engine_disp_bound(r.s->eng);
		int ref = irdm_contact_closest(&r.ctrl.cm, &disp, r.cfg.proxy.max_disp_m, p_obj,
					       r.cfg.proxy.radius_m, &hit);
		if (tick(&r) != IRDM_OK)
			fail_msg("tick %d: fault 0x%x", k, r.out.cause);
		if (!inactive || k < 50)
			continue;
		const struct irdm_ctrl_device_output *o = &r.out.dev[0];
		bool touch = ref == 1 && hit.dist_m <= 0;
		assert_int_equal(o->proxy_event, touch ? IRDM_PROXY_TOUCH : IRDM_PROXY_FREE);
		if (touch) {
			assert_int_equal(o->tri, hit.tri);
			assert_memory_equal(o->bary, hit.bary, sizeof(hit.bary));
			assert_memory_equal(o->proxy_m, hit.point_m, sizeof(hit.point_m));
			touches_moving += bound > 1e-5;
		}
		compared++;
	}
	print_message("  %d free queries compared, %d touches of a moving surface\n", compared,
		      touches_moving);
	assert_true(compared > 200 && touches_moving >= 1);
	rig_close(&r);
}

static void test_two_devices_two_contacts(void **state)
{
	struct rig r;
	(void)state;

	rig_config(&r, 2);
	rig_open(&r);
	rig_enable(&r);
	approach(&r, 0, -0.01, 0.002);
	approach(&r, 1, 0.01, -0.003);
	for (int k = 1; k <= 300; k++) {
		double p[3];
		at(&r, -0.01, 0.002, GAP_M - (GAP_M + 0.0015) * k / 300, p);
		put(&r, 0, p);
		at(&r, 0.01, -0.003, GAP_M - (GAP_M + 0.001) * k / 300, p);
		put(&r, 1, p);
		assert_int_equal(tick(&r), IRDM_OK);
	}
	for (int k = 0; k < 200; k++) /* settled (the first touch bounces) */
		assert_int_equal(tick(&r), IRDM_OK);
	for (unsigned i = 0; i < 2; i++) {
		const struct irdm_ctrl_device_output *o = &r.out.dev[i];
		const double *f = irdm_engine_contact(r.s->eng, i)->force_n;
		assert_true(o->contact);
		assert_true(irdm_v3_norm(f) > 0);
		assert_memory_equal(o->force_obj_n, f, sizeof(o->force_obj_n));
		for (int a = 0; a < 3; a++)
			assert_true(o->force_n[a] == -(rot[a] * f[0] + rot[3 + a] * f[1] +
						       rot[6 + a] * f[2]));
	}
	/* the deeper press pushes harder */
	assert_true(irdm_v3_norm(r.out.dev[0].force_n) > irdm_v3_norm(r.out.dev[1].force_n));
	/* lift device 0 only */
	for (int k = 1; k <= 400; k++) {
		double p[3];
		at(&r, -0.01, 0.002, -0.0015 + 1e-5 * k, p);
		put(&r, 0, p);
		assert_int_equal(tick(&r), IRDM_OK);
	}
	assert_false(r.out.dev[0].contact);
	assert_true(r.out.dev[1].contact);
	assert_int_equal(irdm_engine_contact(r.s->eng, 0)->mode, IRDM_CONTACT_OFF);
	assert_int_not_equal(irdm_engine_contact(r.s->eng, 1)->mode, IRDM_CONTACT_OFF);
	rig_close(&r);
}

/* ---- rigid coupling: the controller is the engine driven directly ---- */

/*
 * With coupling_k = 0 the engine imposes the contact point's displacement:
 * target = device position (object frame) - the site's rest point.  A
 * second engine on the same image is driven directly with that contact
 * trajectory -- the site rebuilt from the proxy's triangle and weights by
 * irdm_engine_site_point(), the target from the test's own counts -> FK ->
 * placement chain -- and must give the controller's forces to 1e-9
 * relative.  (irdm replay drives the engine the same way; the integrator
 * extends this to it.)
 */
static void test_rigid_coupling_reproduces_the_engine(void **state)
{
	struct irdm_session_config sc = { .deform = false };
	struct irdm_session *ref;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	double worst = 0, f_peak = 0, worst_p = 0;
	unsigned touches = 0, n = 0;
	char err[512];
	struct rig r;
	(void)state;

	rig_config(&r, 1);
	irdm_engine_config_default(&r.cfg.engine);
	assert_true(r.cfg.engine.coupling_k_n_per_m == 0);
	rig_open(&r);
	sc.engine = r.cfg.engine;
	if (irdm_session_open(&ref, tick_image_path(), &sc, err, sizeof(err)))
		fail_msg("session: %s", err);
	rig_enable(&r);
	approach(&r, 0, -0.01, 0.003);
	memset(cmd, 0, sizeof(cmd));
	for (uint64_t k = 0; k < r.out.tick; k++) /* the set-up ticks: no contact */
		assert_int_equal(irdm_engine_tick(ref->eng, cmd), IRDM_OK);
	/* down, across, up, over, down again, up: 1600 ticks */
	for (int k = 0; k < 1600; k++) {
		double p[3], p_obj[3], tip[3], q[3], dx, dz;
		int seg = k / 200, s = k % 200;
		static const double x0[] = { -0.01, -0.01, 0.002, 0.002, 0.002, 0.006, 0.006, 0.006 };
		static const double x1[] = { -0.01, 0.002, 0.002, 0.002, 0.006, 0.006, 0.006, 0.006 };
		static const double z0[] = { GAP_M, -0.0015, -0.0015, 0.001, 0.001, 0.001, -0.001, -0.001 };
		static const double z1[] = { -0.0015, -0.0015, 0.001, 0.001, 0.001, -0.001, -0.001, 0.001 };
		dx = x0[seg] + (x1[seg] - x0[seg]) * (s + 1) / 200;
		dz = z0[seg] + (z1[seg] - z0[seg]) * (s + 1) / 200;
		at(&r, dx, 0.003, dz, p);
		put(&r, 0, p);
		assert_int_equal(tick(&r), IRDM_OK);
		const struct irdm_ctrl_device_output *o = &r.out.dev[0];
		tip_of_counts(&r, 0, p_obj, tip, q);
		for (int a = 0; a < 3; a++)
			worst_p = fmax(worst_p, fabs(o->tip_obj_m[a] - p_obj[a]));
		memset(cmd, 0, sizeof(cmd));
		if (o->proxy_event == IRDM_PROXY_TOUCH || o->proxy_event == IRDM_PROXY_SLIDE) {
			struct irdm_contact_site site;
			assert_int_equal(irdm_engine_site_point(ref->eng, o->tri, o->bary, &site), IRDM_OK);
			memcpy(site.normal, o->normal, sizeof(site.normal));
			assert_int_equal(irdm_engine_contact_begin(ref->eng, 0, &site, IRDM_CONTACT_PUSH),
					 IRDM_OK);
			cmd[0].mode = IRDM_CONTACT_PUSH;
			irdm_v3_sub(cmd[0].target_m, p_obj, site.rest_m);
			touches += o->proxy_event == IRDM_PROXY_TOUCH;
		}
		assert_int_equal(irdm_engine_tick(ref->eng, cmd), IRDM_OK);
		const double *f = irdm_engine_contact(ref->eng, 0)->force_n;
		for (int a = 0; a < 3; a++) {
			worst = fmax(worst, fabs(o->force_obj_n[a] - f[a]));
			f_peak = fmax(f_peak, fabs(f[a]));
		}
		n += irdm_v3_norm(f) > 0;
	}
	print_message("  %u ticks with force (max %.4g N), %u touches: largest difference %.3g N (%.2g relative); positions within %.2g m\n",
		      n, f_peak, touches, worst, worst / f_peak, worst_p);
	irdm_session_close(ref);
	rig_close(&r);
	assert_true(touches >= 2); /* two presses (and bounces) */
	assert_true(n > 500);
	assert_true(f_peak > 0);
	assert_true(worst <= 1e-9 * f_peak);
	assert_true(worst_p <= 1e-15);
}

/* ---- real time: the whole tick, every path, no system call, no allocation ---- */

struct rt_result {
	uint32_t magic;
	int prctl_errno;
	unsigned long ticks, bad, touches, slides, site_changes, releases, faults, resets,
		holds, nonzero_in_fault, allocs;
	double max_f;
};

#define RT_MAGIC 0x43544c31u
#define RT_CYCLES 5

static void rt_tick(struct rig *r, struct rt_result *res, uint32_t *last_tri, double last_bary[3])
{
	const struct irdm_ctrl_device_output *o = &r->out.dev[0];

	irdm_ctrl_tick(&r->ctrl, &r->in, &r->out);
	r->in.cmd = 0;
	r->in.prev_latency_ns = r->in.prev_compute_ns = 0;
	res->ticks++;
	res->touches += o->proxy_event == IRDM_PROXY_TOUCH;
	res->releases += o->proxy_event == IRDM_PROXY_RELEASE;
	if (o->proxy_event == IRDM_PROXY_SLIDE) {
		res->slides++;
		res->site_changes += o->tri != *last_tri || memcmp(o->bary, last_bary, 3 * sizeof(double));
	}
	*last_tri = o->tri;
	memcpy(last_bary, o->bary, 3 * sizeof(double));
	res->holds += r->out.held;
	if (r->out.state != IRDM_SAFETY_ENABLED)
		for (int j = 0; j < 3; j++)
			res->nonzero_in_fault += o->torque_nm[j] != 0;
	if (irdm_v3_norm(o->force_n) > res->max_f)
		res->max_f = irdm_v3_norm(o->force_n);
}

/* Move to (dx, dz) over n ticks from (x0, z0). */
static void rt_move(struct rig *r, struct rt_result *res, double x0, double z0, double x1,
		    double z1, int n, uint32_t *tri, double bary[3])
{
	for (int k = 1; k <= n; k++) {
		double p[3];
		at(r, x0 + (x1 - x0) * k / n, 0.003, z0 + (z1 - z0) * k / n, p);
		if (put_counts(r, 0, p))
			res->bad++;
		rt_tick(r, res, tri, bary);
	}
}

/*
 * One cycle of every path: free, touch, slide (a new site every tick),
 * release, an overrun (torque held), a NaN encoder fault and its reset, a
 * watchdog fault and its reset.  The counts are re-enabled each time.
 */
static void rt_cycle(struct rig *r, struct rt_result *res)
{
	uint32_t tri = UINT32_MAX;
	double bary[3] = { 0 };

	rt_move(r, res, -0.01, GAP_M, -0.01, GAP_M, 20, &tri, bary);     /* free */
	rt_move(r, res, -0.01, GAP_M, -0.01, -0.0015, 100, &tri, bary);  /* touch */
	rt_move(r, res, -0.01, -0.0015, 0.01, -0.0015, 400, &tri, bary); /* slide */
	r->in.prev_compute_ns = PERIOD_NS + 1;                           /* overrun */
	rt_move(r, res, 0.01, -0.0015, 0.01, -0.0015, 1, &tri, bary);
	rt_move(r, res, 0.01, -0.0015, 0.01, GAP_M, 200, &tri, bary); /* release */
	rt_move(r, res, 0.01, GAP_M, -0.01, GAP_M, 200, &tri, bary);
	r->in.counts[0][0] = IRDM_CTRL_COUNT_NAN; /* fault */
	rt_tick(r, res, &tri, bary);
	res->faults += r->out.state == IRDM_SAFETY_FAULT;
	rt_move(r, res, -0.01, GAP_M, -0.01, GAP_M, 1, &tri, bary);
	r->in.cmd = IRDM_CTRL_CMD_RESET; /* reset */
	rt_tick(r, res, &tri, bary);
	res->resets += r->out.state == IRDM_SAFETY_READY;
	r->in.cmd = IRDM_CTRL_CMD_ENABLE;
	rt_tick(r, res, &tri, bary);
	r->in.prev_compute_ns = 1000000000ull; /* watchdog */
	rt_tick(r, res, &tri, bary);
	res->faults += r->out.state == IRDM_SAFETY_FAULT;
	r->in.cmd = IRDM_CTRL_CMD_RESET | IRDM_CTRL_CMD_ENABLE;
	rt_tick(r, res, &tri, bary);
	res->resets += r->out.state == IRDM_SAFETY_ENABLED;
}

/* The signal at the end: fault, no reset, off. */
static void rt_stop(struct rig *r, struct rt_result *res)
{
	uint32_t tri = UINT32_MAX;
	double bary[3] = { 0 };

	rt_move(r, res, -0.01, GAP_M, -0.01, -0.0015, 100, &tri, bary);
	r->in.cmd = IRDM_CTRL_CMD_SIGNAL;
	rt_tick(r, res, &tri, bary);
	res->faults += r->out.state == IRDM_SAFETY_FAULT;
	r->in.cmd = IRDM_CTRL_CMD_RESET;
	rt_tick(r, res, &tri, bary);
	res->bad += r->out.state != IRDM_SAFETY_FAULT;
	r->in.cmd = IRDM_CTRL_CMD_SHUTDOWN;
	rt_tick(r, res, &tri, bary);
	res->bad += r->out.state != IRDM_SAFETY_OFF;
}

struct strict_job {
	struct rig *r;
	bool slip; /* make one system call: the control */
};

/* Exit status 0, or killed by SIGKILL if it made a system call. */
static void strict_child(void *arg, int fd)
{
	const struct strict_job *job = arg;
	struct rt_result res = { .magic = RT_MAGIC }, warm = { 0 };

	rt_cycle(job->r, &warm); /* every path once: first touches done */
	res.prctl_errno = strict_enter();
	if (res.prctl_errno)
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	alloc_arm();
	for (int c = 0; c < RT_CYCLES; c++) {
		rt_cycle(job->r, &res);
		if (job->slip && c == 1)
			syscall(SYS_getppid);
	}
	rt_stop(job->r, &res);
	res.allocs = alloc_calls();
	strict_exit(fd, &res, sizeof(res), 0);
}

/* An image and an engine configuration the strict-mode run covers. */
struct rt_variant {
	const char *name;
	const char *path; /* NULL: IRDM_TICK_IMAGE */
	enum irdm_solve_mode solve;
	bool rigid;    /* coupling_k = 0 */
	bool floating; /* the object drifts off: fewer touches */
};

static char rt_dir[64];
static char fir_path[128], float_path[128];

static struct rt_variant variants[] = {
	{ "modal, haptic coupling, coupled solve", NULL, IRDM_SOLVE_COUPLED, false, false },
	{ "modal, haptic coupling, per-vertex solve", NULL, IRDM_SOLVE_PER_VERTEX, false, false },
	{ "modal, rigid coupling", NULL, IRDM_SOLVE_COUPLED, true, false },
	{ "FIR T = 100", fir_path, IRDM_SOLVE_COUPLED, false, false },
	{ "floating cube, modal", float_path, IRDM_SOLVE_COUPLED, false, true },
};

static int run_strict(bool slip, struct rt_result *res, const struct rt_variant *v)
{
	struct rig r;
	struct strict_job job = { &r, slip };
	size_t got;
	int status;

	rig_config(&r, 1);
	r.path = v->path;
	r.cfg.engine.solve = v->solve;
	if (v->rigid)
		irdm_engine_config_default(&r.cfg.engine);
	rig_open(&r);
	rig_enable(&r);
	status = strict_run(strict_child, &job, res, sizeof(*res), &got);
	rig_close(&r);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE) {
		print_message("  seccomp strict mode not available (errno %d): skipped\n",
			      res->prctl_errno);
		skip();
	}
	return status;
}

static void test_tick_makes_no_system_call_and_no_allocation(void **state)
{
	(void)state;

	for (size_t i = 0; i < sizeof(variants) / sizeof(variants[0]); i++) {
		const struct rt_variant *v = &variants[i];
		struct rt_result res;
		int status = run_strict(false, &res, v);

		if (WIFSIGNALED(status))
			fail_msg("%s: strict-mode child died of signal %d (SIGKILL: a system call in the tick)",
				 v->name, WTERMSIG(status));
		assert_true(WIFEXITED(status));
		assert_int_equal(WEXITSTATUS(status), 0);
		assert_int_equal(res.magic, RT_MAGIC);
		print_message("  %s: %lu ticks, %lu touches, %lu slide ticks (%lu new sites), %lu releases, %lu holds, %lu faults, %lu resets, max |f| %.3g N, %lu allocator calls%s\n",
			      v->name, res.ticks, res.touches, res.slides, res.site_changes,
			      res.releases, res.holds, res.faults, res.resets, res.max_f, res.allocs,
			      alloc_counting() ? "" : " (not counted: ASan owns the allocator)");
		assert_int_equal(res.bad, 0);
		assert_int_equal(res.allocs, 0);
		assert_int_equal(res.nonzero_in_fault, 0);
		/* every path ran: it cannot pass by doing nothing */
		assert_true(res.touches >= (v->floating ? 1 : RT_CYCLES + 1));
		assert_true(res.releases >= (v->floating ? 1 : RT_CYCLES));
		assert_int_equal(res.holds, RT_CYCLES);
		assert_int_equal(res.faults, 2 * RT_CYCLES + 1);
		assert_int_equal(res.resets, 2 * RT_CYCLES);
		assert_true(res.slides > 100);
		assert_true(res.site_changes >= res.slides - res.slides / 20);
		assert_true(res.max_f > 0);
	}
}

static void test_a_system_call_is_caught(void **state)
{
	struct rt_result res;
	int status;
	(void)state;

	status = run_strict(true, &res, &variants[0]);
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), SIGKILL);
}

/* The FIR and floating images of the strict-mode run. */
static int make_images(void **state)
{
	struct irdm_image img;
	(void)state;

	strcpy(rt_dir, "/tmp/irdm-ctrl-XXXXXX");
	if (!mkdtemp(rt_dir))
		return -1;
	snprintf(fir_path, sizeof(fir_path), "%s/fir.img", rt_dir);
	snprintf(float_path, sizeof(float_path), "%s/float.img", rt_dir);
	efx_image(&img, fir_path, "mesh", "box:0.04,0.04,0.08", "resolution", "2,2,4",
		  "fixed", "z<=0", "touch", "z>=0.08", "display", "surface",
		  "representation", "fir:100", "uncertified", "yes", NULL);
	irdm_image_unmap(&img);
	efx_image(&img, float_path, "mesh", "cube", "resolution", "3,3,3", "floating", "yes",
		  "representation", "modal:all", "touch", "surface", "display", "surface", NULL);
	irdm_image_unmap(&img);
	return 0;
}

static int remove_images(void **state)
{
	(void)state;
	unlink(fir_path);
	unlink(float_path);
	rmdir(rt_dir);
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_defaults_are_the_board_defaults),
		cmocka_unit_test(test_config_errors),
		cmocka_unit_test(test_transitions_through_the_tick),
		cmocka_unit_test(test_signal_mid_contact),
		cmocka_unit_test(test_hal_failures),
		cmocka_unit_test(test_enable_inside_fades_in),
		cmocka_unit_test(test_encoder_nan_and_range),
		cmocka_unit_test(test_watchdog),
		cmocka_unit_test(test_overruns),
		cmocka_unit_test(test_workspace),
		cmocka_unit_test(test_velocity),
		cmocka_unit_test(test_clamp),
		cmocka_unit_test(test_force_to_torque_virtual_work),
		cmocka_unit_test(test_gravity_compensation_holds_the_arm),
		cmocka_unit_test(test_proxy_follows_and_releases),
		cmocka_unit_test(test_free_query_matches_the_configured_bound),
		cmocka_unit_test(test_two_devices_two_contacts),
		cmocka_unit_test(test_rigid_coupling_reproduces_the_engine),
		cmocka_unit_test(test_tick_makes_no_system_call_and_no_allocation),
		cmocka_unit_test(test_a_system_call_is_caught),
	};

	return cmocka_run_group_tests(tests, make_images, remove_images);
}
