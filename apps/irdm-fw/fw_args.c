/* SPDX-License-Identifier: MIT */
/* irdm-fw's arguments: one option table drives parsing and --help. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "irdm/posix/clock.h"
#include "irdm/error.h"
#include "irdm/options.h"
#include "irdm/posix/options_doc.h"

#include "fw.h"

#define FA(member) IRDM_OPT_FIELD(struct fw_args, member)
#define FA_REF(member) IRDM_OPT_TEXT_REF(struct fw_args, member)

static const struct irdm_opt_name clock_names[] = {
	{ "real", IRDM_CLOCK_REAL },
	{ "virtual", IRDM_CLOCK_VIRTUAL },
	{ NULL, 0 },
};

static const struct irdm_opt_name doc_names[] = {
	{ "boards", FW_DOC_BOARDS },
	{ "hal-options", FW_DOC_HAL_OPTIONS },
	{ NULL, 0 },
};

static const struct irdm_opt fw_opts[] = {
	{ .name = "board", .short_name = 'b', .type = IRDM_OPT_STRING, FA_REF(board), .metavar = "BOARD", .help = "the board file (docs/boards.md); required" },
	{ .name = "image", .short_name = 'i', .type = IRDM_OPT_STRING, FA_REF(image), .metavar = "IMAGE", .help = "the object's image (irdm precompute); required" },
	{ .name = "user", .type = IRDM_OPT_STRING, FA_REF(user), .metavar = "SCRIPT", .help = "virtual user script (sim boards; scenes/users/)" },
	{ .name = "duration", .type = IRDM_OPT_DOUBLE, FA(duration_s), .metavar = "S", .unit = "s", .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 86400, .help = "run time (default: the user script's end + 1 s, else 5 s)" },
	{ .name = "log", .type = IRDM_OPT_STRING, FA_REF(log), .metavar = "FILE", .help = "binary per-tick log (irdm log export FILE -o CSV)" },
	{ .name = "frame-at", .type = IRDM_OPT_DOUBLE, FA(frame_at_s), .metavar = "S", .unit = "s", .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 86400, .help = "write the deformed surface at time S to --frame-out (VTK; needs a "
																					"board with deform_rate_hz > 0)" },
	{ .name = "frame-out", .type = IRDM_OPT_STRING, FA_REF(frame_out), .metavar = "FILE", .help = "where --frame-at writes (legacy VTK POLYDATA, ASCII)" },
	{ .name = "frames-every", .type = IRDM_OPT_DOUBLE, FA(frames_every_s), .metavar = "S", .unit = "s", .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 86400, .help = "a deformed-surface frame every S seconds of the run into --frames-out "
																						"(at most 1000 frames)" },
	{ .name = "frames-out", .type = IRDM_OPT_STRING, FA_REF(frames_out), .metavar = "DIR", .help = "where --frames-every writes: frame_NNNNN.vtk and frames.vtk.series (ParaView "
												       "opens the series with time); replaced as a whole, and only if irdm-fw wrote it" },
	{ .name = "force", .type = IRDM_OPT_FLAG, FA(force), .help = "replace --frames-out DIR even if irdm-fw did not write it (a directory of "
								     "files only)" },
	{ .name = "view", .type = IRDM_OPT_STRING, FA_REF(view), .metavar = "[ADDR:]PORT", .help = "serve the live view (docs/view.md) on ADDR (default 127.0.0.1), PORT (0: any)" },
	{ .name = "clock", .type = IRDM_OPT_ENUM, FA(clock), .names = clock_names, .metavar = "real | virtual", .help = "real time paced at the board's period, or virtual time (deterministic, fast)" },
	{ .name = "require-rt", .type = IRDM_OPT_FLAG, FA(require_rt), .help = "refuse to run without PREEMPT_RT, SCHED_FIFO and locked memory, or with "
									       "another thread allowed on the loop's CPU" },
	{ .name = "quiet", .short_name = 'q', .type = IRDM_OPT_FLAG, FA(quiet), .help = "no summary" },
	{ .name = "help", .short_name = 'h', .type = IRDM_OPT_FLAG, FA(help), .help = "this text" },
	{ .name = "help-board", .type = IRDM_OPT_FLAG, FA(help_board), .help = "the board file's keys and each HAL back-end's hal_options, with their "
									       "defaults" },
	{ .name = "doc", .type = IRDM_OPT_ENUM, FA(doc), .names = doc_names, .metavar = "boards | hal-options", .help = "write a generated document to stdout: the key table of docs/boards.md, "
															"or docs/hal-options.md" },
};

static const struct irdm_opt_table fw_table = {
	.what = "option",
	.see = "irdm-fw --help",
	.opts = fw_opts,
	.n_opts = sizeof(fw_opts) / sizeof(fw_opts[0]),
};

void fw_args_usage(FILE *f)
{
	fputs("usage: irdm-fw --board BOARD --image IMAGE [--user SCRIPT] [--duration S]\n"
	      "               [--log FILE] [--frame-at S --frame-out FILE]\n"
	      "               [--frames-every S --frames-out DIR [--force]]\n"
	      "               [--clock real|virtual] [--require-rt] [--view [ADDR:]PORT]\n"
	      "\n"
	      "Runs the force loop on a board's device: HAL read, encoders, kinematics,\n"
	      "proxy on the deformed surface, force engine, J^T and limits, HAL write,\n"
	      "every period; torque off on any fault and on every signal.  The torque is\n"
	      "asked for from the second tick on and the request stands until the limits\n"
	      "(workspace, speed, encoders) allow it; once on, a fault ends the run.\n\n",
	      f);
	irdm_opt_print_help(f, &fw_table, IRDM_OPT_STYLE_ARG);
	fputs("\nexit codes: 0 ran to the end with the torque enabled; 2 bad arguments;\n"
	      "3 board, image or user script refused; 4 HAL, real time (--require-rt) or\n"
	      "memory refused; 5 the controller faulted (torque off, reason printed);\n"
	      "6 stopped by SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXCPU, SIGUSR1,\n"
	      "SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGPWR, SIGSTKFLT or a real-time\n"
	      "signal (torque off and state off in the next tick, logged; during the\n"
	      "set-up: no drive enabled); 7 the torque was never enabled (the limit\n"
	      "that refused it printed); 8 SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT,\n"
	      "SIGTRAP, SIGSYS or a second signal while the loop runs: torque off at\n"
	      "once by the emergency path, the log cut short; 9 the run ended but its\n"
	      "--log could not be written (no log is left under its name; SIGXFSZ is\n"
	      "ignored, so a log past the file-size limit ends here)\n",
	      f);
}

int fw_args_parse(struct fw_args *a, int argc, char **argv, char *err, size_t errlen)
{
	struct irdm_opt_set set = { &fw_table, a };
	int rc;

	memset(a, 0, sizeof(*a));
	a->clock = IRDM_CLOCK_REAL;
	rc = irdm_opt_parse_args(&set, 1, argc, argv, NULL, NULL, err, errlen);
	if (rc || a->help || a->help_board || a->doc)
		return rc;
	if (!a->board || !a->image) {
		snprintf(err, errlen, "%s", !a->board ? "missing --board BOARD" : "missing --image IMAGE");
		return IRDM_EINVAL;
	}
	if ((a->frame_at_s > 0) != (a->frame_out != NULL)) {
		snprintf(err, errlen, "%s", a->frame_out ? "--frame-out needs --frame-at S" : "--frame-at needs --frame-out FILE");
		return IRDM_EINVAL;
	}
	if ((a->frames_every_s > 0) != (a->frames_out != NULL)) {
		snprintf(err, errlen, "%s", a->frames_out ? "--frames-out needs --frames-every S" : "--frames-every needs --frames-out DIR");
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}
