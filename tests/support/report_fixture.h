/* SPDX-License-Identifier: MIT */
/* irdm report run from a test, and its CSV read back (cmocka inside). */
#ifndef IRDM_TESTS_REPORT_FIXTURE_H
#define IRDM_TESTS_REPORT_FIXTURE_H

#include <stddef.h>

#include "irdm/image.h"

/* One CSV row (tools/report/report_out.c's columns). */
struct rfx_row {
	char repr[48], scenario[32];
	double dt_ms;
	double force_err, first10, after100, disp_err, median_us, p99_us;
	size_t bytes;
	double radius;
	int cert_stable, bounded;
	double growth;
	size_t ticks;
	int paper;
};

/* `irdm report --config config -o DIR --keep-images -q` ($IRDM, default
 * build/irdm) into DIR = a new /tmp/irdm-report-XXXXXX/out, written to dir.
 * Return: 0, or -1 with the reason on stderr (for cmocka setups). */
int rfx_run(char *dir, size_t len, const char *config);

/* Remove what rfx_run made (dir and the directory around it). */
int rfx_remove(const char *dir);

/* The rows of DIR/report-CONFIG.csv, at most max; fails the test on a
 * row of another configuration or one it cannot parse.  Return: rows. */
int rfx_read_csv(const char *dir, const char *config, struct rfx_row *rows, int max);

/* The row of repr on scenario (NULL: any); fails the test if none. */
const struct rfx_row *rfx_row_of(const struct rfx_row *rows, int n, const char *repr,
				 const char *scenario);

/* The report's engine loop restated: a grab of the column nearest p on img
 * (a fresh engine, defaults, one contact) driven to target (N x 3, world
 * displacement from rest; NAN: let go); the contact force into F (N x 3). */
void rfx_engine_grab(const struct irdm_image *img, const double p[3], const double *target,
		     size_t N, double *F);

#endif
