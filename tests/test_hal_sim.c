/* SPDX-License-Identifier: MIT */
/*
 * The HAL (irdm/hal.h) with the simulator's back-end, driven through the
 * ops table only, the way the force loop will: registration and look-up by
 * name, the life cycle and every documented error, a force on the tip that
 * moves it the expected way, safe-off, a fault that every op reports, and
 * the virtual user's hand that an attached script puts on the arm at each
 * read.
 * The test reaches behind the ops only to inject the fault and to read the
 * torque that reached the simulated motors.
 */
#include <math.h>
#include <setjmp.h>
#include <stdalign.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/board.h"
#include "irdm/device.h"
#include "irdm/error.h"
#include "irdm/hal/hal.h"
#include "irdm/sim/hal_sim.h"
#include "irdm/sim/sim_user.h"
#include "irdm/sim/sim_user_push.h"
#include "irdm/posix/board_file.h"

#define PERIOD_S 1e-3

static alignas(max_align_t) unsigned char mem[64 * 1024];
static struct irdm_device_config device;
static struct irdm_hal_config cfg;
static struct irdm_hal_dev dev;

static int setup(void **state)
{
	(void)state;
	irdm_device_config_default(&device);
	cfg = (struct irdm_hal_config){ .device = &device, .options = NULL, .period_s = PERIOD_S };
	assert_int_equal(irdm_hal_register(&irdm_hal_sim_backend), IRDM_OK);
	return 0;
}

static void open_sim(const char *options)
{
	cfg.options = options;
	assert_int_equal(irdm_hal_init(&dev, "sim", &cfg, mem, sizeof(mem)), IRDM_OK);
	assert_int_equal(irdm_hal_open(&dev), IRDM_OK);
}

static void tip_of(const struct irdm_hal_joint_state *st, double tip[3])
{
	double q[3];

	assert_int_equal(irdm_device_angles_from_counts(&device, st->counts, q), IRDM_OK);
	irdm_device_fk(&device, q, tip);
}

static void motor_torque(double tau[3])
{
	irdm_sim_device_motor_torque(irdm_hal_sim_device(&dev), tau);
}

/* ---- registration ----------------------------------------------------------- */

static int nop(struct irdm_hal_dev *d)
{
	(void)d;
	return IRDM_OK;
}

static void test_registry(void **state)
{
	static const struct irdm_hal_ops half = { .open = nop };
	static const struct irdm_hal_backend incomplete = { .name = "half", .ops = &half };
	static const struct irdm_hal_backend impostor = { .name = "sim" };
	struct irdm_hal_backend twin = irdm_hal_sim_backend;
	(void)state;

	assert_ptr_equal(irdm_hal_find("sim"), &irdm_hal_sim_backend);
	assert_null(irdm_hal_find("can"));
	assert_null(irdm_hal_find(NULL));
	assert_int_equal(irdm_hal_register(&irdm_hal_sim_backend), IRDM_OK); /* again */
	assert_int_equal(irdm_hal_register(&incomplete), IRDM_EINVAL);
	assert_int_equal(irdm_hal_register(&impostor), IRDM_EINVAL);
	assert_int_equal(irdm_hal_register(NULL), IRDM_EINVAL);
	assert_int_equal(irdm_hal_register(&twin), IRDM_EBUSY); /* name taken */

	assert_int_equal(irdm_hal_init(&dev, "can", &cfg, mem, sizeof(mem)), IRDM_ENOTSUP);
	assert_true(irdm_hal_sim_backend.data_size <= sizeof(mem));
	assert_int_equal(irdm_hal_init(&dev, "sim", &cfg, mem, irdm_hal_sim_backend.data_size - 1),
			 IRDM_ENOMEM);
	assert_int_equal(irdm_hal_init(&dev, "sim", &cfg, mem + 1, sizeof(mem) - 1), IRDM_EINVAL);
	assert_int_equal(irdm_hal_init(&dev, "sim", NULL, mem, sizeof(mem)), IRDM_EINVAL);
}

/* ---- life cycle ------------------------------------------------------------- */

static void test_life_cycle_errors(void **state)
{
	struct irdm_hal_joint_state st;
	uint32_t faults = 7;
	const double tau[3] = { 0.1, 0, 0 };
	(void)state;

	assert_int_equal(irdm_hal_init(&dev, "sim", &cfg, mem, sizeof(mem)), IRDM_OK);
	/* nothing works before open */
	assert_int_equal(irdm_hal_start(&dev), IRDM_EINVAL);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_EINVAL);
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_EINVAL);
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_EINVAL);
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK); /* always allowed */
	/* bad options, bad configuration */
	cfg.options = "write_delay=2 warp=9";
	assert_int_equal(irdm_hal_open(&dev), IRDM_EINVAL);
	cfg.options = "read_delay=99";
	assert_int_equal(irdm_hal_open(&dev), IRDM_EINVAL);
	cfg.options = "substeps=x";
	assert_int_equal(irdm_hal_open(&dev), IRDM_EINVAL);
	cfg.options = NULL;
	cfg.period_s = 0;
	assert_int_equal(irdm_hal_open(&dev), IRDM_EINVAL);
	cfg.period_s = PERIOD_S;

	open_sim("substeps=20, read_delay=0");
	assert_int_equal(irdm_hal_open(&dev), IRDM_EBUSY);
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_OK);
	assert_int_equal(faults, 0);
	/* open: reads work (calibration), writes do not */
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(st.seq, 1);
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_EINVAL);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_OK);
	/* a non-finite torque is refused and zero goes out instead */
	assert_int_equal(irdm_hal_write(&dev, (double[3]){ 0.1, NAN, 0 }), IRDM_EFAULT);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(st.seq, 2);
	{
		double m[3];

		motor_torque(m);
		assert_true(m[0] == 0 && m[1] == 0 && m[2] == 0);
	}
	irdm_hal_close(&dev);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_EINVAL);
	open_sim(NULL); /* may open again */
	irdm_hal_close(&dev);
}

/* ---- motion ----------------------------------------------------------------- */

static void test_force_moves_tip(void **state)
{
	struct irdm_hal_joint_state st;
	double tip0[3], tip[3], q[3], g[3], tau[3];
	const double f[3] = { 0.3, 0, 0 }; /* push toward +x */
	(void)state;

	open_sim(NULL);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	tip_of(&st, tip0);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	for (int k = 0; k < 60; k++) {
		/* the loop's sum: gravity compensation + J^T F, saturated */
		assert_int_equal(irdm_device_angles_from_counts(&device, st.counts, q), IRDM_OK);
		irdm_device_gravity_torque(&device, q, g);
		irdm_device_force_to_torque(&device, q, f, tau);
		for (int i = 0; i < 3; i++)
			tau[i] += g[i];
		assert_int_equal(irdm_device_torque_saturate(&device, tau, tau, NULL), IRDM_OK);
		assert_int_equal(irdm_hal_write(&dev, tau), IRDM_OK);
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	}
	tip_of(&st, tip);
	printf("0.3 N along +x for 60 ms: tip moved (%.2f, %.2f, %.2f) mm\n", 1e3 * (tip[0] - tip0[0]),
	       1e3 * (tip[1] - tip0[1]), 1e3 * (tip[2] - tip0[2]));
	assert_true(tip[0] - tip0[0] > 3e-3);
	/* sideways drift measured 2.5 % of the push: margin 2x */
	assert_true(fabs(tip[1] - tip0[1]) < 0.05 * (tip[0] - tip0[0]));
	assert_true(fabs(tip[2] - tip0[2]) < 0.05 * (tip[0] - tip0[0]));

	/* safe-off: zero torque at the motors from the next tick, writes refused */
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, tau), IRDM_EINVAL);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	motor_torque(tau);
	assert_true(tau[0] == 0 && tau[1] == 0 && tau[2] == 0);
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK); /* twice is fine */
	/* only start re-enables */
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, (double[3]){ 0.2, 0, 0 }), IRDM_OK);
	irdm_hal_close(&dev);
}

static void test_delay_option(void **state)
{
	struct irdm_hal_joint_state st;
	double m[3];
	(void)state;

	/* write_delay=3: the torque reaches the motors on the 4th read after it */
	open_sim("write_delay=3");
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, (double[3]){ 0.3, 0, 0 }), IRDM_OK);
	for (int k = 1; k <= 4; k++) {
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
		motor_torque(m);
		assert_true(m[0] == (k == 4 ? 0.3 : 0.0));
	}
	/* safe-off does not wait for the bus */
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	motor_torque(m);
	assert_true(m[0] == 0);
	irdm_hal_close(&dev);
}

/* ---- faults ----------------------------------------------------------------- */

static void test_injected_fault(void **state)
{
	struct irdm_hal_joint_state st = { .seq = 42 };
	uint32_t faults = 0;
	double m[3];
	(void)state;

	open_sim(NULL);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, (double[3]){ 0.3, 0.2, 0.1 }), IRDM_OK);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(irdm_hal_sim_inject_fault(&dev, IRDM_HAL_FAULT_DRIVE), IRDM_OK);
	/* every op reports it, the torque is already off, and it stays latched */
	st.seq = 42;
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_EHW);
	assert_int_equal(st.seq, 42); /* untouched */
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_EHW);
	assert_int_equal(faults, IRDM_HAL_FAULT_DRIVE);
	assert_int_equal(irdm_hal_write(&dev, (double[3]){ 0.3, 0, 0 }), IRDM_EHW);
	motor_torque(m);
	assert_true(m[0] == 0 && m[1] == 0 && m[2] == 0);
	assert_int_equal(irdm_hal_safe_off(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_EHW);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_EHW);
	/* close clears it */
	irdm_hal_close(&dev);
	assert_int_equal(irdm_hal_sim_inject_fault(&dev, IRDM_HAL_FAULT_LINK), IRDM_EINVAL);
	assert_null(irdm_hal_sim_device(&dev));
	open_sim(NULL);
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_OK);
	irdm_hal_close(&dev);
}

/* A count outside the range the controller accepts (device config). */
static bool out_of_range(const int32_t *counts)
{
	for (int i = 0; i < 3; i++)
		if (counts[i] < device.count_min[i] || counts[i] > device.count_max[i])
			return true;
	return false;
}

static void test_encoder_out_of_range(void **state)
{
	struct irdm_hal_joint_state st = { .seq = 0 };
	int rc = IRDM_OK, k;
	(void)state;

	/* no compensation and no end stops: the arm falls out of the range
	 * the controller accepts; the read goes on giving the counts (the
	 * controller's encoder check reports them, as its own cause, not as a
	 * failed read).  With its stops it rests on one, within the range. */
	open_sim(NULL);
	for (k = 0; k < 2000; k++) {
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
		assert_false(out_of_range(st.counts));
	}
	irdm_hal_close(&dev);
	open_sim("end_stops=0");
	for (k = 0; k < 5000 && rc == IRDM_OK && !out_of_range(st.counts); k++)
		rc = irdm_hal_read(&dev, &st);
	printf("unpowered arm left the encoder range after %d ticks\n", k);
	assert_int_equal(rc, IRDM_OK);
	assert_true(out_of_range(st.counts));
	irdm_hal_close(&dev);
}

/* ---- the virtual user ------------------------------------------------------- */

/*
 * An attached script's hand pushes the arm at the start of each read, at
 * tick x period: bit for bit the arm a loop gets that pushes before each
 * read at its clock's time (the loop irdm-fw ran before the push moved
 * behind the HAL).  Also: the hand moves the arm, and open forgets it.
 */
static void test_attached_user_pushes_at_tick_time(void **state)
{
	static struct irdm_sim_user user;
	static struct irdm_board board;
	struct irdm_device_config arm_cfg;
	struct irdm_sim_device ref;
	struct irdm_sim_params p;
	struct irdm_hal_joint_state st;
	struct irdm_hal_config bcfg;
	double tip[3], home[3], q[3], qd[3], q_ref[3], qd_ref[3], q_free[3];
	char err[256];
	(void)state;

	assert_int_equal(irdm_board_load(&board, "boards/sim-phantom.board", err, sizeof(err)),
			 IRDM_OK);
	irdm_board_device(&board, 0, &arm_cfg);
	irdm_device_fk(&arm_cfg, board.calibration_pose_rad, tip);
	irdm_board_device_to_object(&board, tip, home);
	assert_int_equal(irdm_sim_user_parse(&user, "press", "place 1 at home\n"
							     "move 1 by 0,0,-0.02 over 0.1\n",
					     err,
					     sizeof(err)),
			 IRDM_OK);
	assert_int_equal(irdm_sim_user_start(&user, 0, home, "press", err, sizeof(err)), IRDM_OK);
	bcfg = (struct irdm_hal_config){ &arm_cfg, NULL, board.period_us * 1e-6 };
	assert_int_equal(irdm_hal_init(&dev, "sim", &bcfg, mem, sizeof(mem)), IRDM_OK);
	assert_int_equal(irdm_hal_open(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_sim_attach_user(&dev, &user, IRDM_SIM_USER_HANDS, &board),
			 IRDM_EINVAL);
	assert_int_equal(irdm_hal_sim_attach_user(&dev, &user, 0, &board), IRDM_OK);
	irdm_sim_params_default(&p);
	assert_int_equal(irdm_sim_device_init(&ref, &arm_cfg, &p), IRDM_OK);
	for (uint64_t k = 0; k < 150; k++) {
		uint32_t period_ns = board.period_us * 1000u;

		irdm_sim_user_push(&user, 0, &board, &ref, (double)k * period_ns * 1e-9);
		assert_int_equal(irdm_sim_device_step(&ref, bcfg.period_s), IRDM_OK);
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	}
	irdm_sim_device_state(irdm_hal_sim_device(&dev), q, qd);
	irdm_sim_device_state(&ref, q_ref, qd_ref);
	assert_memory_equal(q, q_ref, sizeof(q));
	assert_memory_equal(qd, qd_ref, sizeof(qd));
	/* reopened, nobody holds it: the same reads leave the arm elsewhere */
	irdm_hal_close(&dev);
	assert_int_equal(irdm_hal_open(&dev), IRDM_OK);
	for (int k = 0; k < 150; k++)
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	irdm_sim_device_state(irdm_hal_sim_device(&dev), q_free, qd);
	print_message("after 0.15 s: joint 2 at %.6f rad held, %.6f rad free\n", q[1], q_free[1]);
	assert_true(fabs(q[1] - q_free[1]) > 1e-3);
	irdm_hal_close(&dev);
	/* only an open sim instance takes a hand */
	assert_int_equal(irdm_hal_sim_attach_user(&dev, &user, 0, &board), IRDM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_registry),
		cmocka_unit_test(test_life_cycle_errors),
		cmocka_unit_test(test_force_moves_tip),
		cmocka_unit_test(test_delay_option),
		cmocka_unit_test(test_injected_fault),
		cmocka_unit_test(test_encoder_out_of_range),
		cmocka_unit_test(test_attached_user_pushes_at_tick_time),
	};

	return cmocka_run_group_tests(tests, setup, NULL);
}
