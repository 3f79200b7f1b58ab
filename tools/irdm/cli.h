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

int irdm_cmd_precompute(int argc, char **argv);
int irdm_cmd_image(int argc, char **argv);
int irdm_cmd_replay(int argc, char **argv);
int irdm_cmd_log(int argc, char **argv);

#endif
