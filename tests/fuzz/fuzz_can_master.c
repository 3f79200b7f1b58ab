// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: the CANopen master's receive path (hal/can/can_master.c)
 * in the operational state, on arbitrary frames.  A fake port confirms
 * every SDO download of the set-up and answers its uploads as a CiA 402
 * drive, then hands the master the input's frames:
 * 2 bytes of identifier (11 bits used), 1 of length (any), 8 of data, and
 * one control byte (bit 0: end the period here - receive, then send with
 * torque); repeated.  Invariants: once faulted, every RPDO sent is disable
 * voltage with zero torque; no torque while an axis is not operation
 * enabled; the reason is one NUL-terminated line.
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "irdm/hal/can_master.h"
#include "irdm/error.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static struct irdm_can_frame pending[64], sdo_answer;
static unsigned n_pending, next_pending;
static int have_answer;
static const struct irdm_can_master *watched;

static int fake_send(void *ctx, const struct irdm_can_frame *f)
{
	(void)ctx;
	if (f->id >= 0x601 && f->id <= 0x67F) { /* confirm every download */
		uint16_t index = (uint16_t)(f->data[1] | f->data[2] << 8);

		sdo_answer = *f;
		sdo_answer.id = f->id - 0x80;
		sdo_answer.data[0] = 0x60;
		memset(sdo_answer.data + 4, 0, 4);
		if (f->data[0] == 0x40) { /* an upload: as a CiA 402 drive */
			sdo_answer.data[0] = 0x43;
			if (index == 0x1000)
				sdo_answer.data[4] = 0x92, sdo_answer.data[5] = 0x01;
			if (index == 0x6061)
				sdo_answer.data[4] = 10;
		}
		have_answer = 1;
	}
	if (watched && f->id >= 0x201 && f->id <= 0x203 && f->dlc == 4) {
		int torque = f->data[2] | f->data[3];

		if (watched->faulted && (f->data[0] | f->data[1] | torque))
			__builtin_trap(); /* faulted yet not off */
		if (torque && irdm_can_master_first_not_enabled(watched) >= 0)
			__builtin_trap(); /* torque to a drive not enabled */
	}
	return IRDM_OK;
}

static int fake_recv(void *ctx, struct irdm_can_frame *f)
{
	(void)ctx;
	if (have_answer) {
		*f = sdo_answer;
		have_answer = 0;
		return 1;
	}
	if (next_pending < n_pending) {
		*f = pending[next_pending++];
		return 1;
	}
	return 0;
}

static void idle(void *ctx)
{
	(void)ctx;
}

static const struct irdm_can_port_ops fake_ops = { fake_send, fake_recv };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct irdm_can_master m;
	struct irdm_can_port port = { &fake_ops, NULL };
	struct irdm_can_master_cfg cfg = {
		.n_axes = 3,
		.period_us = 1000,
		.bitrate = 1000000,
		.sync_counter = true,
		.heartbeat_ms = 10,
		.heartbeat_timeout_ms = 50,
		.tpdo_missing_periods = 3,
		.master_node = 127,
		.rpdo_timeout_ms = 3,
		.sdo_timeout_polls = 2,
		.idle = idle,
	};
	const double tau[3] = { 0.5, -0.5, 0.25 };
	char err[160];

	for (unsigned k = 0; k < 3; k++)
		cfg.axis[k] = (struct irdm_can_axis_cfg){ k + 1, 100, 11.6 };
	watched = NULL;
	n_pending = next_pending = 0;
	have_answer = 0;
	if (irdm_can_master_init(&m, &port, &cfg, err, sizeof(err)) != IRDM_OK)
		__builtin_trap(); /* every SDO was confirmed */
	irdm_can_master_enable(&m, 1);
	watched = &m;
	for (; size >= 12; data += 12, size -= 12) {
		struct irdm_can_frame *f = &pending[n_pending++];

		f->id = (uint32_t)(data[0] | (data[1] << 8)) & 0x7FF;
		f->dlc = data[2];
		memcpy(f->data, data + 3, 8);
		if ((data[11] & 1) || n_pending == 64) {
			(void)irdm_can_master_receive(&m);
			(void)irdm_can_master_send(&m, tau);
			n_pending = next_pending = 0;
		}
	}
	(void)irdm_can_master_receive(&m);
	(void)irdm_can_master_send(&m, tau);
	if (memchr(m.why, '\0', sizeof(m.why)) == NULL || strchr(m.why, '\n'))
		__builtin_trap();
	return 0;
}
