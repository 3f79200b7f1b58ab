/* SPDX-License-Identifier: MIT */
/* Output directories written whole, never over what is not ours (irdm/posix/outdir.h). */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/outdir.h"
#include "irdm/version.h"

#define MARKER_MAGIC "irdm-output 1\n"
#define MARKER_MAX (1u << 20) /* 5000 frames' names fit many times */
#define SCRATCH (IRDM_OUTDIR_PATH_MAX + 512)

/* A marker read: its text (NUL-terminated), and the fields the checks use. */
struct marker {
	char *text;
	char tool[64];
	long pid;
	bool complete;
};

/* od->why (a long path is cut short: the message stays one line) */
__attribute__((format(printf, 2, 3))) static void say(struct irdm_outdir *od, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(od->why, sizeof(od->why), fmt, ap);
	va_end(ap);
}

static int sys_fail(struct irdm_outdir *od, const char *path, const char *what, int e)
{
	say(od, "%s: %s: %s", path, what, strerror(e));
	return IRDM_EIO;
}

static const char *field(const char *text, const char *key)
{
	const char *p = strstr(text, key);

	return p ? p + strlen(key) : NULL;
}

static void parse_marker(struct marker *m)
{
	const char *p = field(m->text, "\ntool ");
	size_t n = p ? strcspn(p, "\n") : 0;

	if (n < sizeof(m->tool))
		memcpy(m->tool, p ? p : "", n);
	p = field(m->text, "\npid ");
	m->pid = p ? strtol(p, NULL, 10) : 0;
	m->complete = field(m->text, "\nstate complete\n") != NULL;
}

/* Read dir's marker.  0; ENOENT: none; EINVAL: not one of ours; else errno. */
static int marker_read(const char *dir, struct marker *m)
{
	char path[SCRATCH];
	struct stat st;
	ssize_t got = 0;
	int fd, e = 0;

	memset(m, 0, sizeof(*m));
	snprintf(path, sizeof(path), "%s/%s", dir, IRDM_OUTDIR_MARKER);
	fd = open(path, O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
	if (fd < 0)
		return errno == ELOOP ? EINVAL : errno;
	if (fstat(fd, &st) || !S_ISREG(st.st_mode) || st.st_size > MARKER_MAX) {
		e = EINVAL;
		goto out_close;
	}
	m->text = calloc(1, (size_t)st.st_size + 1);
	if (!m->text) {
		e = ENOMEM;
		goto out_close;
	}
	while (got < st.st_size) {
		ssize_t r = read(fd, m->text + got, (size_t)(st.st_size - got));
		if (r <= 0)
			break;
		got += r;
	}
	if (got != st.st_size || strncmp(m->text, MARKER_MAGIC, strlen(MARKER_MAGIC))) {
		free(m->text);
		m->text = NULL;
		e = EINVAL;
		goto out_close;
	}
	parse_marker(m);
out_close:
	close(fd);
	return e;
}

static bool marker_lists(const struct marker *m, const char *name)
{
	char needle[NAME_MAX + 16];

	if (!strcmp(name, IRDM_OUTDIR_MARKER))
		return true;
	snprintf(needle, sizeof(needle), "\nfile %s\n", name);
	return m->text && strstr(m->text, needle);
}

static bool is_dot(const char *name)
{
	return !strcmp(name, ".") || !strcmp(name, "..");
}

/*
 * Remove the non-directory entries of dir that keep() does not keep, then
 * dir itself.  Only open(), getdents64, unlinkat() and rmdir(): safe in a
 * signal handler, so a handler may abort an output (irdm_outdir_abort()).
 * Return 0 when dir is gone.
 */
static int remove_files(const char *dir, const struct marker *only)
{
	char buf[4096];
	long n;
	int fd = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);

	if (fd < 0)
		return -1;
	while ((n = syscall(SYS_getdents64, fd, buf, sizeof(buf))) > 0) {
		for (long off = 0; off < n;) {
			struct dirent64 *d = (struct dirent64 *)(buf + off);

			off += d->d_reclen;
			if (is_dot(d->d_name) || d->d_type == DT_DIR)
				continue;
			if (only && !marker_lists(only, d->d_name))
				continue;
			unlinkat(fd, d->d_name, 0);
		}
	}
	close(fd);
	return rmdir(dir);
}

/* Every entry of an existing directory must be ours, or force must allow it. */
static int check_entries(struct irdm_outdir *od, DIR *h, const struct marker *m, bool ours)
{
	struct dirent *d;

	while ((d = readdir(h))) {
		struct stat st;
		bool plain;

		if (is_dot(d->d_name))
			continue;
		plain = !fstatat(dirfd(h), d->d_name, &st, AT_SYMLINK_NOFOLLOW) &&
			!S_ISDIR(st.st_mode);
		if (ours && plain && marker_lists(m, d->d_name))
			continue;
		if (!plain) {
			say(od, "%s/%s: a directory inside the output (%s writes files only); "
				"%s not replaced",
			    od->dir, d->d_name, od->tool, od->dir);
			return IRDM_EEXIST;
		}
		if (!od->force) {
			say(od, "%s/%s: not written by %s; %s not replaced (--force replaces it)",
			    od->dir, d->d_name, od->tool, od->dir);
			return IRDM_EEXIST;
		}
		/* forced over a file we did not write: it goes with the rest */
		od->replace_foreign = true;
	}
	return IRDM_OK;
}

/* May od->dir be replaced?  *exists says whether there is one to replace. */
static int check_target(struct irdm_outdir *od, bool *exists)
{
	struct marker m;
	struct stat st;
	bool ours;
	DIR *h;
	int rc;

	*exists = false;
	if (lstat(od->dir, &st))
		return errno == ENOENT ? IRDM_OK : sys_fail(od, od->dir, "cannot stat", errno);
	*exists = true;
	if (!S_ISDIR(st.st_mode)) {
		say(od, "%s: exists and is not a directory%s; not replaced", od->dir,
		    S_ISLNK(st.st_mode) ? " (a symbolic link)" : "");
		return IRDM_EEXIST;
	}
	ours = !marker_read(od->dir, &m) && m.complete && !strcmp(m.tool, od->tool);
	h = opendir(od->dir);
	if (!h) {
		rc = sys_fail(od, od->dir, "cannot read", errno);
		goto out_free;
	}
	od->replace_foreign = false;
	rc = check_entries(od, h, &m, ours);
	closedir(h);
out_free:
	free(m.text);
	return rc;
}

/* Split od->dir into its parent and base name. */
static void parent_and_base(const struct irdm_outdir *od, char *parent, size_t len,
			    const char **base)
{
	const char *slash = strrchr(od->dir, '/');

	if (!slash) {
		snprintf(parent, len, ".");
		*base = od->dir;
	} else {
		snprintf(parent, len, "%.*s", slash == od->dir ? 1 : (int)(slash - od->dir),
			 od->dir);
		*base = slash + 1;
	}
}

/* A beside-directory whose writer no longer runs: a killed run's debris. */
static bool is_debris(const char *path)
{
	struct marker m;
	bool dead;

	if (marker_read(path, &m))
		return false;
	dead = m.pid > 0 && m.pid != (long)getpid() && kill((pid_t)m.pid, 0) && errno == ESRCH;
	free(m.text);
	return dead;
}

static void remove_debris(struct irdm_outdir *od)
{
	char parent[IRDM_OUTDIR_PATH_MAX], prefix[IRDM_OUTDIR_PATH_MAX + 16], path[SCRATCH];
	const char *base;
	struct dirent *d;
	size_t plen;
	DIR *h;

	parent_and_base(od, parent, sizeof(parent), &base);
	plen = (size_t)snprintf(prefix, sizeof(prefix), "%s%s", base, IRDM_OUTDIR_TMP);
	h = opendir(parent);
	while (h && (d = readdir(h))) {
		if (strncmp(d->d_name, prefix, plen) || strlen(d->d_name) != plen + 6)
			continue;
		snprintf(path, sizeof(path), "%s/%s", parent, d->d_name);
		if (is_debris(path) && !remove_files(path, NULL))
			od->debris_removed++;
	}
	if (h)
		closedir(h);
}

/* The marker: tool, version, pid; when complete, the files written. */
static int marker_write(struct irdm_outdir *od, bool complete)
{
	char path[SCRATCH], final[SCRATCH];
	struct dirent *d;
	DIR *h = NULL;
	FILE *f;
	int e = 0;

	snprintf(path, sizeof(path), "%s/%s.new", od->tmp, IRDM_OUTDIR_MARKER);
	snprintf(final, sizeof(final), "%s/%s", od->tmp, IRDM_OUTDIR_MARKER);
	f = fopen(path, "w");
	if (!f)
		return sys_fail(od, path, "cannot write", errno);
	fprintf(f, "%stool %s\nversion %s\npid %ld\nstate %s\n", MARKER_MAGIC, od->tool,
		IRDM_VERSION, (long)getpid(), complete ? "complete" : "writing");
	if (complete)
		h = opendir(od->tmp);
	while (h && (d = readdir(h)))
		if (!is_dot(d->d_name) && strncmp(d->d_name, IRDM_OUTDIR_MARKER,
						  strlen(IRDM_OUTDIR_MARKER)))
			fprintf(f, "file %s\n", d->d_name);
	if (h)
		closedir(h);
	if (ferror(f))
		e = errno ? errno : EIO;
	if (fclose(f) && !e)
		e = errno;
	if (!e && rename(path, final))
		e = errno;
	return e ? sys_fail(od, path, "cannot write", e) : IRDM_OK;
}

int irdm_outdir_begin(struct irdm_outdir *od, const char *dir, const char *tool, bool force)
{
	size_t n = strlen(dir);
	bool exists;
	mode_t mask;
	int rc;

	memset(od, 0, sizeof(*od));
	od->force = force;
	snprintf(od->tool, sizeof(od->tool), "%s", tool);
	while (n > 1 && dir[n - 1] == '/')
		n--;
	if (n == 0 || n >= sizeof(od->dir) - 32) {
		snprintf(od->why, sizeof(od->why), "%.200s: %s", dir,
			 n ? "path too long" : "empty path");
		return IRDM_EINVAL;
	}
	memcpy(od->dir, dir, n);
	rc = check_target(od, &exists);
	if (rc)
		return rc;
	remove_debris(od);
	snprintf(od->tmp, sizeof(od->tmp), "%s%sXXXXXX", od->dir, IRDM_OUTDIR_TMP);
	if (!mkdtemp(od->tmp)) {
		rc = sys_fail(od, od->tmp, "cannot create", errno);
		od->tmp[0] = 0;
		return rc;
	}
	/* mkdtemp's 0700 would hide the output from others: the umask decides */
	mask = umask(0);
	umask(mask);
	chmod(od->tmp, 0777 & ~mask);
	rc = marker_write(od, false);
	if (rc)
		irdm_outdir_abort(od);
	return rc;
}

/* Without an exchange: the old set aside into a fresh beside name, ours in. */
static int swap_by_renames(struct irdm_outdir *od, char *aside, size_t len)
{
	snprintf(aside, len, "%s%sXXXXXX", od->dir, IRDM_OUTDIR_TMP);
	if (!mkdtemp(aside))
		return sys_fail(od, aside, "cannot create", errno);
	if (rename(od->dir, aside)) {
		rmdir(aside);
		return sys_fail(od, od->dir, "cannot move aside", errno);
	}
	if (rename(od->tmp, od->dir)) {
		int e = errno;

		rename(aside, od->dir);
		return sys_fail(od, od->dir, "cannot replace", e);
	}
	return IRDM_OK;
}

/* The replaced set: the files its marker lists, or all (forced), then it. */
static void remove_old(const struct irdm_outdir *od, const char *path)
{
	struct marker m;

	if (od->replace_foreign) {
		remove_files(path, NULL);
		return;
	}
	if (!marker_read(path, &m))
		remove_files(path, &m);
	else
		rmdir(path); /* an empty directory */
	free(m.text);
}

int irdm_outdir_commit(struct irdm_outdir *od)
{
	char aside[IRDM_OUTDIR_PATH_MAX + 32];
	bool exists;
	int rc;

	rc = marker_write(od, true);
	if (!rc)
		rc = check_target(od, &exists);
	if (rc)
		goto out_abort;
	if (!exists) {
		/* rename() replaces at most an empty directory made meanwhile */
		if (rename(od->tmp, od->dir)) {
			rc = sys_fail(od, od->dir, "cannot create", errno);
			goto out_abort;
		}
		od->tmp[0] = 0;
		return IRDM_OK;
	}
	if (!renameat2(AT_FDCWD, od->tmp, AT_FDCWD, od->dir, RENAME_EXCHANGE)) {
		remove_old(od, od->tmp);
		od->tmp[0] = 0;
		return IRDM_OK;
	}
	if (errno != EINVAL && errno != ENOSYS) {
		rc = sys_fail(od, od->dir, "cannot replace", errno);
		goto out_abort;
	}
	rc = swap_by_renames(od, aside, sizeof(aside));
	if (rc)
		goto out_abort;
	remove_old(od, aside);
	od->tmp[0] = 0;
	return IRDM_OK;
out_abort:
	irdm_outdir_abort(od);
	return rc;
}

int irdm_outdir_remove_files(const char *dir)
{
	return remove_files(dir, NULL);
}

void irdm_outdir_abort(struct irdm_outdir *od)
{
	if (od->tmp[0])
		remove_files(od->tmp, NULL);
	od->tmp[0] = 0;
}
