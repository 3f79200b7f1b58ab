/* SPDX-License-Identifier: MIT */
/*
 * An output directory written whole or not at all, and never in place of
 * something its tool did not write (irdm-fw's frame series, irdm render's
 * frames).
 *
 * The files go into a fresh directory beside the target, DIR.irdm-tmp.XXXXXX,
 * which holds a marker file, .irdm-output: the tool's name and version, the
 * writer's pid, and once complete the names of the files written.  At the
 * end it takes DIR's place (an atomic exchange where the file system has
 * one) when DIR does not exist, is an empty directory, or holds exactly what
 * the same tool wrote there before (its complete marker and the files that
 * lists).  Anything else is refused, naming the path: a directory the tool
 * did not write unless force (then a directory of plain files is replaced),
 * and a non-directory always.  The replaced set is removed; nothing else is
 * touched.  A beside-directory left by a killed run (its marker names a pid
 * that no longer runs) is removed by the next run on the same DIR.
 *
 * One caller-owned struct per output.  Init- and exit-time only (file system
 * calls).  Directories hold files only, no subdirectories.
 */
#ifndef IRDM_OUTDIR_H
#define IRDM_OUTDIR_H

#include <stdbool.h>
#include <stddef.h>

#define IRDM_OUTDIR_PATH_MAX 4096
#define IRDM_OUTDIR_MARKER ".irdm-output"
#define IRDM_OUTDIR_TMP ".irdm-tmp." /* DIR.irdm-tmp.XXXXXX */

struct irdm_outdir {
	char dir[IRDM_OUTDIR_PATH_MAX];
	char tmp[IRDM_OUTDIR_PATH_MAX + 32]; /* where the files go; "" when none */
	char tool[64];                       /* "irdm-fw", "irdm render" */
	bool force;
	bool replace_foreign;                 /* forced over a directory we did not write */
	unsigned debris_removed;              /* killed runs' directories removed at begin */
	char why[IRDM_OUTDIR_PATH_MAX + 256]; /* one line naming the path, after a failure */
};

/*
 * Check that dir may be replaced (see above), remove the debris of killed
 * runs on it, and make the directory the files go into (od->tmp).
 * Return: IRDM_OK; IRDM_EEXIST (dir is not the tool's to replace);
 * IRDM_EINVAL (a path too long); IRDM_EIO (a system call failed).  od->why
 * says which path and why.
 */
int irdm_outdir_begin(struct irdm_outdir *od, const char *dir, const char *tool, bool force);

/*
 * Mark od->tmp complete (the files in it), check dir again (it may have
 * changed during the run) and put od->tmp in its place; the old set is
 * removed.  Return as irdm_outdir_begin(); on failure od->tmp is removed
 * and dir is as it was.
 */
int irdm_outdir_commit(struct irdm_outdir *od);

/* Remove od->tmp and the files in it (nothing if none).  Async-signal-safe. */
void irdm_outdir_abort(struct irdm_outdir *od);

/* Remove the files in dir (not its subdirectories), then dir.  Only
 * open(), getdents64, unlinkat(), close() and rmdir(): async-signal-safe,
 * so a signal handler may call it.  0 when dir is gone. */
int irdm_outdir_remove_files(const char *dir);

#endif
