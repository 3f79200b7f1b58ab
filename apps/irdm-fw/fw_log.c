/* SPDX-License-Identifier: MIT */
/*
 * The per-tick record: the controller's output as the telemetry log keeps
 * it, pushed through the lock-free ring.  In real time a low-priority thread
 * drains the ring to the file; in virtual time the loop outruns any thread,
 * so it drains the ring itself every IRDM_LOG_WRITER_CHUNK records (virtual
 * time is not real time: the file I/O is allowed there, and the log loses
 * nothing).  Timing fields are 0 in virtual time: its logs are the same
 * every run.
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "irdm/error.h"
#include "irdm/posix/rt.h"
#include "irdm/posix/telemetry_log.h"

#include "fw.h"

#define RING_RECORDS 4096u /* 4 s at 1 kHz: the writer may stall that long */

static void fill_dev(struct irdm_tick_dev *r, const struct irdm_ctrl_device_output *d)
{
	memcpy(r->tip_pos_m, d->tip_m, sizeof(r->tip_pos_m));
	memcpy(r->tip_vel_m_s, d->vel_m_per_s, sizeof(r->tip_vel_m_s));
	memcpy(r->joint_angle_rad, d->q_rad, sizeof(r->joint_angle_rad));
	memcpy(r->joint_torque_nm, d->torque_nm, sizeof(r->joint_torque_nm));
	memcpy(r->force_n, d->force_obj_n, sizeof(r->force_n));
	r->contact_tri = d->contact ? d->tri : IRDM_TELEM_NO_TRI;
	r->proxy = (uint8_t)d->proxy_event;
	r->softened = d->softened;
	/* a proxy that touches or slides commanded the engine (controller_contact.c) */
	r->site_tri = IRDM_TELEM_NO_TRI;
	if (d->proxy_event == IRDM_PROXY_TOUCH || d->proxy_event == IRDM_PROXY_SLIDE) {
		r->site_tri = d->tri;
		memcpy(r->site_bary, d->bary, sizeof(r->site_bary));
		memcpy(r->target_m, d->target_m, sizeof(r->target_m));
	}
}

static int64_t clamp_i32(int64_t v)
{
	return v > INT32_MAX ? INT32_MAX : v < INT32_MIN ? INT32_MIN :
							   v;
}

static void drain(struct fw *fw, size_t below)
{
	struct irdm_tick_record chunk[IRDM_LOG_WRITER_CHUNK];
	size_t n;

	while (irdm_telem_ring_used(fw->ring) > below) {
		n = irdm_telem_ring_pop(fw->ring, chunk, IRDM_LOG_WRITER_CHUNK);
		if (!n || irdm_log_file_append(fw->logf, chunk, n, fw->err, sizeof(fw->err)))
			return;
	}
}

void fw_log_record(struct fw *fw, const struct irdm_ctrl_output *out, int64_t latency_ns,
		   int64_t compute_ns)
{
	struct irdm_tick_record r;

	irdm_hist_add(&fw->latency, latency_ns);
	if (!fw->ring && !fw->view_ring)
		return;
	memset(&r, 0, sizeof(r));
	r.tick = out->tick - 1;
	r.wake_latency_ns = (int32_t)clamp_i32(latency_ns);
	r.compute_ns = (uint32_t)(compute_ns < 0 ? 0 : clamp_i32(compute_ns));
	r.fault_flags = out->faults;
	r.state = (uint8_t)out->state;
	r.n_devices = (uint8_t)out->n_devices;
	for (unsigned i = 0; i < out->n_devices && i < IRDM_TELEM_MAX_DEVICES; i++)
		fill_dev(&r.dev[i], &out->dev[i]);
	if (fw->ring)
		irdm_telem_ring_push(fw->ring, &r);
	if (fw->view_ring)
		irdm_telem_ring_push(fw->view_ring, &r);
	if (fw->logf)
		drain(fw, IRDM_LOG_WRITER_CHUNK);
}

int fw_log_open(struct fw *fw)
{
	struct irdm_log_info info = {
		.period_us = fw->board.period_us,
		.n_devices = fw->board.devices,
		.start_time_ns = 0,
		.board = fw->board.name,
		.image = fw->args.image,
	};
	struct irdm_rt_sched writer = { SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	struct timespec now;
	size_t bytes = irdm_telem_ring_mem_size(RING_RECORDS);
	int rc;

	irdm_hist_init(&fw->latency, 0);
	irdm_hist_init(&fw->compute_measured, (int64_t)fw->board.period_us * 1000);
	if (!fw->args.log)
		return IRDM_OK;
	fw->ring_mem = aligned_alloc(64, (bytes + 63) / 64 * 64);
	if (!fw->ring_mem)
		return IRDM_ENOMEM;
	rc = irdm_telem_ring_init(&fw->ring, fw->ring_mem, bytes, RING_RECORDS);
	if (rc)
		return rc;
	if (fw->args.clock == IRDM_CLOCK_VIRTUAL)
		return irdm_log_file_open(&fw->logf, fw->args.log, &info, fw->err, sizeof(fw->err));
	clock_gettime(CLOCK_REALTIME, &now);
	info.start_time_ns = (int64_t)now.tv_sec * 1000000000 + now.tv_nsec;
	/* the lowest priority, and off the force thread's CPU when it has one */
	writer.cpu = fw->board.cpu >= 0 ? IRDM_RT_CPU_EXCEPT(fw->board.cpu) : IRDM_RT_ANY_CPU;
	return irdm_log_writer_start(&fw->writer, fw->args.log, &info, fw->ring, &writer, fw->err,
				     sizeof(fw->err));
}

int fw_log_close(struct fw *fw)
{
	int rc = IRDM_OK;

	if (fw->logf) {
		drain(fw, 0);
		rc = irdm_log_file_close(fw->logf, irdm_telem_ring_drops(fw->ring), fw->err,
					 sizeof(fw->err));
		fw->logf = NULL;
	}
	if (fw->writer) {
		rc = irdm_log_writer_stop(fw->writer, fw->err, sizeof(fw->err));
		fw->writer = NULL;
	}
	free(fw->ring_mem);
	fw->ring_mem = NULL;
	fw->ring = NULL;
	return rc;
}
