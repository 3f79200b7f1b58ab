/* SPDX-License-Identifier: MIT */
/*
 * Telemetry of the 1 kHz controller: what each tick did, carried out of the
 * tick without making it wait.
 *
 *   force tick --push--> SPSC ring --pop--> log writer thread --> LOG.tmp
 *   (no lock,            (caller memory,    (lowest priority,      renamed to
 *    no stdio)            drops when full)   fwrite in chunks)      LOG on close)
 *
 * Tick side (telemetry_ring.c, telemetry_hist.c): no allocation, lock,
 * system call, stdio or pthread call; safe inside the tick.  The ring is
 * lock-free with C11 atomics (acquire/release), one producer (the tick) and
 * one consumer (the writer).  The histograms are plain fixed-size structs
 * owned by the tick; read them once the tick has stopped.
 *
 * Off-tick side (the platform's, irdm/posix/telemetry_log.h: the log
 * file's writer and reader, and the writer thread): stdio, allocation and
 * threads, init-time or in their own thread only.
 *
 * The log file (little-endian; this code stores its structs as they are in
 * memory, so it builds only on little-endian hosts, checked at compile time):
 *   struct irdm_log_header   (IRDM_LOG_HEADER_SIZE bytes)
 *   struct irdm_tick_record  x record_count (header.record_size bytes each)
 */
#ifndef IRDM_TELEMETRY_H
#define IRDM_TELEMETRY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"

/* ---- the per-tick record ---- */

#define IRDM_TELEM_MAX_DEVICES 2
#define IRDM_TELEM_NO_TRI UINT32_MAX /* contact_tri when no proxy is active */

/*
 * Controller states as stored in irdm_tick_record.state.  The controller
 * defines the same numbers as its enum (irdm/safety.h: IRDM_SAFETY_INIT ..
 * IRDM_SAFETY_OFF); they are part of the log format and never change.
 */
enum irdm_telem_state {
	IRDM_TELEM_STATE_INIT = 0,
	IRDM_TELEM_STATE_READY = 1,
	IRDM_TELEM_STATE_ENABLED = 2,
	IRDM_TELEM_STATE_FAULT = 3,
	IRDM_TELEM_STATE_OFF = 4,
};
#define IRDM_TELEM_N_STATES 5

/*
 * Bits of irdm_tick_record.fault_flags: what the safety layer saw in the
 * tick, as a set: a limit it enforced (CLAMP) and every reason to zero the
 * torque or hold the last safe force.  Part of the log format: a bit never
 * changes meaning; new reasons take new bits.
 */
enum irdm_telem_fault {
	IRDM_TELEM_FAULT_CLAMP = 1u << 0,         /* torque clamped to the board's limit */
	IRDM_TELEM_FAULT_WORKSPACE = 1u << 1,     /* tip outside the workspace limits */
	IRDM_TELEM_FAULT_VELOCITY = 1u << 2,      /* tip speed over the velocity limit */
	IRDM_TELEM_FAULT_WATCHDOG = 1u << 3,      /* a tick came too late (watchdog) */
	IRDM_TELEM_FAULT_OVERRUN = 1u << 4,       /* compute overran the period */
	IRDM_TELEM_FAULT_ENCODER_NAN = 1u << 5,   /* NaN/Inf joint angle or velocity */
	IRDM_TELEM_FAULT_ENCODER_RANGE = 1u << 6, /* encoder value out of range */
	IRDM_TELEM_FAULT_SIGNAL = 1u << 7,        /* SIGINT/SIGTERM */
	IRDM_TELEM_FAULT_HAL_READ = 1u << 8,      /* the HAL could not read joint state */
	IRDM_TELEM_FAULT_HAL_WRITE = 1u << 9,     /* the HAL could not write torques */
	IRDM_TELEM_FAULT_HAL_FAULT = 1u << 10,    /* the HAL's poll reported a fault */
	IRDM_TELEM_FAULT_ENGINE = 1u << 11,       /* the force engine returned an error */
};
#define IRDM_TELEM_N_FAULTS 12

/* Proxy state as stored in irdm_tick_dev.proxy: enum irdm_proxy_event
 * (irdm/contact.h): 0 free, 1 touch, 2 slide, 3 release. */
#define IRDM_TELEM_N_PROXY 4

/*
 * One device in one tick; all frames are the object frame of the image
 * (docs/architecture.md, "Frames and signs").  Doubles, so that a log
 * carries the controller's values bit for bit (the replay comparison is at
 * 1e-9 relative; a float would not do).
 */
struct irdm_tick_dev {
	double tip_pos_m[3];
	double tip_vel_m_s[3]; /* estimated from the encoders */
	double joint_angle_rad[3];
	double joint_torque_nm[3]; /* commanded, after clamping */
	double force_n[3];         /* force on the object (the device renders -force_n) */
	uint32_t contact_tri;      /* the proxy's SURFACE triangle, IRDM_TELEM_NO_TRI: none */
	uint8_t proxy;             /* enum irdm_proxy_event */
	uint8_t softened;          /* 1: the contact began softly this tick
					 * (irdm_engine_contact_soften()), 0 */
	uint8_t reserved[2];       /* zero */
	/*
	 * The engine's command this tick, all that `irdm replay --sites`
	 * needs to repeat it: the site (SURFACE triangle and barycentrics;
	 * site_tri IRDM_TELEM_NO_TRI when no contact was commanded) and the
	 * target (the tip less the site's rest point, object frame).
	 */
	uint32_t site_tri;
	uint32_t reserved2; /* zero */
	double site_bary[3];
	double target_m[3];
};

/*
 * One tick.  Plain old data of fixed size with no implicit padding (the
 * offsets are checked at compile time), so that it is written to and read
 * from the log as it is.  Zero it before filling it, so that unused devices
 * and reserved bytes are zero and logs are reproducible.
 */
struct irdm_tick_record {
	uint64_t tick;           /* 0, 1, 2, ... since the loop started */
	int32_t wake_latency_ns; /* wake-up time minus the deadline (saturated) */
	uint32_t compute_ns;     /* the tick's work, wake-up to torque written */
	uint32_t fault_flags;    /* enum irdm_telem_fault bits */
	uint8_t state;           /* enum irdm_telem_state */
	uint8_t n_devices;       /* devices filled in dev[], 0..IRDM_TELEM_MAX_DEVICES */
	uint8_t reserved[2];     /* zero */
	struct irdm_tick_dev dev[IRDM_TELEM_MAX_DEVICES];
};

#define IRDM_TICK_RECORD_SIZE 392u

/* ---- the ring: tick -> writer, lock-free, one producer, one consumer ---- */

struct irdm_telem_ring; /* opaque, in caller memory */

/*
 * Bytes irdm_telem_ring_init() needs for `capacity` records (any
 * alignment of the memory will do: the ring aligns itself inside it); 0 if
 * capacity is not a power of two in [2, IRDM_TELEM_RING_MAX].
 */
#define IRDM_TELEM_RING_MAX (1u << 24)
size_t irdm_telem_ring_mem_size(uint32_t capacity);

/*
 * Initialise an empty ring of `capacity` records in mem (which must
 * outlive it).  Init-time: not concurrently with push or pop.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if ring or mem is NULL or capacity is not a power of two in
 * [2, IRDM_TELEM_RING_MAX];
 * IRDM_ENOMEM if mem_size < irdm_telem_ring_mem_size(capacity).
 * On error *ring is NULL.
 */
int irdm_telem_ring_init(struct irdm_telem_ring **ring, void *mem, size_t mem_size,
			 uint32_t capacity);

/*
 * Producer (one thread only, the tick): copy *rec into the ring.  Never
 * blocks: when the ring is full the record is dropped and counted.
 *
 * Return: IRDM_OK; IRDM_EBUSY if the ring was full (the record is dropped).
 */
int irdm_telem_ring_push(struct irdm_telem_ring *ring, const struct irdm_tick_record *rec);

/*
 * Consumer (one thread only): move up to max records, oldest first, into
 * out.  Never blocks.  Returns how many were moved (0: empty).
 */
size_t irdm_telem_ring_pop(struct irdm_telem_ring *ring, struct irdm_tick_record *out,
			   size_t max);

/* Records dropped because the ring was full, since init (any thread). */
uint64_t irdm_telem_ring_drops(const struct irdm_telem_ring *ring);

/* Records waiting to be popped (any thread): a snapshot, which the other
 * side may change as soon as it is taken. */
uint32_t irdm_telem_ring_used(const struct irdm_telem_ring *ring);

uint32_t irdm_telem_ring_capacity(const struct irdm_telem_ring *ring);

/* ---- histograms: latency and compute time, fixed memory ---- */

/*
 * Log-spaced bins from IRDM_HIST_MIN_NS (100 ns) to IRDM_HIST_MAX_NS
 * (100 ms): IRDM_HIST_BINS_PER_DECADE bins per decade, 300 in all, each
 * [edge_ns[i], edge_ns[i+1]) with edge_ns[i] = ceil(100 ns * r^i) and
 * r = 10^(1/50) = 1.0471 (bins 4.7 % wide), plus one bin below 100 ns
 * (zero and negative values too) and one at or above 100 ms.
 *
 * Percentiles are nearest-rank: the p-quantile of n samples is the k-th
 * smallest with k = ceil(p n) (k >= 1).  The histogram reports the largest
 * value its bin can hold, clamped to the maximum seen, so the error is
 * one-sided and bounded:
 *   exact <= reported < r * exact    for exact in [100 ns, 100 ms);
 *   exact <= reported < 100 ns       for exact below 100 ns;
 *   reported = max (exact)           for exact >= 100 ms (and for p = 1).
 *
 * Overruns: a sample above limit_ns (set at init; 0 = none counted) is an
 * overrun; the histogram counts them and the longest run of consecutive
 * ones (the policy "fault after K consecutive overruns" reads the run).
 */
#define IRDM_HIST_MIN_NS 100
#define IRDM_HIST_MAX_NS 100000000
#define IRDM_HIST_BINS_PER_DECADE 50
#define IRDM_HIST_LOG_BINS (6 * IRDM_HIST_BINS_PER_DECADE)
#define IRDM_HIST_BINS (IRDM_HIST_LOG_BINS + 2) /* + under + over */
#define IRDM_HIST_REL_WIDTH 1.0471285480508996  /* r = 10^(1/50) */

struct irdm_hist {
	uint32_t edge_ns[IRDM_HIST_LOG_BINS + 1]; /* edge_ns[0] = 100 ns ... 100 ms */
	uint64_t count[IRDM_HIST_BINS];           /* [0] < 100 ns, [1 + i] bin i, last: more */
	uint64_t n;
	int64_t min_ns, max_ns; /* valid when n > 0 */
	int64_t limit_ns;       /* overrun threshold, 0 = none */
	uint64_t overruns;
	uint64_t run; /* current run of consecutive overruns */
	uint64_t longest_run;
};

struct irdm_hist_summary {
	uint64_t n;
	int64_t p50_ns, p99_ns, p999_ns, max_ns, min_ns; /* 0 when n = 0 */
	uint64_t overruns, longest_run;
};

/*
 * Empty histogram; samples above limit_ns are overruns (0: none).
 * Init-time (it computes the bin edges).
 *
 * Return: IRDM_OK; IRDM_EINVAL if h is NULL or limit_ns < 0.
 */
int irdm_hist_init(struct irdm_hist *h, int64_t limit_ns);

/*
 * Add one sample (tick-safe: integer work and a binary search over the
 * edges, no call).  Returns the current run of consecutive overruns: 0 if
 * this sample was not one.
 */
uint64_t irdm_hist_add(struct irdm_hist *h, int64_t value_ns);

/*
 * The nearest-rank quantile at per_million / 1e6 (500000 = p50,
 * 999000 = p99.9, 1000000 = max) within the bound above; 0 if empty.
 * per_million is clamped to [1, 1000000].
 */
int64_t irdm_hist_quantile(const struct irdm_hist *h, uint32_t per_million);

/* p50, p99, p99.9, max, min, count and overruns of h. */
void irdm_hist_summarize(const struct irdm_hist *h, struct irdm_hist_summary *s);

/* ---- the log file ---- */

/*
 * The layout (docs/log-format.md): the header; the records in blocks of
 * block_records (the last block may be shorter, never empty), each block
 * followed by its struct irdm_log_block_end (a CRC-32C of its records);
 * then struct irdm_log_trailer (the record count again).  A log cut short,
 * or with one bit changed, is refused naming the block.
 */
#define IRDM_LOG_MAGIC "IRDMLOG" /* 8 bytes with its NUL */
#define IRDM_LOG_VERSION 3u      /* 3: blocks with CRC-32C, a trailer; 2: the engine's command */
#define IRDM_LOG_HEADER_SIZE 256u
#define IRDM_LOG_COUNT_OPEN UINT64_MAX /* record_count of a log never closed */
#define IRDM_LOG_NAME_LEN 64
#define IRDM_LOG_IMAGE_LEN 128
#define IRDM_LOG_BLOCK_RECORDS 256u      /* records per block (the last: fewer) */
#define IRDM_LOG_BLOCK_MAGIC "BLK"       /* 4 bytes with its NUL */
#define IRDM_LOG_TRAILER_MAGIC "IRDMEND" /* 8 bytes with its NUL */

struct irdm_log_header {
	char magic[8];                  /* IRDM_LOG_MAGIC */
	uint32_t version;               /* IRDM_LOG_VERSION */
	uint32_t header_size;           /* IRDM_LOG_HEADER_SIZE: records start here */
	uint32_t record_size;           /* IRDM_TICK_RECORD_SIZE */
	uint32_t period_us;             /* the tick's period */
	int64_t start_time_ns;          /* given by the caller: wall clock (ns since the
					 * epoch) in real time, 0 in virtual time so that
					 * logs are bit-identical run to run */
	uint64_t record_count;          /* written on close; IRDM_LOG_COUNT_OPEN before */
	uint64_t dropped;               /* records the ring dropped (full), on close */
	uint32_t n_devices;             /* 0..IRDM_TELEM_MAX_DEVICES */
	uint32_t reserved;              /* zero */
	char board[IRDM_LOG_NAME_LEN];  /* NUL-terminated, NUL-padded */
	char image[IRDM_LOG_IMAGE_LEN]; /* NUL-terminated, NUL-padded */
	uint32_t block_records;         /* IRDM_LOG_BLOCK_RECORDS */
	uint32_t header_crc32c;         /* CRC-32C of bytes [0, 252) */
};

/* After each block's records. */
struct irdm_log_block_end {
	char magic[4];      /* IRDM_LOG_BLOCK_MAGIC */
	uint32_t index;     /* the block's number, from 0 */
	uint32_t n_records; /* in this block: block_records, the last fewer */
	uint32_t crc32c;    /* CRC-32C of the block's records and the 12 bytes above */
};

/* After the last block: the file's end. */
struct irdm_log_trailer {
	char magic[8];         /* IRDM_LOG_TRAILER_MAGIC */
	uint64_t record_count; /* as the header's */
	uint64_t dropped;      /* as the header's */
	uint32_t n_blocks;
	uint32_t crc32c; /* CRC-32C of the 28 bytes above */
};

/* Names for the numbers in a record ("?" outside the range). */
const char *irdm_telem_state_name(unsigned state);
const char *irdm_telem_proxy_name(unsigned proxy);
const char *irdm_telem_fault_name(unsigned bit); /* bit 0..IRDM_TELEM_N_FAULTS-1 */

#endif /* IRDM_TELEMETRY_H */
