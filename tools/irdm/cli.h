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

#endif
