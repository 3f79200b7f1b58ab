/* SPDX-License-Identifier: MIT */
/* The CLI's one-line failure message: command, error name, reason. */
#include <stdio.h>

#include "cli.h"
#include "irdm/error.h"

void irdm_cli_fail(const char *cmd, int code, const char *reason)
{
	fprintf(stderr, "irdm %s: %s: %s\n", cmd, irdm_errname(code), reason);
}
