/* SPDX-License-Identifier: MIT */
/* Output directories written whole or not at all (irdm/outdir.h). */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/outdir.h"

#define OUTDIR_PATH_MAX 4200

void irdm_outdir_remove(const char *dir)
{
	char path[OUTDIR_PATH_MAX];
	struct dirent *d;
	DIR *h = opendir(dir);

	while (h && (d = readdir(h))) {
		if (!strcmp(d->d_name, ".") || !strcmp(d->d_name, ".."))
			continue;
		snprintf(path, sizeof(path), "%s/%s", dir, d->d_name);
		remove(path);
	}
	if (h)
		closedir(h);
	rmdir(dir);
}

int irdm_outdir_begin(const char *dir, char *tmp, size_t len)
{
	if ((size_t)snprintf(tmp, len, "%s.old", dir) >= len ||
	    (size_t)snprintf(tmp, len, "%s.tmp", dir) >= len)
		return ENAMETOOLONG;
	irdm_outdir_remove(tmp);
	return mkdir(tmp, 0777) ? errno : 0;
}

int irdm_outdir_commit(const char *dir, const char *tmp)
{
	char old[OUTDIR_PATH_MAX];
	int had_old, e = 0;

	if ((size_t)snprintf(old, sizeof(old), "%s.old", dir) >= sizeof(old)) {
		e = ENAMETOOLONG;
		goto out_remove_tmp;
	}
	irdm_outdir_remove(old);
	had_old = rename(dir, old) == 0;
	if (!had_old && errno != ENOENT) {
		e = errno;
		goto out_remove_tmp;
	}
	if (rename(tmp, dir)) {
		e = errno;
		if (had_old)
			rename(old, dir);
		goto out_remove_tmp;
	}
	if (had_old)
		irdm_outdir_remove(old);
	return 0;
out_remove_tmp:
	irdm_outdir_remove(tmp);
	return e;
}
