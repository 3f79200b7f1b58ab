/* SPDX-License-Identifier: MIT */
/*
 * The CAN HAL (irdm/hal_can.h) on a bus that behaves like a wire: the
 * drives answer a SYNC after the HAL call that sent it has returned, never
 * within it (the "canemu" back-end lets them answer at once, which hid
 * both cases below; make hil's VM found them on vcan0):
 *  - a period nobody wrote (the controller writes from enable on) is
 *    closed by the next read; its answer cannot be in that read, which
 *    must still succeed on the counts of the period before;
 *  - a TPDO1 that misses a period (a late frame) is tolerated for
 *    tpdo_missing_periods - 1 periods, on the latest counts; then lost.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/sim/can_drives.h"
#include "irdm/sim/can_membus.h"
#include "irdm/error.h"
#include "irdm/hal/hal_can.h"

struct wire_data {
	struct irdm_hal_can can; /* first: the shared code's view */
	struct irdm_can_membus bus;
	struct irdm_can_drives drives;
};

static struct wire_data data;

static int wire_open_link(struct irdm_hal_dev *dev, struct irdm_can_port *port, char *err,
			  size_t errlen)
{
	struct irdm_can_port drives_port;
	struct irdm_sim_params p;

	(void)err, (void)errlen;
	irdm_can_membus_init(&data.bus);
	irdm_can_membus_port(&data.bus, port);
	irdm_can_membus_port(&data.bus, &drives_port);
	irdm_sim_params_default(&p);
	return irdm_can_drives_init(&data.drives, &drives_port, dev->config->device, &p, 3, 1,
				    dev->config->period_s);
}

/* Set-up waits a period: the drives answer meanwhile. */
static void wire_idle(void *ctx)
{
	(void)ctx;
	irdm_can_drives_poll(&data.drives);
}

static void wire_close(struct irdm_hal_dev *dev)
{
	(void)dev;
}

static const struct irdm_hal_can_link wire_link = {
	.open = wire_open_link,
	.pump = NULL, /* a wire: nobody answers within the call */
	.idle = wire_idle,
	.check = NULL,
	.close = wire_close,
};

static int wire_open(struct irdm_hal_dev *dev)
{
	return irdm_hal_can_open(dev, &wire_link, 0);
}

static const struct irdm_hal_ops wire_ops = IRDM_HAL_CAN_OPS(wire_open, NULL);

static const struct irdm_hal_backend wire_backend = {
	.name = "test-wire",
	.ops = &wire_ops,
	.data_size = sizeof(struct wire_data),
};

static struct irdm_hal_dev dev;
static struct irdm_device_config arm;
static struct irdm_hal_config cfg;

static void up(void)
{
	irdm_device_config_default(&arm);
	cfg = (struct irdm_hal_config){ &arm,
					"nodes=1,2,3 rated_torque_mnm=100 heartbeat_ms=10 heartbeat_timeout_ms=50 "
					"tpdo_missing_periods=3",
					1e-3 };
	irdm_hal_register(&wire_backend);
	assert_int_equal(irdm_hal_init(&dev, "test-wire", &cfg, &data, sizeof(data)), IRDM_OK);
	if (irdm_hal_open(&dev))
		fail_msg("open: %s", dev.why);
	if (irdm_hal_start(&dev))
		fail_msg("start: %s", dev.why);
	irdm_can_drives_poll(&data.drives); /* the answer to start's last SYNC */
}

static void test_unwritten_period(void **state)
{
	struct irdm_hal_joint_state st;
	const double zero[3] = { 0, 0, 0 };

	(void)state;
	up();
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK); /* tick 0: calibrate, no write */
	irdm_can_drives_poll(&data.drives);
	if (irdm_hal_read(&dev, &st)) /* tick 1 closes tick 0's period */
		fail_msg("read after an unwritten period: %s", dev.why);
	irdm_can_drives_poll(&data.drives);
	assert_int_equal(irdm_hal_write(&dev, zero), IRDM_OK);
	irdm_can_drives_poll(&data.drives);
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(st.seq, 3);
	irdm_hal_close(&dev);
}

static void test_late_tpdo_tolerated_then_lost(void **state)
{
	struct irdm_hal_joint_state st;
	const double zero[3] = { 0, 0, 0 };
	uint32_t faults;
	int k;

	(void)state;
	up();
	for (k = 0; k < 5; k++) { /* steady: each answered */
		assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
		assert_int_equal(irdm_hal_write(&dev, zero), IRDM_OK);
		irdm_can_drives_poll(&data.drives);
	}
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	assert_int_equal(irdm_hal_write(&dev, zero), IRDM_OK); /* this SYNC is answered late */
	if (irdm_hal_read(&dev, &st))
		fail_msg("one late TPDO1: %s", dev.why);
	assert_int_equal(irdm_hal_write(&dev, zero), IRDM_OK);
	irdm_can_drives_poll(&data.drives); /* both answers come */
	assert_int_equal(irdm_hal_read(&dev, &st), IRDM_OK);
	for (k = 0; k < 3; k++) { /* now none for 3 periods */
		assert_int_equal(irdm_hal_write(&dev, zero), IRDM_OK);
		if (irdm_hal_read(&dev, &st))
			break;
	}
	assert_int_equal(k, 2);
	assert_int_equal(irdm_hal_poll(&dev, &faults), IRDM_EHW);
	assert_string_equal(dev.why, "drive 1 (node 1): no TPDO1 for 3 periods");
	irdm_hal_close(&dev);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_unwritten_period),
		cmocka_unit_test(test_late_tpdo_tolerated_then_lost),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
