/* SPDX-License-Identifier: MIT */
/*
 * The safety state machine (irdm/safety.h), transition by transition: from
 * each of the five states, each operation, the state it must lead to and
 * the code it must return, the forbidden ones included.  The table is
 * written from the diagram in the header, not from the code.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/safety.h"

enum op { OP_CALIBRATED,
	  OP_ENABLE,
	  OP_DISABLE,
	  OP_FAULT,
	  OP_RESET,
	  OP_RESET_BUSY,
	  OP_SHUTDOWN,
	  OP_COUNT };

static const char *const op_name[OP_COUNT] = {
	"calibrated",
	"enable",
	"disable",
	"fault(workspace)",
	"reset",
	"reset(cause holds)",
	"shutdown",
};

/* A machine in `state`, reached the way the controller reaches it. */
static void put_in(struct irdm_safety *s, int state)
{
	irdm_safety_init(s);
	switch (state) {
	case IRDM_SAFETY_INIT:
		break;
	case IRDM_SAFETY_READY:
		assert_int_equal(irdm_safety_calibrated(s), IRDM_OK);
		break;
	case IRDM_SAFETY_ENABLED:
		assert_int_equal(irdm_safety_calibrated(s), IRDM_OK);
		assert_int_equal(irdm_safety_enable(s), IRDM_OK);
		break;
	case IRDM_SAFETY_FAULT:
		assert_int_equal(irdm_safety_calibrated(s), IRDM_OK);
		assert_int_equal(irdm_safety_enable(s), IRDM_OK);
		assert_int_equal(irdm_safety_fault(s, IRDM_FAULT_VELOCITY), IRDM_OK);
		break;
	case IRDM_SAFETY_OFF:
		irdm_safety_shutdown(s);
		break;
	}
	assert_int_equal(s->state, state);
}

static int apply(struct irdm_safety *s, enum op op)
{
	switch (op) {
	case OP_CALIBRATED:
		return irdm_safety_calibrated(s);
	case OP_ENABLE:
		return irdm_safety_enable(s);
	case OP_DISABLE:
		return irdm_safety_disable(s);
	case OP_FAULT:
		return irdm_safety_fault(s, IRDM_FAULT_WORKSPACE);
	case OP_RESET:
		return irdm_safety_reset(s, 0);
	case OP_RESET_BUSY:
		return irdm_safety_reset(s, IRDM_FAULT_VELOCITY);
	case OP_SHUTDOWN:
		irdm_safety_shutdown(s);
		return IRDM_OK;
	default:
		return -100;
	}
}

#define I IRDM_SAFETY_INIT
#define R IRDM_SAFETY_READY
#define E IRDM_SAFETY_ENABLED
#define F IRDM_SAFETY_FAULT
#define O IRDM_SAFETY_OFF
#define OK IRDM_OK
#define INV IRDM_EINVAL
#define FLT IRDM_EFAULT

struct expect {
	int state, rc;
};

/* [from][op] */
static const struct expect table[5][OP_COUNT] = {
	/*          calibrated  enable     disable    fault      reset      reset busy  shutdown */
	[I] = { { R, OK }, { I, INV }, { I, INV }, { F, OK }, { I, INV }, { I, INV }, { O, OK } },
	[R] = { { R, INV }, { E, OK }, { R, OK }, { F, OK }, { R, INV }, { R, INV }, { O, OK } },
	[E] = { { E, INV }, { E, OK }, { R, OK }, { F, OK }, { E, INV }, { E, INV }, { O, OK } },
	[F] = { { F, INV }, { F, INV }, { F, INV }, { F, OK }, { R, OK }, { F, FLT }, { O, OK } },
	[O] = { { O, INV }, { O, INV }, { O, INV }, { O, OK }, { O, INV }, { O, INV }, { O, OK } },
};

static void test_every_transition(void **state)
{
	unsigned n = 0;
	(void)state;

	for (int from = I; from <= O; from++)
		for (int op = 0; op < OP_COUNT; op++) {
			struct irdm_safety s;
			int rc;

			put_in(&s, from);
			rc = apply(&s, (enum op)op);
			if (rc != table[from][op].rc || (int)s.state != table[from][op].state)
				fail_msg("%s --%s--> %s rc %d; expected %s rc %d",
					 irdm_safety_state_name(from), op_name[op],
					 irdm_safety_state_name((int)s.state), rc,
					 irdm_safety_state_name(table[from][op].state),
					 table[from][op].rc);
			assert_int_equal(irdm_safety_torque_allowed(&s), s.state == E);
			n++;
		}
	print_message("  %u (state, operation) pairs as the diagram says\n", n);
}

/* A fault latches: no enable without a reset, and no reset while it holds. */
static void test_fault_never_reenables_by_itself(void **state)
{
	struct irdm_safety s;
	(void)state;

	put_in(&s, IRDM_SAFETY_ENABLED);
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_OVERRUN | IRDM_FAULT_WATCHDOG), IRDM_OK);
	assert_int_equal(s.cause, IRDM_FAULT_WATCHDOG); /* the lowest bit */
	assert_int_equal(s.faults, IRDM_FAULT_OVERRUN | IRDM_FAULT_WATCHDOG);
	for (int k = 0; k < 100; k++) {
		assert_int_equal(irdm_safety_enable(&s), IRDM_EINVAL);
		assert_int_equal(s.state, IRDM_SAFETY_FAULT);
	}
	/* a later fault latches but does not change the reason */
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_WORKSPACE), IRDM_OK);
	assert_int_equal(s.cause, IRDM_FAULT_WATCHDOG);
	assert_int_equal(s.n_faults, 1);
	assert_int_equal(irdm_safety_reset(&s, IRDM_FAULT_WATCHDOG), IRDM_EFAULT);
	/* CLAMP is informational: it never blocks a reset */
	assert_int_equal(irdm_safety_reset(&s, IRDM_FAULT_CLAMP), IRDM_OK);
	assert_int_equal(s.state, IRDM_SAFETY_READY);
	assert_int_equal(s.faults, 0);
	assert_int_equal(s.cause, 0);
	assert_int_equal(irdm_safety_enable(&s), IRDM_OK);
}

static void test_clamp_alone_is_not_a_fault(void **state)
{
	struct irdm_safety s;
	(void)state;

	put_in(&s, IRDM_SAFETY_ENABLED);
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_CLAMP), IRDM_EINVAL);
	assert_int_equal(irdm_safety_fault(&s, 0), IRDM_EINVAL);
	assert_int_equal(s.state, IRDM_SAFETY_ENABLED);
	assert_int_equal(s.faults, 0);
	/* CLAMP with a real fault: only the fatal bit latches */
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_CLAMP | IRDM_FAULT_ENGINE), IRDM_OK);
	assert_int_equal(s.faults, IRDM_FAULT_ENGINE);
	assert_int_equal(s.cause, IRDM_FAULT_ENGINE);
}

/* A signal means the process is stopping: no reset out of it. */
static void test_signal_is_never_reset(void **state)
{
	struct irdm_safety s;
	(void)state;

	put_in(&s, IRDM_SAFETY_ENABLED);
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_SIGNAL), IRDM_OK);
	assert_int_equal(irdm_safety_reset(&s, 0), IRDM_EFAULT);
	assert_int_equal(s.state, IRDM_SAFETY_FAULT);
	irdm_safety_shutdown(&s);
	assert_int_equal(s.state, IRDM_SAFETY_OFF);
}

/* A fault before calibration resets to INIT: enabling still needs it. */
static void test_reset_before_calibration_goes_to_init(void **state)
{
	struct irdm_safety s;
	(void)state;

	put_in(&s, IRDM_SAFETY_INIT);
	assert_int_equal(irdm_safety_fault(&s, IRDM_FAULT_HAL_READ), IRDM_OK);
	assert_int_equal(irdm_safety_reset(&s, 0), IRDM_OK);
	assert_int_equal(s.state, IRDM_SAFETY_INIT);
	assert_int_equal(irdm_safety_enable(&s), IRDM_EINVAL);
}

/* The log's names: bit numbers and names as the telemetry export prints them. */
static void test_names(void **state)
{
	static const char *const want[IRDM_FAULT_BITS] = {
		"clamp",
		"workspace",
		"velocity",
		"watchdog",
		"overrun",
		"encoder-nan",
		"encoder-range",
		"signal",
		"hal-read",
		"hal-write",
		"hal-fault",
		"engine",
	};
	static const uint32_t bit[IRDM_FAULT_BITS] = {
		IRDM_FAULT_CLAMP,
		IRDM_FAULT_WORKSPACE,
		IRDM_FAULT_VELOCITY,
		IRDM_FAULT_WATCHDOG,
		IRDM_FAULT_OVERRUN,
		IRDM_FAULT_ENCODER_NAN,
		IRDM_FAULT_ENCODER_RANGE,
		IRDM_FAULT_SIGNAL,
		IRDM_FAULT_HAL_READ,
		IRDM_FAULT_HAL_WRITE,
		IRDM_FAULT_HAL_FAULT,
		IRDM_FAULT_ENGINE,
	};
	(void)state;

	for (unsigned b = 0; b < IRDM_FAULT_BITS; b++) {
		assert_int_equal(bit[b], 1u << b);
		assert_string_equal(irdm_safety_fault_name(1u << b), want[b]);
	}
	assert_string_equal(irdm_safety_fault_name(0), "none");
	assert_string_equal(irdm_safety_fault_name(1u << 20), "unknown");
	assert_string_equal(irdm_safety_fault_name(IRDM_FAULT_ENGINE | IRDM_FAULT_VELOCITY),
			    "velocity");
	assert_int_equal(IRDM_SAFETY_INIT, 0);
	assert_int_equal(IRDM_SAFETY_READY, 1);
	assert_int_equal(IRDM_SAFETY_ENABLED, 2);
	assert_int_equal(IRDM_SAFETY_FAULT, 3);
	assert_int_equal(IRDM_SAFETY_OFF, 4);
	assert_string_equal(irdm_safety_state_name(IRDM_SAFETY_ENABLED), "enabled");
	assert_string_equal(irdm_safety_state_name(IRDM_SAFETY_OFF), "off");
	assert_string_equal(irdm_safety_state_name(5), "unknown");
	assert_string_equal(irdm_safety_state_name(-1), "unknown");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_every_transition),
		cmocka_unit_test(test_fault_never_reenables_by_itself),
		cmocka_unit_test(test_clamp_alone_is_not_a_fault),
		cmocka_unit_test(test_signal_is_never_reset),
		cmocka_unit_test(test_reset_before_calibration_goes_to_init),
		cmocka_unit_test(test_names),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
