/* SPDX-License-Identifier: MIT */
/* A telemetry log (irdm/telemetry.h) as CSV: `irdm log export`. */
#ifndef IRDM_TOOLS_LOG_CSV_H
#define IRDM_TOOLS_LOG_CSV_H

#include <stddef.h>

/*
 * Write the log at log_path as CSV to csv_path: a header row whose column
 * names carry their units, then one row per record (columns in
 * irdm_log_csv_columns_help).  The log is validated whole first (a bad or
 * truncated log writes nothing); the CSV goes to CSV_PATH.tmp, renamed
 * into place once complete, so a failure never leaves a partial CSV.
 *
 * Return: IRDM_OK; the errors of irdm_log_open() and irdm_log_next();
 * IRDM_EINVAL if csv_path is too long; IRDM_EIO if the CSV cannot be
 * written or renamed.  err says why and
 * names the file.
 */
int irdm_log_export_csv(const char *log_path, const char *csv_path, char *err, size_t errlen);

/* The columns, described for --help. */
extern const char irdm_log_csv_columns_help[];

#endif
