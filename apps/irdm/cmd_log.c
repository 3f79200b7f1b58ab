/* SPDX-License-Identifier: MIT */
/* irdm log export: a telemetry log from irdm-fw as CSV. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "log/log_csv.h"

static const char usage[] =
	"usage: irdm log export LOG -o FILE.csv\n"
	"\n"
	"LOG is a telemetry log written by irdm-fw --log (one record per tick).\n"
	"export validates the whole log first (magic, version, record size,\n"
	"length): a bad or truncated log is an error and writes nothing.  The\n"
	"CSV has a header row and one row per tick.\n"
	"Exit: 0 done, 1 bad log or write error, 2 usage.\n"
	"\n";

static int print_usage(FILE *f, int code)
{
	fputs(usage, f);
	if (f == stdout)
		fputs(irdm_log_csv_columns_help, f);
	return code;
}

static int cmd_export(int argc, char **argv)
{
	const char *log = NULL, *out = NULL;
	char err[1024];
	int rc;

	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h"))
			return print_usage(stdout, 0);
		if (!strcmp(argv[i], "-o")) {
			if (i + 1 >= argc) {
				fprintf(stderr, "irdm log export: -o needs a value\n");
				return 2;
			}
			out = argv[++i];
		} else if (argv[i][0] == '-' && argv[i][1]) {
			fprintf(stderr, "irdm log export: unknown option '%s' (see --help)\n", argv[i]);
			return 2;
		} else if (!log) {
			log = argv[i];
		} else {
			fprintf(stderr, "irdm log export: one LOG only ('%s' is extra)\n", argv[i]);
			return 2;
		}
	}
	if (!log || !out) {
		fprintf(stderr, "irdm log export: needs LOG and -o FILE.csv (see --help)\n");
		return 2;
	}
	rc = irdm_log_export_csv(log, out, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("log export", rc, err);
		return 1;
	}
	return 0;
}

int irdm_cmd_log(int argc, char **argv)
{
	if (argc < 2)
		return print_usage(stderr, 2);
	if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))
		return print_usage(stdout, 0);
	if (!strcmp(argv[1], "export"))
		return cmd_export(argc - 1, argv + 1);
	fprintf(stderr, "irdm log: unknown subcommand '%s' (export)\n", argv[1]);
	return 2;
}
