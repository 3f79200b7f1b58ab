/* SPDX-License-Identifier: MIT */
/* Output files written whole, under a fresh name, then renamed (irdm/posix/outfile.h). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/outfile.h"

/* A missing path or a regular file may be replaced; nothing else. */
static int check_target(const char *path, char *err, size_t errlen)
{
	struct stat st;

	if (lstat(path, &st) ? errno == ENOENT : S_ISREG(st.st_mode))
		return IRDM_OK;
	snprintf(err, errlen, "%s: exists and is not a regular file; not replaced", path);
	return IRDM_EEXIST;
}

unsigned irdm_outfile_remove_debris(const char *path, void (*removed)(const char *path, void *ctx),
				    void *ctx)
{
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	char dir[IRDM_OUTFILE_PATH_MAX], prefix[512], victim[IRDM_OUTFILE_PATH_MAX + 300];
	unsigned n = 0;
	size_t plen;
	struct dirent *d;
	DIR *h;

	if (slash)
		snprintf(dir, sizeof(dir), "%.*s", (int)(slash - path + (slash == path)), path);
	else
		snprintf(dir, sizeof(dir), ".");
	plen = (size_t)snprintf(prefix, sizeof(prefix), "%s%s", base, IRDM_OUTDIR_TMP);
	if (plen >= sizeof(prefix))
		return 0;
	h = opendir(dir);
	while (h && (d = readdir(h))) {
		int fd;

		if (strncmp(d->d_name, prefix, plen) || strlen(d->d_name) != plen + 6)
			continue;
		fd = openat(dirfd(h), d->d_name, O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
		if (fd < 0)
			continue;
		/* a writer alive holds the lock; a regular file only */
		if (!flock(fd, LOCK_EX | LOCK_NB) && !unlinkat(dirfd(h), d->d_name, 0)) {
			n++;
			snprintf(victim, sizeof(victim), "%s/%s", dir, d->d_name);
			if (removed)
				removed(victim, ctx);
		}
		close(fd);
	}
	if (h)
		closedir(h);
	return n;
}

int irdm_outfile_open(struct irdm_outfile *o, const char *path, char *err, size_t errlen)
{
	mode_t mask;
	int fd, ret;

	memset(o, 0, sizeof(*o));
	o->lock_fd = -1;
	if (strlen(path) >= sizeof(o->path)) {
		snprintf(err, errlen, "%.200s...: path too long", path);
		return IRDM_EINVAL;
	}
	strcpy(o->path, path);
	ret = check_target(path, err, errlen);
	if (ret)
		return ret;
	o->debris_removed = irdm_outfile_remove_debris(path, NULL, NULL);
	snprintf(o->tmp, sizeof(o->tmp), "%s%sXXXXXX", path, IRDM_OUTDIR_TMP);
	fd = mkstemp(o->tmp);
	if (fd < 0) {
		snprintf(err, errlen, "%s: cannot create %s: %s", path, o->tmp, strerror(errno));
		o->tmp[0] = 0;
		return IRDM_EIO;
	}
	/* held until the rename (a duplicate: the stream's close must not drop it) */
	o->lock_fd = dup(fd);
	if (o->lock_fd >= 0)
		flock(o->lock_fd, LOCK_EX);
	/* mkstemp's 0600 would hide the output from others: the umask decides */
	mask = umask(0);
	umask(mask);
	fchmod(fd, 0666 & ~mask);
	o->f = fdopen(fd, "w");
	if (!o->f) {
		snprintf(err, errlen, "%s: cannot open %s: %s", path, o->tmp, strerror(errno));
		close(fd);
		irdm_outfile_abort(o);
		return IRDM_EIO;
	}
	return IRDM_OK;
}

int irdm_outfile_commit(struct irdm_outfile *o, char *err, size_t errlen)
{
	int bad = ferror(o->f), e = 0, ret;

	if (fflush(o->f) || fsync(fileno(o->f)))
		e = errno;
	else if (bad)
		e = EIO;
	if (fclose(o->f) && !e)
		e = errno;
	o->f = NULL;
	if (e) {
		snprintf(err, errlen, "%s: not written: %s", o->path, strerror(e));
		irdm_outfile_abort(o);
		return IRDM_EIO;
	}
	ret = check_target(o->path, err, errlen);
	if (ret) {
		irdm_outfile_abort(o);
		return ret;
	}
	if (rename(o->tmp, o->path)) {
		snprintf(err, errlen, "%s: cannot rename into place: %s", o->path, strerror(errno));
		irdm_outfile_abort(o);
		return IRDM_EIO;
	}
	o->tmp[0] = 0;
	irdm_outfile_abort(o); /* the lock */
	return IRDM_OK;
}

void irdm_outfile_abort(struct irdm_outfile *o)
{
	if (o->f)
		fclose(o->f);
	o->f = NULL;
	if (o->tmp[0])
		unlink(o->tmp);
	o->tmp[0] = 0;
	if (o->lock_fd >= 0)
		close(o->lock_fd);
	o->lock_fd = -1;
}
