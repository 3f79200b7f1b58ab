/* SPDX-License-Identifier: MIT */
/*
 * The telemetry log file: its layout, a synchronous writer (the writer
 * thread in telemetry_writer.c drives it) and the reader.  Off the tick:
 * stdio and allocation live here, never in telemetry_ring.c or
 * telemetry_hist.c.
 *
 * A log is written to PATH.tmp and renamed to PATH only once it is
 * complete (records flushed and synced, record_count in the header), so a
 * crash leaves at worst PATH.tmp, never a half log under the final name.
 */
#include <errno.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/telemetry.h"

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
_Static_assert(sizeof(struct irdm_log_header) == IRDM_LOG_HEADER_SIZE, "header layout");

/* ---- names ---- */

const char *irdm_telem_state_name(unsigned state)
{
	static const char *const names[IRDM_TELEM_N_STATES] = {
		"init", "ready", "enabled", "fault", "off",
	};

	return state < IRDM_TELEM_N_STATES ? names[state] : "?";
}

const char *irdm_telem_proxy_name(unsigned proxy)
{
	static const char *const names[IRDM_TELEM_N_PROXY] = { "free", "touch", "slide", "release" };

	return proxy < IRDM_TELEM_N_PROXY ? names[proxy] : "?";
}

const char *irdm_telem_fault_name(unsigned bit)
{
	static const char *const names[IRDM_TELEM_N_FAULTS] = {
		"clamp", "workspace", "velocity", "watchdog", "overrun", "encoder_nan",
		"encoder_range", "signal", "hal_read", "hal_write", "hal_fault", "engine",
	};

	return bit < IRDM_TELEM_N_FAULTS ? names[bit] : "?";
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
	FILE *f;
	char *path;
	char *tmp;
	uint64_t count;
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
	copy_name(h->board, sizeof(h->board), info->board);
	copy_name(h->image, sizeof(h->image), info->image);
}

static void file_free(struct irdm_log_file *lf)
{
	free(lf->path);
	free(lf->tmp);
	free(lf);
}

static struct irdm_log_file *file_alloc(const char *path)
{
	struct irdm_log_file *lf = calloc(1, sizeof(*lf));
	size_t len = strlen(path);

	if (!lf)
		return NULL;
	lf->path = strdup(path);
	lf->tmp = malloc(len + sizeof(".tmp"));
	if (!lf->path || !lf->tmp) {
		file_free(lf);
		return NULL;
	}
	memcpy(lf->tmp, path, len);
	memcpy(lf->tmp + len, ".tmp", sizeof(".tmp"));
	return lf;
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
	lf = file_alloc(path);
	if (!lf)
		return say(err, errlen, IRDM_ENOMEM, "%s: out of memory", path);
	header_fill(&lf->hdr, info);
	lf->f = fopen(lf->tmp, "wb");
	if (!lf->f) {
		ret = say(err, errlen, IRDM_EIO, "%s: cannot create: %s", lf->tmp, strerror(errno));
		goto out_free;
	}
	if (fwrite(&lf->hdr, sizeof(lf->hdr), 1, lf->f) != 1) {
		ret = say(err, errlen, IRDM_EIO, "%s: cannot write the header: %s", lf->tmp,
			  strerror(errno));
		goto out_remove;
	}
	*out = lf;
	return IRDM_OK;
out_remove:
	fclose(lf->f);
	remove(lf->tmp);
out_free:
	file_free(lf);
	return ret;
}

int irdm_log_file_append(struct irdm_log_file *lf, const struct irdm_tick_record *rec, size_t n,
			 char *err, size_t errlen)
{
	if (n && fwrite(rec, sizeof(*rec), n, lf->f) != n)
		return say(err, errlen, IRDM_EIO, "%s: write failed after %llu records: %s", lf->tmp,
			   (unsigned long long)lf->count, strerror(errno));
	lf->count += n;
	return IRDM_OK;
}

uint64_t irdm_log_file_count(const struct irdm_log_file *lf)
{
	return lf->count;
}

/* record_count and dropped into the header, everything on disk. */
static int file_finish(struct irdm_log_file *lf, uint64_t dropped)
{
	lf->hdr.record_count = lf->count;
	lf->hdr.dropped = dropped;
	if (fseek(lf->f, (long)offsetof(struct irdm_log_header, record_count), SEEK_SET) ||
	    fwrite(&lf->hdr.record_count, 2 * sizeof(uint64_t), 1, lf->f) != 1 ||
	    fflush(lf->f) || fsync(fileno(lf->f)))
		return -1;
	return 0;
}

int irdm_log_file_close(struct irdm_log_file *lf, uint64_t dropped, char *err, size_t errlen)
{
	int ret = IRDM_OK;

	_Static_assert(offsetof(struct irdm_log_header, dropped) ==
		       offsetof(struct irdm_log_header, record_count) + sizeof(uint64_t),
		       "file_finish writes record_count and dropped in one go");
	if (file_finish(lf, dropped)) {
		ret = say(err, errlen, IRDM_EIO, "%s: cannot finish the log: %s", lf->tmp,
			  strerror(errno));
		goto out_remove;
	}
	if (fclose(lf->f)) {
		lf->f = NULL;
		ret = say(err, errlen, IRDM_EIO, "%s: close failed: %s", lf->tmp, strerror(errno));
		goto out_remove;
	}
	lf->f = NULL;
	if (rename(lf->tmp, lf->path)) {
		ret = say(err, errlen, IRDM_EIO, "%s: cannot rename into place: %s", lf->path,
			  strerror(errno));
		goto out_remove;
	}
	goto out_free;
out_remove:
	if (lf->f)
		fclose(lf->f);
	remove(lf->tmp);
out_free:
	file_free(lf);
	return ret;
}

void irdm_log_file_abort(struct irdm_log_file *lf)
{
	if (!lf)
		return;
	fclose(lf->f);
	remove(lf->tmp);
	file_free(lf);
}

/* ---- reading ---- */

struct irdm_log_reader {
	FILE *f;
	uint64_t next;
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
	if (h->header_size != IRDM_LOG_HEADER_SIZE || h->record_size != IRDM_TICK_RECORD_SIZE)
		return say(err, errlen, IRDM_EFORMAT, "%s: header size %u, record size %u: this build expects %u and %u",
			   path, h->header_size, h->record_size, IRDM_LOG_HEADER_SIZE,
			   IRDM_TICK_RECORD_SIZE);
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

/* The file holds exactly the records the header says. */
static int check_length(const struct irdm_log_header *h, uint64_t size, const char *path,
			char *err, size_t errlen)
{
	uint64_t body = size - IRDM_LOG_HEADER_SIZE;
	uint64_t whole = body / IRDM_TICK_RECORD_SIZE, part = body % IRDM_TICK_RECORD_SIZE;

	if (whole < h->record_count)
		return say(err, errlen, IRDM_ETRUNC, "%s: truncated: the header says %llu records, the file holds %llu and %llu bytes of the next",
			   path, (unsigned long long)h->record_count, (unsigned long long)whole,
			   (unsigned long long)part);
	if (whole > h->record_count || part)
		return say(err, errlen, IRDM_EFORMAT, "%s: the header says %llu records, the file holds more (%llu bytes after them)",
			   path, (unsigned long long)h->record_count,
			   (unsigned long long)(body - h->record_count * IRDM_TICK_RECORD_SIZE));
	return IRDM_OK;
}

static int read_header(struct irdm_log_reader *r, char *err, size_t errlen)
{
	struct stat st;
	size_t got;
	int ret;

	if (fstat(fileno(r->f), &st))
		return say(err, errlen, IRDM_EIO, "%s: cannot stat: %s", r->path, strerror(errno));
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
	if (ret)
		return ret;
	return check_length(&r->hdr, (uint64_t)st.st_size, r->path, err, errlen);
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
	if (!r)
		return say(err, errlen, IRDM_ENOMEM, "%s: out of memory", path);
	strcpy(r->path, path);
	r->f = fopen(path, "rb");
	if (!r->f) {
		ret = say(err, errlen, IRDM_EIO, "%s: cannot open: %s", path, strerror(errno));
		goto out_free;
	}
	ret = read_header(r, err, errlen);
	if (ret)
		goto out_close;
	*out = r;
	return IRDM_OK;
out_close:
	fclose(r->f);
out_free:
	free(r);
	return ret;
}

const struct irdm_log_header *irdm_log_header(const struct irdm_log_reader *r)
{
	return &r->hdr;
}

int irdm_log_next(struct irdm_log_reader *r, struct irdm_tick_record *rec, char *err,
		  size_t errlen)
{
	if (r->next == r->hdr.record_count)
		return 0;
	if (fread(rec, sizeof(*rec), 1, r->f) != 1)
		return say(err, errlen, IRDM_EIO, "%s: record %llu of %llu: %s", r->path,
			   (unsigned long long)r->next, (unsigned long long)r->hdr.record_count,
			   ferror(r->f) ? strerror(errno) : "end of file (did the file shrink?)");
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
	free(r);
}
