/* SPDX-License-Identifier: MIT */
/*
 * The device model, the velocity estimator and the sim HAL back-end make no
 * system call: 2000 ticks of what the controller will do with them (read
 * through the HAL, counts -> angles -> tip, velocity, gravity compensation,
 * a spring force through J^T, saturation, write, poll, safe-off and
 * restart) run in a forked child in seccomp strict mode, where any system
 * call but read, write, _exit and sigreturn kills it.  The same run with
 * one system call slipped in must be killed (the harness can fail).
 */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdalign.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <linux/seccomp.h>

#include <cmocka.h>

#include "irdm/device.h"
#include "irdm/error.h"
#include "irdm/hal/hal.h"
#include "irdm/sim/hal_sim.h"

#define TICKS 2000

static alignas(max_align_t) unsigned char mem[64 * 1024];
static struct irdm_device_config device;
static struct irdm_hal_config cfg;
static struct irdm_hal_dev dev;
static struct irdm_velocity vel[3];

/* One controller tick; returns how many calls failed unexpectedly. */
static int tick(unsigned k)
{
	struct irdm_hal_joint_state st;
	double q[3], tip[3], g[3], f[3], tau[3], v;
	uint32_t faults;
	int bad = 0;

	bad += irdm_hal_read(&dev, &st) != IRDM_OK;
	bad += irdm_device_angles_from_counts(&device, st.counts, q) != IRDM_OK;
	irdm_device_fk(&device, q, tip);
	for (int i = 0; i < 3; i++) {
		bad += irdm_velocity_update(&vel[i], q[i], &v) != IRDM_OK;
		f[i] = -200.0 * (tip[i] - 0.01 * sin(k * 1e-2 + i)) - 2.0 * v * 0.135;
	}
	irdm_device_gravity_torque(&device, q, g);
	irdm_device_force_to_torque(&device, q, f, tau);
	for (int i = 0; i < 3; i++)
		tau[i] += g[i];
	bad += irdm_device_torque_saturate(&device, tau, tau, NULL) != IRDM_OK;
	bad += irdm_hal_write(&dev, tau) != IRDM_OK;
	bad += irdm_hal_poll(&dev, &faults) != IRDM_OK;
	if (k % 500 == 499) {
		bad += irdm_hal_safe_off(&dev) != IRDM_OK;
		bad += irdm_hal_start(&dev) != IRDM_OK;
	}
	return bad;
}

static void setup_rig(void)
{
	irdm_device_config_default(&device);
	cfg = (struct irdm_hal_config){ .device = &device, .options = "write_delay=1", .period_s = 1e-3 };
	assert_int_equal(irdm_hal_register(&irdm_hal_sim_backend), IRDM_OK);
	assert_int_equal(irdm_hal_init(&dev, "sim", &cfg, mem, sizeof(mem)), IRDM_OK);
	assert_int_equal(irdm_hal_open(&dev), IRDM_OK);
	assert_int_equal(irdm_hal_start(&dev), IRDM_OK);
	for (int i = 0; i < 3; i++)
		assert_int_equal(irdm_velocity_init(&vel[i], 1e-3,
						    irdm_device_rad_per_count(&device, i), 32),
				 IRDM_OK);
}

/* Exit status: 0 all ticks ran clean, 1 a call failed, 2 no strict mode. */
static __attribute__((noreturn)) void strict_child(int slip_syscall)
{
	int bad = 0;

	signal(SIGABRT, SIG_DFL); /* a crash must not look like a kill */
	if (prctl(PR_SET_SECCOMP, SECCOMP_MODE_STRICT, 0, 0, 0))
		_exit(errno == EINVAL ? 2 : 3);
	for (unsigned k = 0; k < TICKS; k++) {
		bad += tick(k);
		if (slip_syscall && k == TICKS / 2)
			syscall(SYS_getppid);
	}
	syscall(SYS_exit, bad ? 1 : 0);
	for (;;)
		;
}

/* Run the ticks in a strict-mode child; its wait status. */
static int run_strict(int slip_syscall)
{
	int status;
	pid_t pid;

	setup_rig();
	fflush(NULL);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		strict_child(slip_syscall);
	while (waitpid(pid, &status, 0) < 0)
		assert_int_equal(errno, EINTR);
	irdm_hal_close(&dev);
	if (WIFEXITED(status) && WEXITSTATUS(status) == 2) {
		print_message("  seccomp strict mode not available in this kernel: skipped\n");
		skip();
	}
	return status;
}

static void test_ticks_make_no_system_call(void **state)
{
	int status;
	(void)state;

	/* the same ticks outside strict mode: they run clean */
	setup_rig();
	for (unsigned k = 0; k < TICKS; k++)
		assert_int_equal(tick(k), 0);
	irdm_hal_close(&dev);

	status = run_strict(0);
	if (WIFSIGNALED(status))
		fail_msg("strict-mode child died of signal %d (SIGKILL: a system call)",
			 WTERMSIG(status));
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 0);
	print_message("  %d ticks in seccomp strict mode: no system call\n", TICKS);
}

static void test_a_system_call_is_caught(void **state)
{
	int status;
	(void)state;

	status = run_strict(1);
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), SIGKILL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ticks_make_no_system_call),
		cmocka_unit_test(test_a_system_call_is_caught),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
