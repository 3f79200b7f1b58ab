/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw: the controller.  Reads the board and the image, brings the
 * device up through the HAL, sets up real time, runs the force loop and
 * shuts down with the torque off first.  `irdm-fw --help` for the
 * arguments and exit codes; docs/architecture.md for the loop.
 */
#include <math.h>
#include <signal.h>
#include <stdalign.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "irdm/board.h"
#include "irdm/error.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/rt.h"
#include "irdm/posix/session.h"

#include "fw.h"

#define FORCE_STACK_BYTES (256u * 1024u) /* pre-faulted for the loop */
#define TASKS_MAX 64                     /* threads listed at start */

static volatile sig_atomic_t signalled;

/* One line on stderr, "irdm-fw: ENAME: reason", and the exit code. */
static int fail(int exit_code, int rc, const char *fmt, const char *what, const char *why)
{
	fprintf(stderr, "irdm-fw: %s: ", irdm_errname(rc));
	fprintf(stderr, fmt, what, why);
	fputc('\n', stderr);
	return exit_code;
}

/* The virtual user's script, met with the board (fw_user.c). */
static int open_user(struct fw *fw)
{
	const struct fw_backend *be = fw_backend_of(fw->board.hal);
	int rc;

	if (!be || !be->simulated_arm)
		return fail(FW_EXIT_INPUT, IRDM_EINVAL, "--user %s: %s", fw->args.user,
			    fw_user_hal_why(fw));
	rc = fw_user_open(fw);
	if (rc)
		return fail(rc == IRDM_ENOMEM ? FW_EXIT_SETUP : FW_EXIT_INPUT, rc, "%s%s", "",
			    fw->err);
	return FW_EXIT_OK;
}

/* What the image is and how far it is from the exact model, first: the
 * figure says what the forces felt are worth. */
static void print_image(const struct fw *fw)
{
	const struct irdm_meta *m = fw->s->img->meta;

	if (fw->args.quiet)
		return;
	if (m->representation == IRDM_REPR_FIR)
		printf("image: %s: FIR of %u samples", fw->args.image, m->fir_length);
	else
		printf("image: %s: modal, %u of %u modes%s%s", fw->args.image, m->n_modes,
		       m->n_modes_total, m->flags & IRDM_META_STATIC_CORR ? " + static correction" : "",
		       m->flags & IRDM_META_EXACT_HEAD ? " + exact head" : "");
	if (m->flags & IRDM_META_ERROR_MEASURED)
		printf("; force error %.3g against the exact model\n", (double)m->measured_error);
	else
		printf("; force error not measured\n");
	if (fw->board.devices < 2)
		return;
	/* two hands: the figure above is one contact's */
	if (fw->s->img->two_contacts_error >= 0)
		printf("image: two contacts at once: force error %.3g against the exact model\n",
		       fw->s->img->two_contacts_error);
	else
		printf("image: two contacts at once: force error not measured\n");
}

static int open_inputs(struct fw *fw)
{
	struct irdm_session_config sc = { .deform = false };
	double dt_us;
	int rc;

	rc = irdm_board_load(&fw->board, fw->args.board, fw->err, sizeof(fw->err));
	if (!rc)
		rc = fw_backend_check_built(fw);
	if (rc)
		return fail(FW_EXIT_INPUT, rc, "%s%s", "", fw->err);
	rc = fw_config_from_board(&fw->ccfg, &fw->board);
	if (rc)
		return fail(FW_EXIT_INPUT, rc, "%s: %s", fw->args.board,
			    "the controller refuses this board's arm, limits or placement");
	sc.engine = fw->ccfg.engine;
	fw_frame_config(fw, &sc);
	rc = irdm_session_open(&fw->s, fw->args.image, &sc, fw->err, sizeof(fw->err));
	if (rc)
		return fail(FW_EXIT_INPUT, rc, "%s%s", "", fw->err);
	dt_us = fw->s->img->meta->dt_s * 1e6;
	if (fabs(dt_us - fw->board.period_us) > 1.0) {
		snprintf(fw->err, sizeof(fw->err), "image dt is %.0f us but the board's period_us is %u",
			 dt_us, fw->board.period_us);
		return fail(FW_EXIT_INPUT, IRDM_EINVAL, "%s: %s", fw->args.image, fw->err);
	}
	print_image(fw);
	return fw->args.user ? open_user(fw) : FW_EXIT_OK;
}

/* A device's info, each line as "hal 'NAME': line". */
static void print_info(const char *hal, const char *info)
{
	while (*info) {
		size_t n = strcspn(info, "\n");

		printf("hal '%s': %.*s\n", hal, (int)n, info);
		info += n + (info[n] == '\n');
	}
}

/* The board's hal_options, refused with the file and line they came from. */
static int check_hal_options(struct fw *fw, const struct irdm_hal_backend *be)
{
	char where[320];
	int rc;

	if (!be->check_options)
		return FW_EXIT_OK;
	if (fw->board.hal_options_line)
		snprintf(where, sizeof(where), "%s:%u: hal_options", fw->args.board,
			 fw->board.hal_options_line);
	else /* not in the file: a back-end that needs options names them */
		snprintf(where, sizeof(where), "%s: hal_options", fw->args.board);
	rc = be->check_options(fw->board.hal_options, where, fw->err, sizeof(fw->err));
	if (rc)
		return fail(FW_EXIT_SETUP, rc, "%s%s", "", fw->err);
	return FW_EXIT_OK;
}

static int open_devices(struct fw *fw)
{
	const struct irdm_hal_backend *be;
	int rc;

	fw_backends_register();
	be = irdm_hal_find(fw->board.hal);
	if (!be)
		return fail(FW_EXIT_SETUP, IRDM_ENOTSUP, "hal '%s': %s", fw->board.hal,
			    "no such back-end in this build");
	rc = check_hal_options(fw, be);
	if (rc)
		return rc;
	for (unsigned i = 0; i < fw->board.devices; i++) {
		irdm_board_device(&fw->board, i, &fw->dev[i]);
		fw->hcfg[i] = (struct irdm_hal_config){ &fw->dev[i], fw->board.hal_options,
							fw->board.period_us * 1e-6 };
		fw->hal_mem[i] = aligned_alloc(alignof(max_align_t),
					       (be->data_size + alignof(max_align_t) - 1) /
						       alignof(max_align_t) * alignof(max_align_t));
		if (!fw->hal_mem[i])
			return fail(FW_EXIT_SETUP, IRDM_ENOMEM, "hal '%s': %s", fw->board.hal,
				    "out of memory");
		rc = irdm_hal_init(&fw->hal[i], fw->board.hal, &fw->hcfg[i], fw->hal_mem[i],
				   be->data_size);
		if (!rc)
			rc = irdm_hal_open(&fw->hal[i]);
		fw->hal_open[i] = !rc;
		if (!rc)
			rc = fw_user_attach(fw, i);
		if (rc) {
			/* the board's file: what the back-end refused is in it */
			snprintf(fw->err, sizeof(fw->err), "%s: hal '%s'", fw->args.board,
				 fw->board.hal);
			return fail(FW_EXIT_SETUP, rc, "%s: %s", fw->err,
				    fw->hal[i].why[0] ? fw->hal[i].why : "the device does not open");
		}
		if (fw->hal[i].info[0] && !fw->args.quiet)
			print_info(fw->board.hal, fw->hal[i].info);
	}
	return FW_EXIT_OK;
}

/* Enable the drives: last, once real time is set up and every thread runs
 * (a drive's deadline must not see the set-up's silences).  A signal that
 * came during the set-up ends the run here, no drive enabled (one after
 * the check is the loop's first tick's to answer). */
static int start_devices(struct fw *fw)
{
	int rc;

	for (unsigned i = 0; i < fw->board.devices; i++) {
		if (signalled)
			return FW_EXIT_SIGNAL;
		rc = irdm_hal_start(&fw->hal[i]);
		if (rc)
			return fail(FW_EXIT_SETUP, rc, "hal '%s': %s", fw->board.hal,
				    fw->hal[i].why[0] ? fw->hal[i].why : "the drives do not start");
	}
	return FW_EXIT_OK;
}

/*
 * Every CPU kept out of idle states that are slow to leave, as cyclictest
 * does: otherwise the loop's CPU, idle for most of each period, sleeps
 * deeply (on a virtual machine the host deschedules it) and every wake
 * pays for leaving that state.  Held until the run stops (the kernel drops
 * it too if the process dies).
 */
static void hold_idle(struct fw *fw)
{
	int32_t us;

	fw->idle_hold = irdm_rt_cpu_latency_hold(0);
	if (fw->args.quiet)
		return;
	us = irdm_rt_cpu_latency_us();
	if (fw->idle_hold >= 0)
		printf("idle states: none slower than %d us to leave, while the loop runs "
		       "(/dev/cpu_dma_latency)\n",
		       (int)us);
	else
		printf("idle states: not limited (/dev/cpu_dma_latency: %s); the loop's wake-ups "
		       "pay for leaving them\n",
		       irdm_strerror(fw->idle_hold));
}

/*
 * Real time as the board asks (real clock only), then report what was
 * granted, read back; --require-rt refuses to run on less (libfranka-style:
 * never claim real time that was not given).
 */
static int setup_realtime(struct fw *fw)
{
	struct irdm_rt_sched sched = { SCHED_FIFO, fw->board.force_priority, fw->board.cpu };
	struct irdm_rt_report rep;
	char line[256];

	if (fw->args.clock == IRDM_CLOCK_VIRTUAL) {
		if (fw->args.require_rt)
			return fail(FW_EXIT_USAGE, IRDM_EINVAL, "%s%s", "",
				    "--require-rt needs --clock real");
		return FW_EXIT_OK;
	}
	irdm_rt_lock_memory();
	irdm_rt_set_self(&sched);
	/* absolute sleeps wake on time, not up to the 50 us default slack later */
	prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
	irdm_rt_prefault_stack(FORCE_STACK_BYTES);
	irdm_rt_report_get(&rep);
	irdm_rt_report_format(&rep, line, sizeof(line));
	if (!fw->args.quiet)
		printf("%s\n", line);
	hold_idle(fw);
	if (fw->args.require_rt && !irdm_rt_report_realtime(&rep))
		return fail(FW_EXIT_SETUP, IRDM_EPERM, "%s: %s", "--require-rt", line);
	return FW_EXIT_OK;
}

/*
 * The loop's CPU to the loop alone, once every thread is up (a BLAS pool
 * started before main has the whole machine in its mask), and every
 * thread listed as the system schedules it, read back: one that may still
 * run on the loop's CPU is named, and --require-rt refuses it.
 */
static int isolate_loop(struct fw *fw)
{
	struct irdm_rt_task tasks[TASKS_MAX];
	pid_t loop = (pid_t)syscall(SYS_gettid);
	int cpu = fw->board.cpu, intruders;
	char line[160];
	size_t n;

	if (fw->args.clock != IRDM_CLOCK_REAL)
		return FW_EXIT_OK;
	if (cpu >= 0)
		irdm_rt_isolate_cpu(cpu, loop);
	intruders = irdm_rt_isolation_check(cpu, loop, tasks, TASKS_MAX, &n);
	for (size_t i = 0; i < n && !fw->args.quiet; i++) {
		irdm_rt_task_format(&tasks[i], line, sizeof(line));
		printf("%s\n", line);
	}
	/* without a CPU of its own, the loop has none to keep */
	if (intruders == 0 || cpu < 0)
		return FW_EXIT_OK;
	if (intruders > 0)
		snprintf(line, sizeof(line), "%d other thread%s may run on the loop's CPU %d",
			 intruders, intruders == 1 ? "" : "s", cpu);
	else
		snprintf(line, sizeof(line), "the threads on the loop's CPU %d cannot be listed",
			 cpu);
	if (fw->args.require_rt)
		return fail(FW_EXIT_SETUP, IRDM_EPERM, "%s: %s", "--require-rt", line);
	fprintf(stderr, "irdm-fw: %s\n", line);
	return FW_EXIT_OK;
}

static uint64_t run_ticks(const struct fw *fw)
{
	double s = fw->args.duration_s;

	if (s <= 0)
		s = fw->user ? fw_user_end_s(fw) + 1.0 : 5.0;
	return (uint64_t)llround(s * 1e6 / fw->board.period_us);
}

static int start(struct fw *fw)
{
	int rc;

	if (fw_signals_arm(fw, &signalled))
		return fail(FW_EXIT_SETUP, IRDM_EIO, "%s%s", "", "cannot install the signal handlers");
	rc = open_inputs(fw);
	if (!rc)
		rc = open_devices(fw);
	if (rc)
		return rc;
	if (irdm_ctrl_init(&fw->ctrl, &fw->ccfg, fw->s))
		return fail(FW_EXIT_INPUT, IRDM_EINVAL, "%s%s", "", fw_ctrl_init_why(fw));
	fw->run_ticks = run_ticks(fw);
	if (fw_trace_alloc(&fw->trace, fw->run_ticks, fw->board.period_us))
		return fail(FW_EXIT_SETUP, IRDM_ENOMEM, "%s%s", "", "out of memory for the run's trace");
	rc = fw_frame_check_args(fw, fw->run_ticks);
	if (!rc)
		rc = fw_frame_claim_series(fw);
	if (rc)
		return fail(rc == IRDM_EIO ? FW_EXIT_SETUP : FW_EXIT_USAGE, rc, "%s%s", "", fw->err);
	rc = fw_frame_open(fw);
	if (rc)
		return fail(rc == IRDM_EINVAL ? FW_EXIT_INPUT : FW_EXIT_SETUP, rc, "%s: %s",
			    fw->args.image, fw->err);
	rc = fw_monitor_open(fw);
	if (rc)
		return fail(FW_EXIT_SETUP, rc, "%s%s", "", fw->err);
	rc = fw_log_open(fw);
	if (rc)
		return fail(FW_EXIT_SETUP, rc, "%s: %s", fw->args.log ? fw->args.log : "log", fw->err);
	rc = fw_view_open(fw);
	if (rc)
		return fail(rc == IRDM_EINVAL ? FW_EXIT_USAGE : FW_EXIT_SETUP, rc, "%s%s", "", fw->err);
	rc = setup_realtime(fw);
	if (rc)
		return rc;
	/* after the real-time set-up: the thread goes one level below it */
	rc = fw_frame_start(fw);
	if (!rc)
		rc = fw_monitor_start(fw);
	if (!rc)
		rc = fw_view_start(fw);
	if (rc)
		return fail(FW_EXIT_SETUP, rc, "%s%s", "", fw->err);
	rc = isolate_loop(fw);
	if (rc)
		return rc;
	return start_devices(fw);
}

/* Torque off first, then everything else.  The frame (--frame-at) is
 * written once the monitor and the worker are joined and while the image
 * is still mapped. */
static int stop(struct fw *fw, int rc)
{
	for (unsigned i = 0; i < IRDM_BOARD_DEVICES_MAX; i++)
		if (fw->hal_open[i])
			irdm_hal_safe_off(&fw->hal[i]);
	/* the monitor's last samples hold the frames' last contacts */
	fw_monitor_stop(fw);
	fw_frame_stop(fw);
	fw_view_close(fw);
	if (rc == FW_EXIT_OK || rc == FW_EXIT_FAULT || rc == FW_EXIT_NEVER_ENABLED) {
		int wrc = fw_frame_write(fw);
		/* a fault's exit code says more than the frame it cut short */
		if (wrc && fail(FW_EXIT_SETUP, wrc, "%s%s", "", fw->err) && rc == FW_EXIT_OK)
			rc = FW_EXIT_SETUP;
		wrc = fw_frame_write_series(fw);
		if (wrc && fail(FW_EXIT_SETUP, wrc, "%s%s", "", fw->err) && rc == FW_EXIT_OK)
			rc = FW_EXIT_SETUP;
	}
	/* the torque is off: the emergency path must not touch what closes */
	fw_signals_disarm();
	for (unsigned i = 0; i < IRDM_BOARD_DEVICES_MAX; i++) {
		if (fw->hal_open[i])
			irdm_hal_close(&fw->hal[i]);
		free(fw->hal_mem[i]);
	}
	/* a run whose log is lost says so in its exit code, not only in a line */
	if (fw->ring && fw_log_close(fw) && fail(FW_EXIT_LOG, IRDM_EIO, "%s%s", "", fw->err) &&
	    rc == FW_EXIT_OK)
		rc = FW_EXIT_LOG;
	irdm_rt_cpu_latency_release(fw->idle_hold);
	fw_user_free(fw);
	fw_monitor_free(fw);
	fw_frame_free(fw);
	irdm_session_close(fw->s);
	return rc;
}

/* The one line a run that did not end as asked for leaves on stderr. */
static void say_end(struct fw *fw, int rc)
{
	switch (rc) {
	case FW_EXIT_SIGNAL:
		fprintf(stderr, "irdm-fw: stopped by %s (signal %d) at tick %llu: torque off, state off\n",
			fw_signal_name((int)signalled), (int)signalled, (unsigned long long)fw->ticks);
		break;
	case FW_EXIT_FAULT:
		fprintf(stderr, "irdm-fw: EFAULT: fault %s at tick %llu: torque off%s%s\n",
			irdm_safety_fault_name(fw->last_cause), (unsigned long long)fw->ticks,
			fw_hal_why(fw)[0] ? ": " : "", fw_hal_why(fw));
		break;
	case FW_EXIT_NEVER_ENABLED:
		if (fw->enable_blocked)
			fprintf(stderr, "irdm-fw: EPERM: the torque was never enabled in %llu ticks: "
					"'%s' refused every request\n",
				(unsigned long long)fw->ticks,
				irdm_safety_fault_name(fw->enable_blocked));
		else
			fprintf(stderr, "irdm-fw: EPERM: the torque was never enabled in %llu ticks: "
					"the device was never calibrated\n",
				(unsigned long long)fw->ticks);
		break;
	default:
		break;
	}
}

int main(int argc, char **argv)
{
	struct fw *fw = calloc(1, sizeof(*fw));
	int rc;

	if (!fw)
		return fail(FW_EXIT_SETUP, IRDM_ENOMEM, "%s%s", "", "out of memory");
	fw->idle_hold = -1;
	rc = fw_args_parse(&fw->args, argc - 1, argv + 1, fw->err, sizeof(fw->err));
	if (rc || fw->args.help || fw->args.help_board || fw->args.doc) {
		if (fw->args.help || !rc) {
			if (fw->args.help)
				fw_args_usage(stdout);
			else if (fw->args.help_board)
				fw_help_board(stdout);
			else
				fw_write_doc(stdout, (enum fw_doc)fw->args.doc);
			free(fw);
			return FW_EXIT_OK;
		}
		/* the option table's messages point to --help already */
		rc = fail(FW_EXIT_USAGE, rc, "%s%s", fw->err,
			  strstr(fw->err, "--help") ? "" : " (see irdm-fw --help)");
		free(fw);
		return rc;
	}
	rc = start(fw);
	if (!rc) {
		fw_signals_loop(true);
		rc = fw_loop_run(fw, &signalled);
		fw_signals_loop(false);
		say_end(fw, rc);
	} else if (rc == FW_EXIT_SIGNAL) {
		say_end(fw, rc); /* during the set-up, no drive enabled */
	}
	rc = stop(fw, rc);
	/* a run stopped by a signal ended cleanly too: what it did is worth
	 * the same summary */
	if ((rc == FW_EXIT_OK || rc == FW_EXIT_FAULT || rc == FW_EXIT_NEVER_ENABLED ||
	     rc == FW_EXIT_SIGNAL || rc == FW_EXIT_LOG) &&
	    !fw->args.quiet)
		fw_summary_print(fw);
	fw_trace_free(&fw->trace);
	free(fw);
	return rc;
}
