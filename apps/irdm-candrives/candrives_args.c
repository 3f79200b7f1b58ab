/* SPDX-License-Identifier: MIT */
/* irdm-candrives' arguments: one option table drives parsing and --help. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/options.h"
#include "irdm/posix/options_doc.h"

#include "candrives.h"

#define CA(member) IRDM_OPT_FIELD(struct cd_args, member)
#define CA_REF(member) IRDM_OPT_TEXT_REF(struct cd_args, member)

/* --fault WORD, repeatable: appended to the schedule. */
static int parse_fault(const struct irdm_opt *o, void *obj, const char *value, char *why,
		       size_t whylen)
{
	struct cd_args *a = obj;

	(void)o;
	if (a->n_faults == IRDM_CAN_FAULTS_MAX) {
		snprintf(why, whylen, "at most %d faults", IRDM_CAN_FAULTS_MAX);
		return IRDM_EFORMAT;
	}
	if (irdm_can_fault_parse(value, &a->fault[a->n_faults], why, whylen))
		return IRDM_EFORMAT;
	a->n_faults++;
	return IRDM_OK;
}

static const struct irdm_opt cd_opts[] = {
	{ .name = "board", .short_name = 'b', .type = IRDM_OPT_STRING, CA_REF(board), .metavar = "BOARD", .help = "the board file: the arm behind the drives; required" },
	{ .name = "if", .type = IRDM_OPT_STRING, CA_REF(ifname), .metavar = "IFACE", .help = "the SocketCAN interface (default vcan0)" },
	{ .name = "user", .type = IRDM_OPT_STRING, CA_REF(user), .metavar = "SCRIPT", .help = "virtual user script pushing the arm, time = SYNC count x period" },
	{ .name = "nodes", .type = IRDM_OPT_UNSIGNED, CA(nodes), .metavar = "N", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 3, .help = "drives, one per joint from the first (default 3)" },
	{ .name = "first-node", .type = IRDM_OPT_UNSIGNED, CA(first_node), .metavar = "ID", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 125, .help = "the first drive's node id (default 1)" },
	{ .name = "syncs", .type = IRDM_OPT_UNSIGNED, CA(syncs), .metavar = "N", .help = "stop after N SYNCs (default: never)" },
	{ .name = "seconds", .type = IRDM_OPT_DOUBLE, CA(seconds), .metavar = "S", .unit = "s", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 0, .max = 86400, .help = "stop after S seconds of wall clock (default: never)" },
	{ .name = "fault", .type = IRDM_OPT_CUSTOM, .parse = parse_fault, .metavar = "KIND:...", .help = "inject a fault (repeatable, up to 16): drop:NODE:SYNC:K, "
													 "delay:NODE:SYNC:K:US, heartbeat-stop:NODE:SYNC, emcy:NODE:SYNC:CODE, "
													 "fault:NODE:SYNC, "
													 "sdo-wrong:NODE, flood:SYNC:COUNT" },
	{ .name = "quiet", .short_name = 'q', .type = IRDM_OPT_FLAG, CA(quiet), .help = "no state changes or summary" },
	{ .name = "help", .short_name = 'h', .type = IRDM_OPT_FLAG, CA(help), .help = "this text" },
};

static const struct irdm_opt_table cd_table = {
	.what = "option",
	.see = "irdm-candrives --help",
	.opts = cd_opts,
	.n_opts = sizeof(cd_opts) / sizeof(cd_opts[0]),
};

static void usage(FILE *f)
{
	fputs("usage: irdm-candrives --board BOARD [--if IFACE] [--user SCRIPT] [--nodes N]\n"
	      "                      [--first-node ID] [--syncs N] [--seconds S] [--fault F]...\n"
	      "\n"
	      "CiA 402 drives in cyclic synchronous torque mode on a SocketCAN interface,\n"
	      "one per joint of the board's simulated arm: NMT, expedited SDO, RPDO1/TPDO1\n"
	      "at each SYNC (the arm moves one period per SYNC), heartbeats on the wall\n"
	      "clock, EMCY; faults injected on a schedule counted in SYNCs.\n\n",
	      f);
	irdm_opt_print_help(f, &cd_table, IRDM_OPT_STYLE_ARG);
	fputs("\nexit codes: 0 stopped (--syncs, --seconds, SIGINT, SIGTERM); 2 bad\n"
	      "arguments; 3 board or user script refused; 4 the interface could not be\n"
	      "opened; 5 the link went down during the run\n",
	      f);
}

int cd_args_parse(struct cd_args *a, int argc, char **argv)
{
	struct irdm_opt_set set = { &cd_table, a };
	char err[256];

	memset(a, 0, sizeof(*a));
	a->ifname = "vcan0";
	a->nodes = 3;
	a->first_node = 1;
	if (irdm_opt_parse_args(&set, 1, argc - 1, argv + 1, NULL, NULL, err, sizeof(err))) {
		fprintf(stderr, "irdm-candrives: %s\n", err);
		return CD_EXIT_USAGE;
	}
	if (a->help) {
		usage(stdout);
		return CD_EXIT_OK;
	}
	if (!a->board) {
		fprintf(stderr, "irdm-candrives: missing --board BOARD\n");
		return CD_EXIT_USAGE;
	}
	return -1;
}
