/* SPDX-License-Identifier: MIT */
/* The report's CSV rows (one per representation, period and scenario). */
#include <math.h>
#include <stdio.h>

#include "report/report.h"

void irdm_report_csv_header(FILE *f)
{
	fputs("config,repr,dt_ms,scenario,force_err,force_err_first10,force_err_after100,disp_err,"
	      "tick_median_us,tick_p99_us,image_bytes,spectral_radius,cert_stable,run_bounded,"
	      "raw_growth,ticks,paper,keys\n",
	      f);
}

void irdm_report_csv_row(FILE *f, const struct irdm_report_row *r)
{
	fprintf(f, "%s,%s,%g,%s,%.6e,%.6e,%.6e,%.6e,%.4f,%.4f,%zu,%.8f,%d,%d,%.6e,%zu,%d,\"%s\"\n",
		r->config, r->repr, r->dt_s * 1e3, r->scenario, r->force_err, r->force_err_first10,
		r->force_err_after100, r->disp_err, r->tick_median_us, r->tick_p99_us,
		r->image_bytes, r->spectral_radius, r->cert_stable, r->run_bounded, r->raw_growth,
		r->ticks, r->paper, r->keys);
}
