/* SPDX-License-Identifier: MIT */
/*
 * An output directory written whole or not at all (irdm-fw's frame series,
 * irdm render's frames): the files go into DIR.tmp, which is then swapped
 * in for DIR (an old DIR is moved aside to DIR.old and removed after), so
 * DIR is always the old set or the whole new one.  Init-time only (file
 * system calls).  Directories hold files only, no subdirectories.
 */
#ifndef IRDM_OUTDIR_H
#define IRDM_OUTDIR_H

#include <stddef.h>

/* Make a fresh, empty DIR.tmp (its path into tmp, len bytes).
 * Return: 0; ENAMETOOLONG if DIR.old or DIR.tmp does not fit in len;
 * else the errno of mkdir. */
int irdm_outdir_begin(const char *dir, char *tmp, size_t len);

/* Swap tmp in for dir.  Return: 0, or errno (tmp is then removed and dir
 * is as it was). */
int irdm_outdir_commit(const char *dir, const char *tmp);

/* Remove dir and the files in it (a missing dir is fine). */
void irdm_outdir_remove(const char *dir);

#endif
