/* SPDX-License-Identifier: MIT */
#ifndef IRDM_TOOLS_CLI_H
#define IRDM_TOOLS_CLI_H

struct irdm_cli_progress {
	int quiet;
	char stage[64];
	int last_pct;
	double t0;
};

void irdm_cli_progress(void *ctx, const char *stage, double fraction);

/* "irdm CMD: ENAME: reason" on stderr, code an IRDM_E* (irdm/error.h), so
 * scripts and tests can tell an I/O error from a bad input or no memory. */
void irdm_cli_fail(const char *cmd, int code, const char *reason);

int irdm_cmd_precompute(int argc, char **argv);
int irdm_cmd_image(int argc, char **argv);
int irdm_cmd_image_config(int argc, char **argv);
int irdm_cmd_replay(int argc, char **argv);
int irdm_cmd_log(int argc, char **argv);
int irdm_cmd_report(int argc, char **argv);
int irdm_cmd_render(int argc, char **argv);
int irdm_cmd_view(int argc, char **argv);

/*
 * The inputs irdm replay and irdm render share (cmd_replay.c): --image,
 * --contact, --sites, --displacement, --log, --board, --push, --passivity,
 * --solve, --coupling.  argv[*i] is one of them: set it in o (advancing *i
 * past its value) and return 1; not one: 0; a bad value: -1 (said).
 * irdm_cli_replay_check(): the set is complete and consistent (0), else -1 (said).
 */
struct irdm_replay_opts;
int irdm_cli_replay_option(struct irdm_replay_opts *o, int argc, char **argv, int *i,
			   const char *cmd);
int irdm_cli_replay_check(const struct irdm_replay_opts *o, const char *cmd);

#endif
