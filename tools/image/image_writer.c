/* SPDX-License-Identifier: MIT */
/*
 * Image writer.  Layout (docs/image-format.md):
 *
 *   header (64) | section table (count x 32) | zero pad to 64 |
 *   payload 0 | zero pad to 64 | payload 1 | ... | last payload (no pad)
 *
 * Payloads are written in the order they were added, straight from the
 * caller's buffers (response data can be gigabytes: no copy).  Writing goes
 * to "<path>.tmp.XXXXXX" in the target's directory, which is fsync'd and
 * renamed over the target, then the directory is fsync'd: a reader sees the
 * old image or the new one, never a mix, and a crash leaves at most a stray
 * temporary file.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/image.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/outfile.h"
#include "image/image_writer.h"
#include "util/interrupt.h"

#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && \
	__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "IRDM images are little-endian; this writer stores host order"
#endif

#define ALIGN IRDM_IMAGE_ALIGN
#define HEADER_SIZE sizeof(struct irdm_image_header)
#define TABLE_OFFSET ALIGN /* the header fills exactly one 64-byte line */
#define HEAD_MAX (TABLE_OFFSET + \
		  IRDM_IMAGE_MAX_SECTIONS * sizeof(struct irdm_image_section))

/* Where everything goes, and the header and table bytes. */
struct layout {
	uint64_t offset[IRDM_IMAGE_MAX_SECTIONS];
	uint64_t file_size;
	uint8_t head[HEAD_MAX]; /* header + table */
	size_t head_len;
};

/* Destination of the bytes: a file descriptor or a memory buffer. */
struct sink {
	int fd; /* -1: write into mem */
	uint8_t *mem;
	uint64_t pos;
};

static const uint8_t zeros[ALIGN];

static uint64_t align_up(uint64_t x)
{
	return (x + ALIGN - 1) / ALIGN * ALIGN;
}

void irdm_iw_init(struct irdm_image_writer *w)
{
	memset(w, 0, sizeof(*w));
}

int irdm_iw_add(struct irdm_image_writer *w, uint32_t kind, uint32_t elem,
		const void *data, uint64_t size)
{
	if (w->n >= IRDM_IMAGE_MAX_SECTIONS || !irdm_elem_size(elem) ||
	    (size && !data) || size > SIZE_MAX)
		return IRDM_EINVAL;
	for (unsigned i = 0; i < w->n; i++)
		if (w->sec[i].kind == kind)
			return IRDM_EINVAL;
	w->sec[w->n].kind = kind;
	w->sec[w->n].elem = elem;
	w->sec[w->n].data = data;
	w->sec[w->n].size = size;
	w->n++;
	return 0;
}

static void fill_table(const struct irdm_image_writer *w, struct layout *lo)
{
	for (unsigned i = 0; i < w->n; i++) {
		struct irdm_image_section s = {
			.kind = w->sec[i].kind,
			.elem = w->sec[i].elem,
			.offset = lo->offset[i],
			.size = w->sec[i].size,
			.crc32c = irdm_crc32c(w->sec[i].data, (size_t)w->sec[i].size),
		};

		memcpy(lo->head + TABLE_OFFSET + i * sizeof(s), &s, sizeof(s));
	}
}

static void fill_header(const struct irdm_image_writer *w, struct layout *lo)
{
	struct irdm_image_header h = {
		.version_major = IRDM_IMAGE_VERSION_MAJOR,
		.version_minor = IRDM_IMAGE_VERSION_MINOR,
		.header_size = HEADER_SIZE,
		.file_size = lo->file_size,
		.section_count = w->n,
		.section_table_offset = TABLE_OFFSET,
	};

	memcpy(h.magic, IRDM_IMAGE_MAGIC, sizeof(h.magic));
	h.table_crc32c = irdm_crc32c(lo->head + TABLE_OFFSET,
				     w->n * sizeof(struct irdm_image_section));
	memcpy(lo->head, &h, sizeof(h));
	h.header_crc32c = irdm_crc32c(lo->head,
				      offsetof(struct irdm_image_header,
					       header_crc32c));
	memcpy(lo->head, &h, sizeof(h));
}

/* Place the payloads and build the header and table.  -1 if empty. */
static int plan(const struct irdm_image_writer *w, struct layout *lo)
{
	uint64_t pos;

	memset(lo, 0, sizeof(*lo));
	if (w->n < 1 || w->n > IRDM_IMAGE_MAX_SECTIONS)
		return -1;
	lo->head_len = TABLE_OFFSET + w->n * sizeof(struct irdm_image_section);
	pos = align_up(lo->head_len);
	lo->file_size = lo->head_len;
	for (unsigned i = 0; i < w->n; i++) {
		lo->offset[i] = pos;
		pos += w->sec[i].size;
		lo->file_size = pos;
		pos = align_up(pos);
	}
	fill_table(w, lo);
	fill_header(w, lo);
	return 0;
}

/* Append len bytes; writes to a file retry short writes and EINTR. */
static int sink_put(struct sink *s, const void *data, uint64_t len)
{
	const uint8_t *p = data;

	if (!len) /* empty payloads may have no buffer at all */
		return 0;
	if (s->fd < 0) {
		memcpy(s->mem + s->pos, p, (size_t)len);
		s->pos += len;
		return 0;
	}
	while (len) {
		size_t chunk = len > (1u << 30) ? (1u << 30) : (size_t)len;
		ssize_t r = write(s->fd, p, chunk);

		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0)
			return -1;
		if (r == 0) {
			errno = EIO;
			return -1;
		}
		p += r;
		len -= (uint64_t)r;
		s->pos += (uint64_t)r;
	}
	return 0;
}

static int sink_pad_to(struct sink *s, uint64_t pos)
{
	return sink_put(s, zeros, pos - s->pos);
}

static int emit(const struct irdm_image_writer *w, const struct layout *lo,
		struct sink *s)
{
	if (sink_put(s, lo->head, lo->head_len))
		return -1;
	for (unsigned i = 0; i < w->n; i++)
		if (sink_pad_to(s, lo->offset[i]) ||
		    sink_put(s, w->sec[i].data, w->sec[i].size))
			return -1;
	return 0;
}

int irdm_iw_to_buffer(const struct irdm_image_writer *w, void **buf,
		      size_t *size)
{
	struct layout *lo;
	struct sink s = { .fd = -1 };
	int ret = IRDM_EINVAL;

	*buf = NULL;
	*size = 0;
	lo = malloc(sizeof(*lo));
	if (!lo)
		return IRDM_ENOMEM;
	if (plan(w, lo))
		goto free_layout;
	ret = IRDM_ENOMEM;
	if (lo->file_size > SIZE_MAX)
		goto free_layout;
	s.mem = malloc((size_t)lo->file_size);
	if (!s.mem)
		goto free_layout;
	emit(w, lo, &s); /* into memory: cannot fail */
	*buf = s.mem;
	*size = (size_t)lo->file_size;
	ret = IRDM_OK;
free_layout:
	free(lo);
	return ret;
}

/* fsync the directory holding path so the rename itself is durable. */
static int sync_dir(const char *path)
{
	const char *slash = strrchr(path, '/');
	char *dir;
	int fd, e, ret = -1;

	if (!slash)
		dir = strdup(".");
	else if (slash == path)
		dir = strdup("/");
	else
		dir = strndup(path, (size_t)(slash - path));
	if (!dir)
		return -1;
	fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd < 0)
		goto free_dir;
	ret = fsync(fd);
	/* Some file systems cannot sync a directory; nothing more to do. */
	if (ret && (errno == EINVAL || errno == ENOTSUP))
		ret = 0;
	e = errno;
	close(fd);
	errno = e;
free_dir:
	free(dir);
	return ret;
}

/* Write, sync and close the temporary file; fd is closed either way. */
static int write_tmp(const struct irdm_image_writer *w, const struct layout *lo,
		     int fd)
{
	struct sink s = { .fd = fd };
	int e;

	/* mkstemp makes 0600; an image is read by the firmware's user too. */
	if (fchmod(fd, 0644) || emit(w, lo, &s) || fsync(fd)) {
		e = errno;
		close(fd);
		errno = e;
		return -1;
	}
	return close(fd);
}

/* A temporary of a killed writer, removed (irdm_outfile_remove_debris()): said. */
static void said_removed(const char *victim, void *ctx)
{
	(void)ctx;
	fprintf(stderr, "irdm: note: removed %s, left by an interrupted run\n", victim);
}

int irdm_iw_write(const struct irdm_image_writer *w, const char *path,
		  char *err, size_t errlen)
{
	static const char suffix[] = IRDM_OUTDIR_TMP "XXXXXX";
	struct layout *lo;
	char *tmp = NULL;
	int fd, lock_fd = -1, slot = -1, ret;

	lo = malloc(sizeof(*lo));
	if (!lo || plan(w, lo)) {
		snprintf(err, errlen, "%s: %s", path,
			 lo ? "image has no sections" : strerror(ENOMEM));
		ret = lo ? IRDM_EINVAL : IRDM_ENOMEM;
		goto free_layout;
	}
	tmp = malloc(strlen(path) + sizeof(suffix));
	if (!tmp) {
		snprintf(err, errlen, "%s: %s", path, strerror(ENOMEM));
		ret = IRDM_ENOMEM;
		goto free_layout;
	}
	/* the same names and lock as irdm/posix/outfile.h's: a killed writer's debris goes */
	irdm_outfile_remove_debris(path, said_removed, NULL);
	/* from here on every failure is the file system's */
	ret = IRDM_EIO;
	strcpy(tmp, path);
	strcat(tmp, suffix);
	fd = mkstemp(tmp);
	if (fd < 0) {
		snprintf(err, errlen, "%s: cannot create temporary file: %s",
			 path, strerror(errno));
		goto free_layout;
	}
	/* the lock says "a writer is alive" until the rename (remove_debris) */
	lock_fd = dup(fd);
	if (lock_fd >= 0)
		flock(lock_fd, LOCK_EX);
	slot = irdm_interrupt_add(IRDM_INTERRUPT_FILE, tmp, 0);
	if (write_tmp(w, lo, fd)) {
		snprintf(err, errlen, "%s: cannot write %s: %s", path, tmp,
			 strerror(errno));
		goto unlink_tmp;
	}
	if (rename(tmp, path)) {
		snprintf(err, errlen, "%s: cannot replace with %s: %s", path,
			 tmp, strerror(errno));
		goto unlink_tmp;
	}
	irdm_interrupt_del(slot);
	slot = -1;
	if (sync_dir(path)) {
		/* Too late to keep the old image: it is replaced, not durable. */
		snprintf(err, errlen, "%s: written, but cannot sync its directory: %s",
			 path, strerror(errno));
		goto free_layout;
	}
	ret = IRDM_OK;
	goto free_layout;
unlink_tmp:
	unlink(tmp);
free_layout:
	irdm_interrupt_del(slot);
	if (lock_fd >= 0)
		close(lock_fd);
	free(tmp);
	free(lo);
	return ret;
}
