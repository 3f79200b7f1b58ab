/* SPDX-License-Identifier: MIT */
/*
 * The telemetry log file (its layout: irdm/telemetry.h, docs/log-format.md):
 * a synchronous writer, the writer thread that drains the tick's ring into
 * it, and the reader.  Off the tick: stdio, allocation and threads.
 */
#ifndef IRDM_POSIX_TELEMETRY_LOG_H
#define IRDM_POSIX_TELEMETRY_LOG_H

#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/telemetry.h"

/* The size in bytes of a complete log of n records. */
uint64_t irdm_log_size(uint64_t n);

/* What the caller says about a run; names are cut to fit the header. */
struct irdm_log_info {
	uint32_t period_us; /* > 0 */
	uint32_t n_devices; /* 0..IRDM_TELEM_MAX_DEVICES */
	int64_t start_time_ns;
	const char *board; /* NULL: "" */
	const char *image; /* NULL: "" */
};

/* A log being written, synchronously (the writer thread runs on one). */
struct irdm_log_file;

/*
 * Create a temporary beside PATH (irdm/posix/outfile.h) and write the header
 * (record_count IRDM_LOG_COUNT_OPEN).
 * Init-time (allocates, opens a file).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if an argument is NULL, period_us is 0 or n_devices too large;
 * IRDM_ENOMEM if out of memory;
 * IRDM_EEXIST if PATH is there and not a regular file;
 * IRDM_EIO if the temporary cannot be created or written.
 * On error *lf is NULL, nothing is left on disk and err says why.
 */
int irdm_log_file_open(struct irdm_log_file **lf, const char *path,
		       const struct irdm_log_info *info, char *err, size_t errlen);

/*
 * Append n records, closing each block that fills.
 *
 * Return: IRDM_OK; IRDM_EIO if a write failed (err says why).  The first
 * failure sticks: later appends fail at once, and irdm_log_file_close()
 * reports it and leaves nothing on disk.
 */
int irdm_log_file_append(struct irdm_log_file *lf, const struct irdm_tick_record *rec,
			 size_t n, char *err, size_t errlen);

/*
 * Close the last block, write the trailer, record_count and `dropped` into
 * the header, flush, sync, close, and rename the temporary onto PATH.
 * Frees lf in every case.
 *
 * Return: IRDM_OK; IRDM_EIO if any write (an earlier append's included),
 * the flush, the sync, the close or the rename failed (the temporary is
 * removed; PATH is untouched; err names PATH and the reason).
 */
int irdm_log_file_close(struct irdm_log_file *lf, uint64_t dropped, char *err, size_t errlen);

/* Close and remove the temporary (PATH is untouched); frees lf.  NULL is fine. */
void irdm_log_file_abort(struct irdm_log_file *lf);

/* Records appended so far. */
uint64_t irdm_log_file_count(const struct irdm_log_file *lf);

/* ---- the writer thread: ring -> log ---- */

struct irdm_log_writer;
struct irdm_rt_sched;

#define IRDM_LOG_WRITER_CHUNK 256    /* records per fwrite at most */
#define IRDM_LOG_WRITER_IDLE_US 2000 /* sleep when the ring is empty */

/*
 * Open the log (irdm_log_file_open) and start a thread that pops `ring`
 * (whose only consumer it becomes) and appends what it pops in chunks of
 * up to IRDM_LOG_WRITER_CHUNK records, sleeping IRDM_LOG_WRITER_IDLE_US
 * when the ring is empty.  sched NULL: SCHED_OTHER at nice 19 on any CPU,
 * the lowest of the controller's threads (below SCHED_FIFO ones and below
 * a SCHED_OTHER deformation thread).  After a write error the thread keeps
 * popping (so the tick sees no difference) and discards.  Init-time.
 *
 * Size the ring for the writer's longest stall (disk, page cache): at 1 kHz
 * 1024 records hold about a second.  In virtual time the loop can outrun
 * any writer; for a complete, reproducible log it should not push faster
 * than the ring drains (wait while irdm_telem_ring_used() is near the
 * capacity), or drain the ring itself through irdm_log_file_append().
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL, IRDM_ENOMEM, IRDM_EIO as irdm_log_file_open(), or if ring
 * is NULL;
 * IRDM_EPERM, IRDM_ETHREAD as irdm_rt_thread_start() (nothing left on disk).
 * On error *w is NULL and err says why.
 */
int irdm_log_writer_start(struct irdm_log_writer **w, const char *path,
			  const struct irdm_log_info *info, struct irdm_telem_ring *ring,
			  const struct irdm_rt_sched *sched, char *err, size_t errlen);

/*
 * Stop the thread after it has drained the ring (call once the producer
 * has stopped pushing), record the ring's drops in the header, close and
 * rename into place.  Frees w.
 *
 * Return: IRDM_OK; IRDM_EIO if any write failed (PATH.tmp is removed and
 * PATH untouched; err says why).
 */
int irdm_log_writer_stop(struct irdm_log_writer *w, char *err, size_t errlen);

/* Records the writer has written so far (any thread). */
uint64_t irdm_log_writer_count(const struct irdm_log_writer *w);

/* ---- reading a log ---- */

struct irdm_log_reader;

/*
 * Open a log and validate its frame before the first record: magic,
 * version, the header's checksum and fields, the strings, that the file's
 * length is that of record_count records in their blocks with the
 * trailer, and the trailer.  Each block's checksum is checked as
 * irdm_log_next() reaches it, before any of its records is returned: a
 * consumer that commits nothing before the last record (irdm log export,
 * irdm replay --log) never uses a damaged log.  Init-time (allocates).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if an argument is NULL;
 * IRDM_ENOMEM if out of memory;
 * IRDM_EIO if the file cannot be opened or read, or is not a regular file;
 * IRDM_EMAGIC if it is not an IRDM log;
 * IRDM_EVERSION if its version is not IRDM_LOG_VERSION;
 * IRDM_ECRC if the header's or the trailer's checksum is wrong;
 * IRDM_EFORMAT if a header field is invalid (sizes, n_devices, strings),
 * the trailer disagrees with the header, or bytes follow the trailer;
 * IRDM_ETRUNC if it is shorter than its header, was never closed, or ends
 * early (err names the block it ends in: "truncated: ends in block 3 of
 * 5 (records 768..1023)").
 * On error *r is NULL and err says why.
 */
int irdm_log_open(struct irdm_log_reader **r, const char *path, char *err, size_t errlen);

const struct irdm_log_header *irdm_log_header(const struct irdm_log_reader *r);

/*
 * Read the next record.
 *
 * Return: 1 if *rec holds the next record; 0 at the end (after
 * record_count records);
 * IRDM_ECRC if the record's block fails its checksum, IRDM_EFORMAT if its
 * block end is not the one expected (err: "block 2 (records 512..767):
 * ...");
 * IRDM_EIO if the read failed or the file shrank since it was opened;
 * IRDM_EFORMAT if the record's n_devices is over IRDM_TELEM_MAX_DEVICES
 * (err says why).
 */
int irdm_log_next(struct irdm_log_reader *r, struct irdm_tick_record *rec, char *err,
		  size_t errlen);

/* Close; NULL is fine. */
void irdm_log_close(struct irdm_log_reader *r);

#endif /* IRDM_POSIX_TELEMETRY_LOG_H */
