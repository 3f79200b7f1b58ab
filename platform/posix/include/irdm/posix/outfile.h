/* SPDX-License-Identifier: MIT */
/*
 * An output file written whole or not at all, and never over something
 * that is not a file: the bytes go to a fresh name beside PATH
 * (PATH.irdm-tmp.XXXXXX, made by mkstemp, so no file of the user's is
 * overwritten on the way), which is renamed onto PATH once every write,
 * the flush, the sync and the close succeeded.  PATH may be replaced only
 * when it is missing or a regular file.  Any failure removes the temporary
 * and leaves PATH as it was.  The writer holds a lock (flock) on its
 * temporary until the rename: one beside PATH that nobody holds was left by
 * a killed writer, and the next open of PATH removes it.  Init- and
 * exit-time only (file system calls).
 */
#ifndef IRDM_OUTFILE_H
#define IRDM_OUTFILE_H

#include <stdio.h>

#define IRDM_OUTFILE_PATH_MAX 4096

struct irdm_outfile {
	FILE *f;                 /* write here; NULL when none */
	int lock_fd;             /* holds the temporary's lock; -1 when none */
	unsigned debris_removed; /* killed writers' temporaries removed at open */
	char path[IRDM_OUTFILE_PATH_MAX];
	char tmp[IRDM_OUTFILE_PATH_MAX + 32];
};

/*
 * Make the temporary beside path, open for writing.  Return: IRDM_OK;
 * IRDM_EEXIST (path is there and not a regular file); IRDM_EINVAL (path
 * too long); IRDM_EIO.  err: "path: reason".
 */
int irdm_outfile_open(struct irdm_outfile *o, const char *path, char *err, size_t errlen);

/*
 * Flush, sync, close and rename onto path.  Return: IRDM_OK; IRDM_EIO if
 * any of them failed or the stream had a write error (the temporary is
 * removed, path untouched; err names path and the reason); IRDM_EEXIST as
 * irdm_outfile_open() should path have become something else meanwhile.
 */
int irdm_outfile_commit(struct irdm_outfile *o, char *err, size_t errlen);

/* Close and remove the temporary; nothing if none. */
void irdm_outfile_abort(struct irdm_outfile *o);

/*
 * Remove the temporaries beside path (PATH.irdm-tmp.XXXXXX, regular files)
 * that no live writer holds locked; removed(path, ctx) for each if not
 * NULL.  Return how many.
 */
unsigned irdm_outfile_remove_debris(const char *path, void (*removed)(const char *path, void *ctx),
				    void *ctx);

#endif
