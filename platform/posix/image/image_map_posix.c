/* SPDX-License-Identifier: MIT */
/*
 * Getting an image's bytes on a POSIX system: open, copy the file into
 * private anonymous memory made read-only, optionally lock it, fault every
 * page in, then hand the bytes to irdm_image_parse().  Every system call of the loader is here and nowhere
 * else: a port to a bare-metal flash replaces this one file with one whose
 * irdm_image_map() points at the flash and whose irdm_image_unmap() does
 * nothing.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stdarg.h>

#include "irdm/error.h"
#include "irdm/image_format.h"
#include "irdm/posix/image_map.h"

/* A one-line reason into msg (if any); returns code. */
static int map_report(char *msg, size_t len, int code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

static int map_report(char *msg, size_t len, int code, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	if (msg && len)
		vsnprintf(msg, len, fmt, ap);
	va_end(ap);
	return code;
}

static void format_size(char *buf, size_t len, size_t bytes)
{
	const size_t mib = (size_t)1 << 20;

	if (bytes >= mib)
		snprintf(buf, len, "%zu MiB", (bytes + mib - 1) / mib);
	else
		snprintf(buf, len, "%zu KiB", (bytes + 1023) / 1024);
}

/* Read one byte of every page: the loop must never take a page fault.
 * MAP_POPULATE and mlock usually did it already; this makes it certain. */
static void touch_pages(const uint8_t *base, size_t size)
{
	long page = sysconf(_SC_PAGESIZE);
	volatile uint8_t sink = 0;

	if (page <= 0)
		page = 4096;
	for (size_t o = 0; o < size; o += (size_t)page)
		sink ^= base[o];
	sink ^= base[size - 1];
	(void)sink;
}

static int lock_pages(struct irdm_image *raw, char *msg, size_t msglen)
{
	char sz[32];
	int e;

	if (!mlock(raw->base, raw->size)) {
		raw->locked = true;
		return IRDM_OK;
	}
	e = errno;
	format_size(sz, sizeof(sz), raw->size);
	return map_report(msg, msglen, IRDM_EIO, "cannot lock %s: %s%s", sz,
			  strerror(e), e == EPERM || e == ENOMEM ? " (raise RLIMIT_MEMLOCK or run with CAP_IPC_LOCK)" : "");
}

/*
 * Read the whole file (st_size bytes) into base; the file must neither
 * shrink nor grow while it is read.
 */
static int read_all(int fd, uint8_t *base, size_t size, char *msg, size_t msglen)
{
	size_t done = 0;
	uint8_t extra;
	ssize_t n;

	while (done < size) {
		n = pread(fd, base + done, size - done, (off_t)done);
		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0)
			return map_report(msg, msglen, IRDM_EIO, "cannot read: %s", strerror(errno));
		if (n == 0)
			return map_report(msg, msglen, IRDM_ETRUNC,
					  "image is truncated: the file shrank to %zu bytes while "
					  "it was read (%zu expected)",
					  done, size);
		done += (size_t)n;
	}
	if (pread(fd, &extra, 1, (off_t)size) > 0)
		return map_report(msg, msglen, IRDM_EIO,
				  "the file grew past %zu bytes while it was read", size);
	return IRDM_OK;
}

/*
 * A private copy of the whole file in anonymous memory, read-only once
 * filled; the caller closes fd.  Not a mapping of the file: a file mapped
 * in place (even MAP_PRIVATE) is still the file's page cache, and a
 * truncation under a running loop gives SIGBUS, a copy over it changes the
 * bytes the loop reads.  The copy cannot change after it was checked.
 */
static int map_fd(int fd, unsigned flags, struct irdm_image *raw,
		  char *msg, size_t msglen)
{
	int mflags = MAP_PRIVATE | MAP_ANONYMOUS;
	struct stat st;
	void *base;
	int ret;

	if (fstat(fd, &st))
		return map_report(msg, msglen, IRDM_EIO, "cannot stat: %s",
				  strerror(errno));
	if (!S_ISREG(st.st_mode))
		return map_report(msg, msglen, IRDM_EIO, "not a regular file");
	if ((uintmax_t)st.st_size < sizeof(struct irdm_image_header))
		return map_report(msg, msglen, IRDM_ETRUNC,
				  "image is truncated: file has %jd bytes, the header alone needs %zu",
				  (intmax_t)st.st_size, sizeof(struct irdm_image_header));
	if ((uintmax_t)st.st_size > SIZE_MAX)
		return map_report(msg, msglen, IRDM_EIO,
				  "too large to map (%jd bytes)", (intmax_t)st.st_size);
#ifdef MAP_POPULATE
	mflags |= MAP_POPULATE;
#endif
	base = mmap(NULL, (size_t)st.st_size, PROT_READ | PROT_WRITE, mflags, -1, 0);
	if (base == MAP_FAILED)
		return map_report(msg, msglen, IRDM_EIO, "cannot map: %s",
				  strerror(errno));
	raw->base = base;
	raw->size = (size_t)st.st_size;
	ret = read_all(fd, base, raw->size, msg, msglen);
	if (ret)
		goto unmap;
	if (mprotect(base, raw->size, PROT_READ)) {
		ret = map_report(msg, msglen, IRDM_EIO, "cannot protect the copy: %s",
				 strerror(errno));
		goto unmap;
	}
	if (flags & IRDM_IMAGE_MAP_LOCK) {
		ret = lock_pages(raw, msg, msglen);
		if (ret)
			goto unmap;
	}
	touch_pages(base, raw->size);
	return IRDM_OK;
unmap:
	munmap(base, raw->size);
	memset(raw, 0, sizeof(*raw));
	return ret;
}

int irdm_image_map(const char *path, unsigned flags, struct irdm_image *img,
		   char *err, size_t errlen)
{
	struct irdm_image raw = { 0 };
	char msg[256] = "";
	int fd, ret;

	memset(img, 0, sizeof(*img));
	if (flags & ~(unsigned)IRDM_IMAGE_MAP_LOCK) {
		ret = map_report(msg, sizeof(msg), IRDM_EINVAL,
				 "unknown map flags 0x%x", flags);
		goto out_msg;
	}
	/* non-blocking: a FIFO at path must not hang the open (map_fd refuses it) */
	fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0) {
		ret = map_report(msg, sizeof(msg), IRDM_EIO, "cannot open: %s",
				 strerror(errno));
		goto out_msg;
	}
	ret = map_fd(fd, flags, &raw, msg, sizeof(msg));
	close(fd); /* the copy needs the file no more */
	if (ret)
		goto out_msg;
	ret = irdm_image_parse(raw.base, raw.size, img, msg, sizeof(msg));
	if (ret)
		goto unmap;
	img->mapped = true;
	img->locked = raw.locked;
	return IRDM_OK;
unmap:
	munmap((void *)raw.base, raw.size); /* also unlocks */
out_msg:
	if (err && errlen)
		snprintf(err, errlen, "%s: %s", path, msg);
	memset(img, 0, sizeof(*img));
	return ret;
}

void irdm_image_unmap(struct irdm_image *img)
{
	if (img->mapped && img->base)
		munmap((void *)img->base, img->size);
	memset(img, 0, sizeof(*img));
}
