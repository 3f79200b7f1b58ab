/* SPDX-License-Identifier: MIT */
/*
 * irdm-candrives: the CiA 402 drive emulator (sim/can) as a process on a
 * SocketCAN interface.  It sleeps in poll() on the socket between frames
 * and wall-clock events (heartbeats, delayed TPDOs): the master's SYNCs
 * pace the arm, so it is not a loop of its own and needs no real-time
 * priority.  The virtual user's hand pushes the arm at t = (SYNC - 1) x
 * period, the time irdm-fw's in-process loop gives the same step, so a
 * run is reproducible in SYNC count whatever the wall clock does.
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "irdm/board.h"
#include "irdm/posix/board_file.h"
#include "irdm/sim/can_drives.h"
#include "irdm/error.h"
#include "irdm/sim/sim_user_push.h"
#include "irdm/hal/socketcan.h"

#include "candrives.h"

#define POLL_MAX_MS 100 /* re-check --seconds and signals at least this often */

static volatile sig_atomic_t stop_signal;

static void on_signal(int sig)
{
	stop_signal = sig;
}

struct cd {
	struct cd_args args;
	struct irdm_board board;
	struct irdm_sim_user *user; /* NULL: no hand */
	struct irdm_socketcan sock;
	struct irdm_can_drives dr;
	enum irdm_co_nmt_state nmt_seen[IRDM_CAN_DRIVES_MAX];
	enum irdm_cia402_state fsa_seen[IRDM_CAN_DRIVES_MAX];
	char err[512];
};

static uint64_t now_us(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

static int fail(int code, const char *msg)
{
	fprintf(stderr, "irdm-candrives: %s\n", msg);
	return code;
}

/* The hook: the hand pushes the arm before the SYNC's step. */
static void push(void *ctx, struct irdm_can_drives *dr)
{
	struct cd *cd = ctx;

	irdm_sim_user_push(cd->user, 0, &cd->board, &dr->arm,
			   (double)(dr->syncs - 1) * dr->period_s);
}

/* The user script, its home where the arm rests (the calibration pose). */
static int load_user(struct cd *cd)
{
	struct irdm_device_config dev;
	double tip[3], home[3];

	cd->user = calloc(1, sizeof(*cd->user));
	if (!cd->user)
		return fail(CD_EXIT_INPUT, "out of memory for the user script");
	if (irdm_sim_user_load(cd->user, cd->args.user, cd->err, sizeof(cd->err)))
		return fail(CD_EXIT_INPUT, cd->err);
	if (cd->user->hands > 1) {
		snprintf(cd->err, sizeof(cd->err), "--user %s: uses %u hands, the drives move one arm",
			 cd->args.user, cd->user->hands);
		return fail(CD_EXIT_INPUT, cd->err);
	}
	irdm_board_device(&cd->board, 0, &dev);
	irdm_device_fk(&dev, cd->board.calibration_pose_rad, tip);
	irdm_board_device_to_object(&cd->board, tip, home);
	if (irdm_sim_user_start(cd->user, 0, home, cd->args.user, cd->err, sizeof(cd->err)))
		return fail(CD_EXIT_INPUT, cd->err);
	return CD_EXIT_OK;
}

/* Every fault names one of our drives (before anything opens). */
static int check_fault_nodes(struct cd *cd)
{
	unsigned lo = cd->args.first_node, hi = lo + cd->args.nodes - 1;

	for (unsigned k = 0; k < cd->args.n_faults; k++) {
		const struct irdm_can_fault *f = &cd->args.fault[k];

		if (f->kind == IRDM_CAN_FAULT_FLOOD || (f->node >= lo && f->node <= hi))
			continue;
		snprintf(cd->err, sizeof(cd->err), "--fault: node %u is not one of the drives %u..%u",
			 f->node, lo, hi);
		return fail(CD_EXIT_USAGE, cd->err);
	}
	return CD_EXIT_OK;
}

/* Board, user, socket, drives, faults: an exit code or -1 to run. */
static int set_up(struct cd *cd)
{
	struct irdm_device_config dev;
	struct irdm_sim_params p;
	struct irdm_can_port port;
	int rc;

	if (irdm_board_load(&cd->board, cd->args.board, cd->err, sizeof(cd->err)))
		return fail(CD_EXIT_INPUT, cd->err);
	if ((rc = check_fault_nodes(cd)) != CD_EXIT_OK)
		return rc;
	if (cd->args.user && (rc = load_user(cd)) != CD_EXIT_OK)
		return rc;
	irdm_board_device(&cd->board, 0, &dev);
	irdm_sim_params_default(&p);
	rc = irdm_socketcan_open(&cd->sock, cd->args.ifname, &port, cd->err, sizeof(cd->err));
	if (rc)
		return fail(CD_EXIT_SETUP, cd->err);
	if (irdm_can_drives_init(&cd->dr, &port, &dev, &p, cd->args.nodes, cd->args.first_node,
				 cd->board.period_us * 1e-6))
		return fail(CD_EXIT_INPUT, "the board's arm or period is refused by the drives");
	cd->dr.wall_heartbeat = true;
	/* a real arm rests in its dock at the calibration pose until the
	 * controller drives it; the process starts long before that */
	cd->dr.docked = true;
	if (cd->user) {
		cd->dr.before_step = push;
		cd->dr.hook_ctx = cd;
	}
	for (unsigned k = 0; k < cd->args.n_faults; k++)
		irdm_can_drives_schedule(&cd->dr, &cd->args.fault[k]); /* checked above */
	return -1;
}

/* One line per drive whose NMT or CiA 402 state changed. */
static void report_states(struct cd *cd)
{
	for (unsigned k = 0; k < cd->dr.n; k++) {
		const struct irdm_can_drive *d = &cd->dr.d[k];

		if (d->nmt == cd->nmt_seen[k] && d->fsa.state == cd->fsa_seen[k])
			continue;
		cd->nmt_seen[k] = d->nmt;
		cd->fsa_seen[k] = d->fsa.state;
		if (!cd->args.quiet)
			printf("irdm-candrives: SYNC %llu: node %u: NMT 0x%02x, %s\n",
			       (unsigned long long)cd->dr.syncs, d->node, (unsigned)d->nmt,
			       irdm_cia402_name(d->fsa.state));
	}
}

static bool done(const struct cd *cd, uint64_t t0_us, uint64_t t_us)
{
	return stop_signal || (cd->args.syncs && cd->dr.syncs >= cd->args.syncs) ||
	       (cd->args.seconds > 0 && (double)(t_us - t0_us) >= cd->args.seconds * 1e6);
}

static int run(struct cd *cd)
{
	struct pollfd pfd = { .fd = cd->sock.fd, .events = POLLIN };
	uint64_t t0 = now_us(), t = t0;

	for (unsigned k = 0; k < cd->dr.n; k++)
		cd->nmt_seen[k] = (enum irdm_co_nmt_state)0xFF;
	while (!done(cd, t0, t)) {
		uint64_t next = irdm_can_drives_wall(&cd->dr, t);
		int timeout_ms = POLL_MAX_MS;

		if (next != UINT64_MAX && next - t < 1000u * POLL_MAX_MS)
			timeout_ms = (int)((next - t + 999u) / 1000u);
		if (poll(&pfd, 1, next <= t ? 0 : timeout_ms) < 0 && errno != EINTR)
			return fail(CD_EXIT_LINK, "poll on the CAN socket failed");
		/* what arrives is stamped now: the deadlines count from it */
		(void)irdm_can_drives_wall(&cd->dr, now_us());
		if (irdm_can_drives_poll(&cd->dr) == IRDM_EIO) {
			snprintf(cd->err, sizeof(cd->err), "%s: the link went down (%s) at SYNC %llu",
				 cd->args.ifname, cd->sock.bus_off ? "bus-off" : "interface down",
				 (unsigned long long)cd->dr.syncs);
			return fail(CD_EXIT_LINK, cd->err);
		}
		report_states(cd);
		t = now_us();
	}
	return CD_EXIT_OK;
}

static void summary(const struct cd *cd)
{
	const struct irdm_can_drives *dr = &cd->dr;

	printf("irdm-candrives: %llu SYNCs, TPDOs %llu sent %llu dropped %llu delayed, "
	       "%llu faults fired, %llu flood frames, %llu bad frames, %llu error frames\n",
	       (unsigned long long)dr->syncs, (unsigned long long)dr->tpdos_sent,
	       (unsigned long long)dr->tpdos_dropped, (unsigned long long)dr->tpdos_delayed,
	       (unsigned long long)dr->faults_fired, (unsigned long long)dr->flood_sent,
	       (unsigned long long)dr->bad_frames, (unsigned long long)cd->sock.error_frames);
}

int main(int argc, char **argv)
{
	static struct cd cd;
	struct sigaction sa;
	int rc;

	rc = cd_args_parse(&cd.args, argc, argv);
	if (rc >= 0)
		return rc;
	cd.sock.fd = -1;
	rc = set_up(&cd);
	if (rc < 0) {
		memset(&sa, 0, sizeof(sa));
		sa.sa_handler = on_signal; /* no SA_RESTART: poll returns EINTR */
		sigaction(SIGINT, &sa, NULL);
		sigaction(SIGTERM, &sa, NULL);
		setvbuf(stdout, NULL, _IOLBF, 0);
		rc = run(&cd);
		if (!cd.args.quiet)
			summary(&cd);
	}
	irdm_socketcan_close(&cd.sock);
	free(cd.user);
	return rc;
}
