/* SPDX-License-Identifier: MIT */
/*
 * The telemetry log file: its layout, a synchronous writer (the writer
 * thread in telemetry_writer.c drives it) and the reader.  Off the tick:
 * stdio and allocation live here, never in telemetry_ring.c or
 * telemetry_hist.c.
 *
 * A log is written under a fresh name beside PATH (irdm/posix/outfile.h) and
 * renamed to PATH only once it is complete (every write, the flush and the
 * sync checked, the trailer and the record count written), so a crash or
 * a full disk leaves no half log under the final name.  Its blocks carry
 * a CRC-32C each, and the trailer the record count again: a log damaged or
 * cut short later is refused naming the block (docs/log-format.md).
 */
#include <errno.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/posix/outfile.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "irdm/posix/textfile.h"

/* ---- the layout is the file format: pin it ---- */

_Static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
	       "logs are little-endian and written as the structs are in memory");
_Static_assert(sizeof(double) == 8, "records hold IEEE-754 binary64");

_Static_assert(offsetof(struct irdm_tick_dev, tip_pos_m) == 0, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, tip_vel_m_s) == 24, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, joint_angle_rad) == 48, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, joint_torque_nm) == 72, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, force_n) == 96, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, contact_tri) == 120, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, proxy) == 124, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, site_tri) == 128, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, site_bary) == 136, "dev layout");
_Static_assert(offsetof(struct irdm_tick_dev, target_m) == 160, "dev layout");
_Static_assert(sizeof(struct irdm_tick_dev) == 184, "dev layout");

_Static_assert(offsetof(struct irdm_tick_record, tick) == 0, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, wake_latency_ns) == 8, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, compute_ns) == 12, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, fault_flags) == 16, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, state) == 20, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, n_devices) == 21, "record layout");
_Static_assert(offsetof(struct irdm_tick_record, dev) == 24, "record layout");
_Static_assert(sizeof(struct irdm_tick_record) == IRDM_TICK_RECORD_SIZE, "record layout");
_Static_assert(IRDM_TICK_RECORD_SIZE <= 512, "a record stays within 512 bytes");

_Static_assert(offsetof(struct irdm_log_header, version) == 8, "header layout");
_Static_assert(offsetof(struct irdm_log_header, start_time_ns) == 24, "header layout");
_Static_assert(offsetof(struct irdm_log_header, record_count) == 32, "header layout");
_Static_assert(offsetof(struct irdm_log_header, dropped) == 40, "header layout");
_Static_assert(offsetof(struct irdm_log_header, n_devices) == 48, "header layout");
_Static_assert(offsetof(struct irdm_log_header, board) == 56, "header layout");
_Static_assert(offsetof(struct irdm_log_header, image) == 120, "header layout");
_Static_assert(offsetof(struct irdm_log_header, block_records) == 248, "header layout");
_Static_assert(offsetof(struct irdm_log_header, header_crc32c) == 252, "header layout");
_Static_assert(sizeof(struct irdm_log_header) == IRDM_LOG_HEADER_SIZE, "header layout");
_Static_assert(sizeof(struct irdm_log_block_end) == 16, "block end layout");
_Static_assert(offsetof(struct irdm_log_block_end, crc32c) == 12, "block end layout");
_Static_assert(sizeof(struct irdm_log_trailer) == 32, "trailer layout");
_Static_assert(offsetof(struct irdm_log_trailer, crc32c) == 28, "trailer layout");

#define BLOCK_BYTES ((uint64_t)IRDM_LOG_BLOCK_RECORDS * IRDM_TICK_RECORD_SIZE + \
		     sizeof(struct irdm_log_block_end))
#define LOG_MAX_BYTES (1ull << 44) /* 16 TiB: months at 1 kHz */

static uint64_t n_blocks(uint64_t records)
{
	return (records + IRDM_LOG_BLOCK_RECORDS - 1) / IRDM_LOG_BLOCK_RECORDS;
}

uint64_t irdm_log_size(uint64_t n)
{
	return IRDM_LOG_HEADER_SIZE + n * IRDM_TICK_RECORD_SIZE +
	       n_blocks(n) * sizeof(struct irdm_log_block_end) + sizeof(struct irdm_log_trailer);
}

static uint32_t header_crc(const struct irdm_log_header *h)
{
	return irdm_crc32c(h, offsetof(struct irdm_log_header, header_crc32c));
}

static uint32_t trailer_crc(const struct irdm_log_trailer *t)
{
	return irdm_crc32c(t, offsetof(struct irdm_log_trailer, crc32c));
}

/* ---- errors ---- */

static int say(char *err, size_t errlen, int code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

static int say(char *err, size_t errlen, int code, const char *fmt, ...)
{
	va_list ap;

	if (err && errlen) {
		va_start(ap, fmt);
		vsnprintf(err, errlen, fmt, ap);
		va_end(ap);
	}
	return code;
}

/* ---- writing ---- */

struct irdm_log_file {
	struct irdm_outfile out;
	uint64_t count;
	uint32_t in_block, block, crc; /* the open block: records, number, CRC so far */
	int error;                     /* the first write error (errno), sticky */
	char why[256];
	struct irdm_log_header hdr;
};

static void copy_name(char *dst, size_t len, const char *src)
{
	memset(dst, 0, len);
	if (src)
		strncpy(dst, src, len - 1);
}

static void header_fill(struct irdm_log_header *h, const struct irdm_log_info *info)
{
	memset(h, 0, sizeof(*h));
	memcpy(h->magic, IRDM_LOG_MAGIC, sizeof(IRDM_LOG_MAGIC));
	h->version = IRDM_LOG_VERSION;
	h->header_size = IRDM_LOG_HEADER_SIZE;
	h->record_size = IRDM_TICK_RECORD_SIZE;
	h->period_us = info->period_us;
	h->start_time_ns = info->start_time_ns;
	h->record_count = IRDM_LOG_COUNT_OPEN;
	h->n_devices = info->n_devices;
	h->block_records = IRDM_LOG_BLOCK_RECORDS;
	copy_name(h->board, sizeof(h->board), info->board);
	copy_name(h->image, sizeof(h->image), info->image);
	h->header_crc32c = header_crc(h);
}

/* fwrite, remembering the first failure: the log is then lost, and says so. */
static void put(struct irdm_log_file *lf, const void *p, size_t size, const char *what)
{
	if (lf->error)
		return;
	if (fwrite(p, size, 1, lf->out.f) != 1) {
		lf->error = errno ? errno : EIO;
		snprintf(lf->why, sizeof(lf->why), "%s after %llu records: %s", what,
			 (unsigned long long)lf->count, strerror(lf->error));
	}
}

static void end_block(struct irdm_log_file *lf)
{
	struct irdm_log_block_end e = { .index = lf->block, .n_records = lf->in_block };

	memcpy(e.magic, IRDM_LOG_BLOCK_MAGIC, sizeof(IRDM_LOG_BLOCK_MAGIC));
	e.crc32c = irdm_crc32c_update(lf->crc, &e, offsetof(struct irdm_log_block_end, crc32c));
	put(lf, &e, sizeof(e), "write failed");
	lf->block++;
	lf->in_block = 0;
	lf->crc = 0;
}

static int lost(const struct irdm_log_file *lf, char *err, size_t errlen)
{
	return say(err, errlen, IRDM_EIO, "%s: log not written: %s", lf->out.path, lf->why);
}

int irdm_log_file_open(struct irdm_log_file **out, const char *path,
		       const struct irdm_log_info *info, char *err, size_t errlen)
{
	struct irdm_log_file *lf;
	int ret;

	if (!out)
		return say(err, errlen, IRDM_EINVAL, "no log to open into");
	*out = NULL;
	if (!path || !info)
		return say(err, errlen, IRDM_EINVAL, "log: no path or no run information");
	if (!info->period_us || info->n_devices > IRDM_TELEM_MAX_DEVICES)
		return say(err, errlen, IRDM_EINVAL, "%s: period_us %u, n_devices %u: need a period > 0 and at most %d devices",
			   path, info->period_us, info->n_devices, IRDM_TELEM_MAX_DEVICES);
	lf = calloc(1, sizeof(*lf));
	if (!lf)
		return say(err, errlen, IRDM_ENOMEM, "%s: out of memory", path);
	header_fill(&lf->hdr, info);
	ret = irdm_outfile_open(&lf->out, path, err, errlen);
	if (ret)
		goto out_free;
	put(lf, &lf->hdr, sizeof(lf->hdr), "cannot write the header");
	if (lf->error || fflush(lf->out.f)) {
		if (!lf->error)
			snprintf(lf->why, sizeof(lf->why), "cannot write the header: %s",
				 strerror(errno));
		ret = lost(lf, err, errlen);
		irdm_outfile_abort(&lf->out);
		goto out_free;
	}
	*out = lf;
	return IRDM_OK;
out_free:
	free(lf);
	return ret;
}

int irdm_log_file_append(struct irdm_log_file *lf, const struct irdm_tick_record *rec, size_t n,
			 char *err, size_t errlen)
{
	for (size_t i = 0; i < n && !lf->error; i++) {
		put(lf, &rec[i], sizeof(rec[i]), "write failed");
		lf->crc = irdm_crc32c_update(lf->crc, &rec[i], sizeof(rec[i]));
		lf->count++;
		if (++lf->in_block == IRDM_LOG_BLOCK_RECORDS)
			end_block(lf);
	}
	return lf->error ? lost(lf, err, errlen) : IRDM_OK;
}

uint64_t irdm_log_file_count(const struct irdm_log_file *lf)
{
	return lf->count;
}

/* The last block, the trailer, and the header's count, dropped and CRC. */
static void file_finish(struct irdm_log_file *lf, uint64_t dropped)
{
	struct irdm_log_trailer t = { .record_count = lf->count, .dropped = dropped };

	if (lf->in_block)
		end_block(lf);
	memcpy(t.magic, IRDM_LOG_TRAILER_MAGIC, sizeof(IRDM_LOG_TRAILER_MAGIC));
	t.n_blocks = lf->block;
	t.crc32c = trailer_crc(&t);
	put(lf, &t, sizeof(t), "cannot write the trailer");
	lf->hdr.record_count = lf->count;
	lf->hdr.dropped = dropped;
	lf->hdr.header_crc32c = header_crc(&lf->hdr);
	if (!lf->error && fseek(lf->out.f, 0, SEEK_SET)) {
		lf->error = errno;
		snprintf(lf->why, sizeof(lf->why), "cannot seek to the header: %s",
			 strerror(errno));
	}
	put(lf, &lf->hdr, sizeof(lf->hdr), "cannot finish the header");
}

int irdm_log_file_close(struct irdm_log_file *lf, uint64_t dropped, char *err, size_t errlen)
{
	char why[512];
	int ret = IRDM_OK;

	file_finish(lf, dropped);
	if (lf->error) {
		ret = lost(lf, err, errlen);
		irdm_outfile_abort(&lf->out);
	} else if (irdm_outfile_commit(&lf->out, why, sizeof(why))) {
		/* the flush, the sync or the close found what the writes did not */
		ret = say(err, errlen, IRDM_EIO, "%s", why);
	}
	free(lf);
	return ret;
}

void irdm_log_file_abort(struct irdm_log_file *lf)
{
	if (!lf)
		return;
	irdm_outfile_abort(&lf->out);
	free(lf);
}

/* ---- reading ---- */

struct irdm_log_reader {
	FILE *f;
	uint64_t next;                  /* the next record to return */
	uint64_t size;                  /* of the file, at open */
	struct irdm_tick_record *block; /* the current block's records */
	uint32_t in_block, block_pos, block_no;
	struct irdm_log_header hdr;
	char path[];
};

static bool terminated(const char *s, size_t len)
{
	return memchr(s, 0, len) != NULL;
}

/* The header's own fields, before the file's length is looked at. */
static int check_header(const struct irdm_log_header *h, const char *path, char *err,
			size_t errlen)
{
	if (memcmp(h->magic, IRDM_LOG_MAGIC, sizeof(IRDM_LOG_MAGIC)))
		return say(err, errlen, IRDM_EMAGIC, "%s: not an IRDM log (bad magic)", path);
	if (h->version != IRDM_LOG_VERSION)
		return say(err, errlen, IRDM_EVERSION, "%s: log version %u, this build reads version %u",
			   path, h->version, IRDM_LOG_VERSION);
	if (h->header_crc32c != header_crc(h))
		return say(err, errlen, IRDM_ECRC, "%s: header: bad checksum (0x%08x, the bytes give 0x%08x)",
			   path, h->header_crc32c, header_crc(h));
	if (h->header_size != IRDM_LOG_HEADER_SIZE || h->record_size != IRDM_TICK_RECORD_SIZE ||
	    h->block_records != IRDM_LOG_BLOCK_RECORDS)
		return say(err, errlen, IRDM_EFORMAT, "%s: header size %u, record size %u, block of %u records: this build expects %u, %u and %u",
			   path, h->header_size, h->record_size, h->block_records,
			   IRDM_LOG_HEADER_SIZE, IRDM_TICK_RECORD_SIZE, IRDM_LOG_BLOCK_RECORDS);
	if (h->n_devices > IRDM_TELEM_MAX_DEVICES || !h->period_us)
		return say(err, errlen, IRDM_EFORMAT, "%s: n_devices %u, period_us %u: need at most %d devices and a period > 0",
			   path, h->n_devices, h->period_us, IRDM_TELEM_MAX_DEVICES);
	if (!terminated(h->board, sizeof(h->board)) || !terminated(h->image, sizeof(h->image)))
		return say(err, errlen, IRDM_EFORMAT, "%s: board or image name not terminated",
			   path);
	if (h->record_count == IRDM_LOG_COUNT_OPEN)
		return say(err, errlen, IRDM_ETRUNC, "%s: truncated: the log was never closed (its writer stopped early)",
			   path);
	return IRDM_OK;
}

static uint64_t block_first(uint64_t k)
{
	return k * IRDM_LOG_BLOCK_RECORDS;
}

/* Records of block k of a log of count records: its last one. */
static uint64_t block_last(uint64_t k, uint64_t count)
{
	uint64_t end = block_first(k + 1);

	return (end < count ? end : count) - 1;
}

/* The file's length is that of record_count records: where does it end? */
static int check_length(const struct irdm_log_header *h, uint64_t size, const char *path,
			char *err, size_t errlen)
{
	uint64_t want = irdm_log_size(h->record_count), nb = n_blocks(h->record_count), k;

	if (h->record_count > LOG_MAX_BYTES / IRDM_TICK_RECORD_SIZE)
		return say(err, errlen, IRDM_EFORMAT, "%s: the header says %llu records: more than a log may hold",
			   path, (unsigned long long)h->record_count);
	if (size > want)
		return say(err, errlen, IRDM_EFORMAT, "%s: the header says %llu records, the file holds more (%llu bytes after the trailer)",
			   path, (unsigned long long)h->record_count,
			   (unsigned long long)(size - want));
	if (size == want)
		return IRDM_OK;
	k = (size - IRDM_LOG_HEADER_SIZE) / BLOCK_BYTES;
	if (size >= want - sizeof(struct irdm_log_trailer))
		return say(err, errlen, IRDM_ETRUNC, "%s: truncated: ends in the trailer, after the %llu blocks (%llu of %llu bytes)",
			   path, (unsigned long long)nb, (unsigned long long)size,
			   (unsigned long long)want);
	return say(err, errlen, IRDM_ETRUNC, "%s: truncated: ends in block %llu of %llu (records %llu..%llu; %llu of %llu bytes)",
		   path, (unsigned long long)k, (unsigned long long)nb,
		   (unsigned long long)block_first(k),
		   (unsigned long long)block_last(k, h->record_count), (unsigned long long)size,
		   (unsigned long long)want);
}

/* The trailer repeats the header's count: a log whose end was replaced
 * by another's, or whose header was edited, disagrees with itself. */
static int check_trailer(struct irdm_log_reader *r, char *err, size_t errlen)
{
	const struct irdm_log_header *h = &r->hdr;
	struct irdm_log_trailer t;

	if (fseeko(r->f, (off_t)(r->size - sizeof(t)), SEEK_SET) || fread(&t, sizeof(t), 1, r->f) != 1)
		return say(err, errlen, IRDM_EIO, "%s: cannot read the trailer: %s", r->path,
			   strerror(errno));
	if (memcmp(t.magic, IRDM_LOG_TRAILER_MAGIC, sizeof(IRDM_LOG_TRAILER_MAGIC)))
		return say(err, errlen, IRDM_EFORMAT, "%s: trailer: bad magic", r->path);
	if (t.crc32c != trailer_crc(&t))
		return say(err, errlen, IRDM_ECRC, "%s: trailer: bad checksum", r->path);
	if (t.record_count != h->record_count || t.dropped != h->dropped ||
	    t.n_blocks != n_blocks(h->record_count))
		return say(err, errlen, IRDM_EFORMAT, "%s: trailer: %llu records, %llu dropped in %u blocks; the header: %llu, %llu in %llu",
			   r->path, (unsigned long long)t.record_count,
			   (unsigned long long)t.dropped, t.n_blocks,
			   (unsigned long long)h->record_count, (unsigned long long)h->dropped,
			   (unsigned long long)n_blocks(h->record_count));
	if (fseeko(r->f, IRDM_LOG_HEADER_SIZE, SEEK_SET))
		return say(err, errlen, IRDM_EIO, "%s: cannot seek: %s", r->path, strerror(errno));
	return IRDM_OK;
}

static int read_header(struct irdm_log_reader *r, char *err, size_t errlen)
{
	struct stat st;
	size_t got;
	int ret;

	if (fstat(fileno(r->f), &st))
		return say(err, errlen, IRDM_EIO, "%s: cannot stat: %s", r->path, strerror(errno));
	r->size = (uint64_t)st.st_size;
	got = fread(&r->hdr, 1, sizeof(r->hdr), r->f);
	if (got < sizeof(r->hdr) && ferror(r->f))
		return say(err, errlen, IRDM_EIO, "%s: cannot read: %s", r->path, strerror(errno));
	if (got < sizeof(IRDM_LOG_MAGIC) || memcmp(r->hdr.magic, IRDM_LOG_MAGIC, sizeof(IRDM_LOG_MAGIC)))
		return say(err, errlen, IRDM_EMAGIC, "%s: not an IRDM log (%s)", r->path,
			   got < sizeof(IRDM_LOG_MAGIC) ? "too short for a header" : "bad magic");
	if (got < sizeof(r->hdr))
		return say(err, errlen, IRDM_ETRUNC, "%s: truncated: %zu bytes, the header alone takes %u",
			   r->path, got, IRDM_LOG_HEADER_SIZE);
	ret = check_header(&r->hdr, r->path, err, errlen);
	if (!ret)
		ret = check_length(&r->hdr, r->size, r->path, err, errlen);
	if (!ret)
		ret = check_trailer(r, err, errlen);
	return ret;
}

int irdm_log_open(struct irdm_log_reader **out, const char *path, char *err, size_t errlen)
{
	struct irdm_log_reader *r;
	int ret;

	if (!out)
		return say(err, errlen, IRDM_EINVAL, "no reader to open into");
	*out = NULL;
	if (!path)
		return say(err, errlen, IRDM_EINVAL, "no log path");
	r = calloc(1, sizeof(*r) + strlen(path) + 1);
	if (r)
		r->block = malloc(IRDM_LOG_BLOCK_RECORDS * sizeof(*r->block));
	if (!r || !r->block) {
		ret = say(err, errlen, IRDM_ENOMEM, "%s: out of memory", path);
		goto out_free;
	}
	strcpy(r->path, path);
	ret = irdm_file_fopen(path, LOG_MAX_BYTES, &r->f, err, errlen);
	if (ret)
		goto out_free;
	ret = read_header(r, err, errlen);
	if (ret)
		goto out_close;
	*out = r;
	return IRDM_OK;
out_close:
	fclose(r->f);
out_free:
	if (r)
		free(r->block);
	free(r);
	return ret;
}

/* The next block whole, its end and checksum checked, before any record of it is used. */
static int read_block(struct irdm_log_reader *r, char *err, size_t errlen)
{
	uint64_t left = r->hdr.record_count - r->next;
	uint32_t n = left < IRDM_LOG_BLOCK_RECORDS ? (uint32_t)left : IRDM_LOG_BLOCK_RECORDS;
	struct irdm_log_block_end e;
	uint32_t crc;

	if (fread(r->block, sizeof(*r->block), n, r->f) != n || fread(&e, sizeof(e), 1, r->f) != 1)
		return say(err, errlen, IRDM_EIO, "%s: block %u (records %llu..%llu): %s", r->path,
			   r->block_no, (unsigned long long)r->next,
			   (unsigned long long)(r->next + n - 1),
			   ferror(r->f) ? strerror(errno) : "end of file (did the file shrink?)");
	crc = irdm_crc32c_update(irdm_crc32c(r->block, n * sizeof(*r->block)), &e,
				 offsetof(struct irdm_log_block_end, crc32c));
	if (memcmp(e.magic, IRDM_LOG_BLOCK_MAGIC, sizeof(IRDM_LOG_BLOCK_MAGIC)) ||
	    e.index != r->block_no || e.n_records != n)
		return say(err, errlen, IRDM_EFORMAT, "%s: block %u (records %llu..%llu): its end is not block %u's of %u records",
			   r->path, r->block_no, (unsigned long long)r->next,
			   (unsigned long long)(r->next + n - 1), r->block_no, n);
	if (crc != e.crc32c)
		return say(err, errlen, IRDM_ECRC, "%s: block %u (records %llu..%llu): bad checksum (0x%08x, the bytes give 0x%08x)",
			   r->path, r->block_no, (unsigned long long)r->next,
			   (unsigned long long)(r->next + n - 1), e.crc32c, crc);
	r->in_block = n;
	r->block_pos = 0;
	r->block_no++;
	return IRDM_OK;
}

const struct irdm_log_header *irdm_log_header(const struct irdm_log_reader *r)
{
	return &r->hdr;
}

int irdm_log_next(struct irdm_log_reader *r, struct irdm_tick_record *rec, char *err,
		  size_t errlen)
{
	int ret;

	if (r->next == r->hdr.record_count)
		return 0;
	if (r->block_pos == r->in_block) {
		ret = read_block(r, err, errlen);
		if (ret)
			return ret;
	}
	*rec = r->block[r->block_pos++];
	r->next++;
	if (rec->n_devices > IRDM_TELEM_MAX_DEVICES)
		return say(err, errlen, IRDM_EFORMAT, "%s: record %llu: n_devices %u (at most %d)",
			   r->path, (unsigned long long)(r->next - 1), rec->n_devices,
			   IRDM_TELEM_MAX_DEVICES);
	return 1;
}

void irdm_log_close(struct irdm_log_reader *r)
{
	if (!r)
		return;
	fclose(r->f);
	free(r->block);
	free(r);
}
