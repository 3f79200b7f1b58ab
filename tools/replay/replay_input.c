/* SPDX-License-Identifier: MIT */
/*
 * irdm replay's inputs: the displacement trajectory and the per-sample
 * contact sites, CSV on the image's time grid, each value checked (a bad
 * row is named by file and line).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/limits.h"
#include "irdm/posix/textfile.h"
#include "replay/replay_priv.h"

/* ---- trajectory CSV ---- */

static int parse_line(char *line, double *v, size_t want, size_t *got)
{
	char *p = line;
	size_t k = 0;

	for (;;) {
		while (*p == ' ' || *p == '\t')
			p++;
		if (k == want)
			return -1;
		if (*p == ',' || *p == '\n' || *p == '\r' || *p == 0) {
			v[k++] = NAN; /* empty: released */
		} else {
			char *end;
			v[k++] = strtod(p, &end);
			if (end == p)
				return -2; /* not a number */
			p = end;
			while (*p == ' ' || *p == '\t')
				p++;
		}
		if (*p == ',') {
			p++;
			continue;
		}
		if (*p == '\n' || *p == '\r' || *p == 0)
			break;
		return -2;
	}
	*got = k;
	return 0;
}

/* Rows of n_cols numbers on the image's time grid (column 0: t). */
static int read_table(const char *path, size_t n_cols, double dt, struct trajectory *tr,
		      char *err, size_t errlen)
{
	FILE *f;
	char line[4096];
	size_t cap = 0, lineno = 0;
	int ret = IRDM_EFORMAT;

	memset(tr, 0, sizeof(*tr));
	tr->n_cols = n_cols;
	if (irdm_file_fopen(path, IRDM_DATA_MAX_BYTES, &f, err, errlen))
		return IRDM_EIO;
	while (fgets(line, sizeof(line), f)) {
		double v[1 + 3 * IRDM_MAX_CONTACTS];
		size_t got = 0;
		lineno++;
		int rc = parse_line(line, v, n_cols, &got);
		if (rc == -2 && lineno == 1 && tr->n_rows == 0)
			continue; /* header */
		if (rc || got != n_cols) {
			snprintf(err, errlen, "%s:%zu: expected %zu numeric columns", path, lineno,
				 n_cols);
			goto out_fail;
		}
		double t_expect = (double)tr->n_rows * dt;
		if (!isfinite(v[0]) || fabs(v[0] - t_expect) > 1e-6 * dt + 1e-9 * fabs(t_expect)) {
			snprintf(err, errlen, "%s:%zu: t = %g, expected %g: one row per sample of the image's dt = %g s",
				 path, lineno, v[0], t_expect, dt);
			goto out_fail;
		}
		if (tr->n_rows == cap) {
			cap = cap ? 2 * cap : 1024;
			double *nv = realloc(tr->v, cap * n_cols * sizeof(double));
			if (!nv) {
				snprintf(err, errlen, "%s: out of memory", path);
				ret = IRDM_ENOMEM;
				goto out_fail;
			}
			tr->v = nv;
		}
		memcpy(&tr->v[tr->n_rows * n_cols], v, n_cols * sizeof(double));
		tr->n_rows++;
	}
	if (ferror(f)) {
		snprintf(err, errlen, "%s: read failed: %s", path, strerror(errno));
		ret = IRDM_EIO;
		goto out_fail;
	}
	fclose(f);
	if (!tr->n_rows) {
		snprintf(err, errlen, "%s: no samples", path);
		return IRDM_EFORMAT;
	}
	return IRDM_OK;
out_fail:
	fclose(f);
	free(tr->v);
	tr->v = NULL;
	return ret;
}

void irdm_trajectory_free(struct trajectory *tr)
{
	free(tr->v);
	tr->v = NULL;
}

int read_trajectory(const char *path, size_t n_contacts, double dt, struct trajectory *tr,
		    char *err, size_t errlen)
{
	int ret = read_table(path, 1 + 3 * n_contacts, dt, tr, err, errlen);

	for (size_t r = 0; !ret && r < tr->n_rows; r++)
		for (size_t k = 1; k < tr->n_cols; k++) {
			double v = tr->v[r * tr->n_cols + k];
			if (isinf(v) || fabs(v) > 10.0) {
				snprintf(err, errlen, "%s: row %zu: displacement %g m is out of range "
						      "(|u| <= 10 m)",
					 path, r + 1, v);
				ret = IRDM_EFORMAT;
				break;
			}
		}
	if (ret)
		irdm_trajectory_free(tr);
	return ret;
}

/* One contact's site on a row: -1 (none) or a triangle with barycentrics. */
static int check_site(const double *v, uint32_t n_tris, const char **why)
{
	double sum = 0;

	if (v[0] == -1)
		return 0;
	if (!(v[0] >= 0 && v[0] < n_tris && v[0] == floor(v[0]))) {
		*why = "triangle is not -1 or a surface triangle of the image";
		return -1;
	}
	for (int k = 1; k <= 3; k++) {
		if (!isfinite(v[k]) || v[k] < -1e-9) {
			*why = "barycentrics must be finite and >= 0";
			return -1;
		}
		sum += v[k];
	}
	if (fabs(sum - 1) > 1e-9) {
		*why = "barycentrics must sum to 1";
		return -1;
	}
	return 0;
}

int read_sites(const char *path, size_t n_contacts, double dt, uint32_t n_tris,
	       struct trajectory *tr, char *err, size_t errlen)
{
	int ret = read_table(path, 1 + 4 * n_contacts, dt, tr, err, errlen);
	const char *why = NULL;

	for (size_t r = 0; !ret && r < tr->n_rows; r++)
		for (size_t i = 0; i < n_contacts; i++)
			if (check_site(&tr->v[r * tr->n_cols + 1 + 4 * i], n_tris, &why)) {
				snprintf(err, errlen, "%s: row %zu, contact %zu: %s", path, r + 1,
					 i + 1, why);
				ret = IRDM_EFORMAT;
				break;
			}
	if (ret)
		irdm_trajectory_free(tr);
	return ret;
}

int sites_contacts(const char *path, unsigned *n, char *err, size_t errlen)
{
	FILE *f;
	char line[4096];
	size_t cols = 0;

	if (irdm_file_fopen(path, IRDM_DATA_MAX_BYTES, &f, err, errlen))
		return IRDM_EIO;
	while (fgets(line, sizeof(line), f)) {
		double v[1 + 4 * IRDM_MAX_CONTACTS];
		if (parse_line(line, v, 1 + 4 * IRDM_MAX_CONTACTS, &cols) == 0)
			break;
		cols = 0; /* the header: the next line says */
	}
	fclose(f);
	if (cols < 5 || (cols - 1) % 4) {
		snprintf(err, errlen, "%s: expected t, then tri, b0, b1, b2 per contact (at most %d)",
			 path, IRDM_MAX_CONTACTS);
		return IRDM_EFORMAT;
	}
	*n = (unsigned)((cols - 1) / 4);
	return IRDM_OK;
}
