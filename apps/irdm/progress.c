/* SPDX-License-Identifier: MIT */
/* Progress on a terminal: one rewritten line per stage; plain lines at 25 %
 * steps when stderr is not a terminal (logs, CI). */
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "util/clock.h"

void irdm_cli_progress(void *ctx, const char *stage, double fraction)
{
	struct irdm_cli_progress *p = ctx;
	int tty = isatty(STDERR_FILENO);
	int pct = (int)(fraction * 100.0 + 0.5);

	/* a line of its own: warnings even when quiet */
	if (fraction < 0) {
		if (!p->quiet || !strncmp(stage, "warning:", 8))
			fprintf(stderr, "%s%s\n", tty && p->stage[0] ? "\n" : "", stage);
		p->stage[0] = 0;
		return;
	}
	if (p->quiet)
		return;
	if (p->t0 == 0)
		p->t0 = irdm_now_s();
	if (strcmp(stage, p->stage)) {
		if (tty && p->stage[0])
			fputc('\n', stderr);
		snprintf(p->stage, sizeof(p->stage), "%s", stage);
		p->last_pct = -100;
	}
	if (tty) {
		fprintf(stderr, "\r  %-24s %3d%%  (%.1f s)", stage, pct, irdm_now_s() - p->t0);
		if (pct >= 100) {
			fputc('\n', stderr);
			p->stage[0] = 0;
		}
	} else if (pct >= p->last_pct + 25 || (pct >= 100 && p->last_pct < 100)) {
		fprintf(stderr, "  %s %d%% (%.1f s)\n", stage, pct, irdm_now_s() - p->t0);
		p->last_pct = pct;
	}
	fflush(stderr);
}
