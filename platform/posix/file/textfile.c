/* SPDX-License-Identifier: MIT */
/* Input files that cannot hang or mislead a reader (irdm/posix/textfile.h). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/textfile.h"

static const char *kind(mode_t m)
{
	if (S_ISDIR(m))
		return "a directory";
	if (S_ISFIFO(m))
		return "a FIFO";
	if (S_ISCHR(m))
		return "a character device";
	if (S_ISBLK(m))
		return "a block device";
	if (S_ISSOCK(m))
		return "a socket";
	return "not a file";
}

int irdm_file_open_regular(const char *path, size_t max_bytes, int *fd, char *err,
			   size_t errlen)
{
	struct stat st;
	int ret = IRDM_EIO;
	int flags;

	*fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (*fd < 0) {
		snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
		return IRDM_EIO;
	}
	if (fstat(*fd, &st)) {
		snprintf(err, errlen, "%s: cannot stat: %s", path, strerror(errno));
		goto out_close;
	}
	if (!S_ISREG(st.st_mode)) {
		snprintf(err, errlen, "%s: not a regular file (%s)", path, kind(st.st_mode));
		goto out_close;
	}
	if ((unsigned long long)st.st_size > max_bytes) {
		snprintf(err, errlen, "%s: %lld bytes, more than the %zu this input may have",
			 path, (long long)st.st_size, max_bytes);
		ret = IRDM_ERANGE;
		goto out_close;
	}
	/* a regular file never blocks; blocking reads keep stdio simple */
	flags = fcntl(*fd, F_GETFL);
	if (flags >= 0)
		fcntl(*fd, F_SETFL, flags & ~O_NONBLOCK);
	return IRDM_OK;
out_close:
	close(*fd);
	*fd = -1;
	return ret;
}

int irdm_file_fopen(const char *path, size_t max_bytes, FILE **f, char *err, size_t errlen)
{
	int fd, ret;

	*f = NULL;
	ret = irdm_file_open_regular(path, max_bytes, &fd, err, errlen);
	if (ret)
		return ret;
	*f = fdopen(fd, "r");
	if (!*f) {
		snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
		close(fd);
		return IRDM_EIO;
	}
	return IRDM_OK;
}

int irdm_text_open(struct irdm_text_file *t, const char *path, size_t max_bytes, char *err,
		   size_t errlen)
{
	memset(t, 0, sizeof(*t));
	t->name = path;
	t->max_bytes = max_bytes;
	return irdm_file_fopen(path, max_bytes, &t->f, err, errlen);
}

int irdm_text_line(struct irdm_text_file *t, char *buf, size_t len, char *err, size_t errlen)
{
	size_t n = 0;
	int c;

	while ((c = getc(t->f)) != EOF) {
		if (++t->bytes > t->max_bytes) {
			snprintf(err, errlen, "%s:%u: more than %zu bytes", t->name, t->line_no + 1,
				 t->max_bytes);
			return IRDM_ERANGE;
		}
		if (c == '\n')
			break;
		if (c == 0) {
			snprintf(err, errlen, "%s:%u: a NUL byte at column %zu (not a text file?)",
				 t->name, t->line_no + 1, n + 1);
			return IRDM_EFORMAT;
		}
		if (n + 1 >= len) {
			snprintf(err, errlen, "%s:%u: line longer than %zu characters", t->name,
				 t->line_no + 1, len - 1);
			return IRDM_EFORMAT;
		}
		buf[n++] = (char)c;
	}
	if (c == EOF && ferror(t->f)) {
		snprintf(err, errlen, "%s:%u: read error", t->name, t->line_no + 1);
		return IRDM_EIO;
	}
	if (c == EOF && n == 0)
		return 0;
	buf[n] = 0;
	t->line_no++;
	return 1;
}

void irdm_text_close(struct irdm_text_file *t)
{
	if (t->f)
		fclose(t->f);
	t->f = NULL;
}
