/* SPDX-License-Identifier: MIT */
/*
 * irdm-candrives: N CiA 402 drives (sim/can) as one process on a SocketCAN
 * interface, the arm of a board file behind them, optionally pushed by a
 * virtual user's script (time = SYNC count x period).  Internal header of
 * apps/irdm-candrives.
 */
#ifndef IRDM_CANDRIVES_H
#define IRDM_CANDRIVES_H

#include <stdbool.h>
#include <stdint.h>

#include "irdm/sim/can_faults.h"

enum {
	CD_EXIT_OK = 0,    /* stopped by --syncs, --seconds or a signal */
	CD_EXIT_USAGE = 2, /* bad arguments */
	CD_EXIT_INPUT = 3, /* board or user script refused */
	CD_EXIT_SETUP = 4, /* the CAN interface could not be opened */
	CD_EXIT_LINK = 5,  /* the link went down during the run */
};

struct cd_args {
	const char *board, *user, *ifname;
	unsigned nodes, first_node;
	uint64_t syncs; /* stop after this many SYNCs (0: never) */
	double seconds; /* stop after this long (0: never) */
	bool quiet, help;
	struct irdm_can_fault fault[IRDM_CAN_FAULTS_MAX];
	unsigned n_faults;
};

/* argv into *a; prints help (exit 0) or a one-line error (exit 2) itself.
 * Return: -1 to go on, else the exit code. */
int cd_args_parse(struct cd_args *a, int argc, char **argv);

#endif /* IRDM_CANDRIVES_H */
