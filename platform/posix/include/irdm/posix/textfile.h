/* SPDX-License-Identifier: MIT */
/*
 * Reading an input file so that no input can hang or mislead a reader.
 *
 * irdm_file_open_regular() opens non-blocking (a FIFO or a device never
 * blocks the open), checks that the path is a regular file no larger than
 * a bound, then makes the descriptor blocking again for the reads.
 *
 * A text file is then read line by line: a NUL byte (a binary file, or
 * /dev/zero's kind) and a line longer than the reader's buffer are refused
 * naming the file and the line; so is more text than the bound, should
 * the file grow while read.  Init-time only (stdio).
 */
#ifndef IRDM_TEXTFILE_H
#define IRDM_TEXTFILE_H

#include <stddef.h>
#include <stdio.h>

/* Bounds of the project's text inputs: far above any real one. */
#define IRDM_TEXT_MAX_BYTES (16u << 20)
#define IRDM_DATA_MAX_BYTES (4ull << 30) /* trajectories, logs, parts */

/*
 * Open path for reading; *fd on success.  Return: IRDM_OK; IRDM_EIO (cannot
 * open, not a regular file: "NAME: not a regular file (a FIFO)"); IRDM_ERANGE
 * (larger than max_bytes).  err: "path: reason".
 */
int irdm_file_open_regular(const char *path, size_t max_bytes, int *fd, char *err,
			   size_t errlen);

/* irdm_file_open_regular(), as a stdio stream (binary or text). */
int irdm_file_fopen(const char *path, size_t max_bytes, FILE **f, char *err, size_t errlen);

struct irdm_text_file {
	FILE *f;
	const char *name;
	unsigned line_no; /* of the line last read, from 1 */
	size_t bytes, max_bytes;
};

/* irdm_file_open_regular(), as a text file.  Return as it. */
int irdm_text_open(struct irdm_text_file *t, const char *path, size_t max_bytes, char *err,
		   size_t errlen);

/*
 * The next line into buf (len bytes: at most len - 1 characters; the
 * newline is dropped).  Return: 1 a line, 0 the end; IRDM_EFORMAT (a NUL
 * byte, a line too long: "path:line: ..."), IRDM_ERANGE (past max_bytes),
 * IRDM_EIO (a read error).
 */
int irdm_text_line(struct irdm_text_file *t, char *buf, size_t len, char *err, size_t errlen);

void irdm_text_close(struct irdm_text_file *t);

#endif
