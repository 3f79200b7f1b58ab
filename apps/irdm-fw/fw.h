/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw: the controller program.  main() (irdm_fw.c) is the composition
 * root: it reads the arguments (fw_args.c) and the board, opens the session
 * on the image, registers the HAL back-ends this build carries
 * (fw_backends.c) and opens them, hands --user's script to the simulated
 * ones (fw_user.c), sets up real time (irdm/posix/rt.h), maps the board onto
 * the controller's configuration (fw_config.c), runs the loop (fw_loop.c:
 * the HAL and the tick only; fw_monitor.c takes what the summary and the
 * frames need off it) and prints the summary (fw_summary.c).  Private to
 * apps/irdm-fw.
 */
#ifndef IRDM_FW_H
#define IRDM_FW_H

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <time.h>

#include "irdm/board.h"
#include "irdm/posix/clock.h"
#include "irdm/controller.h"
#include "irdm/hal/hal.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/session.h"
#include "irdm/telemetry.h"

struct irdm_sim_user; /* the virtual user's script: fw_user.c alone reads it */

/* Exit codes (irdm-fw --help lists them). */
enum fw_exit {
	FW_EXIT_OK = 0,            /* ran to the end, no fault */
	FW_EXIT_USAGE = 2,         /* bad arguments */
	FW_EXIT_INPUT = 3,         /* board, image or user script refused */
	FW_EXIT_SETUP = 4,         /* HAL, real time (--require-rt) or memory refused */
	FW_EXIT_FAULT = 5,         /* the controller faulted: torque off, reason printed */
	FW_EXIT_SIGNAL = 6,        /* stopped by a signal: torque off, state off, logged */
	FW_EXIT_NEVER_ENABLED = 7, /* ran, but a limit kept the torque off throughout */
	FW_EXIT_EMERGENCY = 8,     /* a fatal (or second) signal: emergency torque off */
	FW_EXIT_LOG = 9,           /* ran, but its --log could not be written (none left) */
};

struct fw_args {
	const char *board;
	const char *image;
	const char *user;
	const char *log;
	const char *frame_out;  /* --frame-out: the VTK --frame-at writes */
	const char *frames_out; /* --frames-out: the directory of the series */
	const char *view;       /* --view [ADDR:]PORT: the live view (fw_view.c) */
	double duration_s;      /* 0: the user script's end + 1 s, else 5 s */
	double frame_at_s;      /* --frame-at: 0 none */
	double frames_every_s;  /* --frames-every: 0 none */
	int clock;              /* enum irdm_clock_mode */
	bool require_rt;
	bool force; /* --force: replace a --frames-out DIR we did not write */
	bool quiet;
	bool help;
	bool help_board; /* --help-board: the board keys, hal_options */
	int doc;         /* --doc: enum fw_doc, 0 none */
};

/* The documents irdm-fw writes from its option tables (fw_docs.c). */
enum fw_doc {
	FW_DOC_BOARDS = 1,  /* the key table of docs/boards.md */
	FW_DOC_HAL_OPTIONS, /* docs/hal-options.md */
};

/*
 * What the summary needs, in memory fixed at the start whatever the run's
 * length (a day's run locks what a second's does): the force's peak and
 * last value as they stream by, and the watched node's motion over the
 * ringing window after the latest release (one window's samples).
 */
struct fw_trace {
	uint64_t n, cap;        /* ticks traced; ticks the run has */
	double peak_n, final_n; /* |force on the object|, device 0 */
	uint64_t peak_at;
	bool contact;              /* device 0 in contact at the last tick */
	bool released;             /* a contact has ended */
	uint64_t release_at;       /* the tick after the latest contact ended */
	double *ring_u_m;          /* the watched node's displacement along its
					 * normal from release_at on */
	uint64_t ring_n, ring_max; /* samples held; the window's length */
};

/*
 * A frame to keep: the snapshot nearest target_tick (engine ticks).  The
 * worker (real time) or the monitor (virtual) fills the frame; the monitor
 * fills the contact at target_tick.
 */
struct fw_frame_slot {
	uint64_t target_tick, held_tick;
	double *pos_m; /* 3 rows, allocated at open */
	bool held;
	bool contact_seen, contact_on;
	double contact_m[3], force_obj_n[3];
};

#define FW_FRAMES_MAX 1000 /* --frames-every's series, at most */

/*
 * The deformation worker's side of the run (fw_frame.c).  Real time: its
 * thread is the single writer of the frames (pos_m, held*) and of the
 * counters below until it is joined; the loop never reads them.  Virtual
 * time: the monitor (fw_monitor.c) runs the update in the loop's thread,
 * every every_ticks engine ticks.
 * Slots are in target order: the --frames-every series (if any), and
 * --frame-at's slot among them at single_slot.
 */
struct fw_frame {
	struct irdm_deform_thread *th; /* real time only */
	struct fw_view *view;          /* --view: offered every frame (fw_view_offer) */
	unsigned every_ticks;          /* engine ticks between snapshots (publish_every) */
	uint64_t last_update_tick;     /* virtual time: the last engine tick updated at */
	uint32_t rows;
	struct fw_frame_slot *slot;
	unsigned n_slots, single_slot; /* single_slot: n_slots if no --frame-at */
	unsigned contact_next;         /* the monitor's: the next slot to take a contact */
	/* --frame-at's frame for the summary, copied at stop (the slots are
	 * freed before the summary prints) */
	bool single_held;
	uint64_t single_held_tick;
	double *scratch_m; /* 3 rows: virtual time's update target */
	/* ---- written by the worker's thread (real) or the monitor (virtual) */
	unsigned next; /* the first slot still looking for its frame */
	uint64_t frames;
	double cpu_sum_ns, cpu_max_ns;
	uint64_t cpu_n;
	struct timespec cpu_prev;
	bool cpu_started;
};

/* One tick as the run's monitor sees it (fw_monitor.c): device 0. */
struct fw_sample {
	uint64_t eng_tick; /* the engine's ticks after this one (the frames' clock) */
	int state;         /* enum irdm_safety_state after the tick */
	bool contact;
	double force_obj_n[3];
	double scale; /* force clamp x torque saturation */
	double proxy_m[3];
	double node_u_m; /* the watched node along its contact's normal */
};

/*
 * The run's monitor (fw_monitor.c): the watched node (the loop's side),
 * and in real time the samples' ring to the consumer thread.
 */
struct fw_monitor {
	uint32_t watch_row; /* the image node whose ringing is measured */
	bool watching;
	double watch_normal[3];
	struct fw_sample *ring;      /* real time only */
	_Atomic uint64_t head, tail; /* written by the loop; by the consumer */
	atomic_bool stop;
	pthread_t tid;
	bool running;
	uint64_t lost; /* samples a full ring lost */
};

struct fw {
	struct fw_args args;
	struct irdm_board board;
	struct irdm_session *s;
	struct irdm_ctrl ctrl;
	struct irdm_ctrl_config ccfg;
	struct irdm_hal_config hcfg[IRDM_BOARD_DEVICES_MAX];
	struct irdm_device_config dev[IRDM_BOARD_DEVICES_MAX];
	struct irdm_hal_dev hal[IRDM_BOARD_DEVICES_MAX];
	void *hal_mem[IRDM_BOARD_DEVICES_MAX];
	bool hal_open[IRDM_BOARD_DEVICES_MAX];
	struct irdm_sim_user *user; /* NULL without --user */
	struct irdm_clock clock;
	int idle_hold; /* real time: the CPUs' idle-latency request, or < 0 */
	struct fw_trace trace;
	double rendered_peak_n; /* |force on tip 0| after the clamp and saturation */
	uint64_t rendered_peak_tick;
	struct fw_frame frame;
	struct irdm_outdir frames_dir; /* --frames-out's, claimed before the run */
	/* telemetry: per-tick records through a ring to the log (--log) */
	struct irdm_telem_ring *ring;
	void *ring_mem;
	struct irdm_log_writer *writer;    /* real time: a thread drains the ring */
	struct irdm_log_file *logf;        /* virtual time: the loop drains it */
	struct fw_view *view;              /* --view */
	struct irdm_telem_ring *view_ring; /* --view: the same records, for the view */
	struct irdm_hist latency;          /* ns, real time only (0 in virtual time) */
	struct irdm_hist compute_measured; /* ns, measured in both clocks; limit: the period */
	struct fw_monitor monitor;
	uint64_t run_ticks; /* the run's length, ticks */
	uint64_t ticks;
	bool enabled_once;       /* the state was ENABLED in some tick */
	uint32_t enable_blocked; /* the conditions that refused the last enable */
	uint32_t last_cause;
	int last_state;
	char err[512];
};

/* fw_args.c */
int fw_args_parse(struct fw_args *a, int argc, char **argv, char *err, size_t errlen);
void fw_args_usage(FILE *f);

/* fw_config.c: the board's arm, limits, placement and coupling, for the
 * controller; the session's engine configuration. */
int fw_config_from_board(struct irdm_ctrl_config *c, const struct irdm_board *b);

/* --help-board: the board keys, then each back-end's hal_options. */
void fw_help_board(FILE *f);

/* --doc: that document, as Markdown. */
void fw_write_doc(FILE *f, enum fw_doc doc);
/* Why irdm_ctrl_init() refused, naming the board or the image (fw->err). */
const char *fw_ctrl_init_why(struct fw *fw);

/*
 * fw_backends.c: the HAL back-ends this build carries, each from its own
 * file (fw_backend_<name>.c) as the build configuration says.
 * fw_backends_register() fills the HAL core's table with them;
 * fw_backend_of() is NULL for a name unknown or not built;
 * fw_backend_check_built() refuses (IRDM_ENOTSUP, fw->err: the board's
 * file and line, the CONFIG_ switch) a board whose back-end this build
 * left out; fw_user_hal_why() says why --user cannot run on the board's.
 */
struct fw_backend {
	const struct irdm_hal_backend *hal;
	bool simulated_arm; /* a virtual user (--user) can push its arm */
};

void fw_backends_register(void);
const struct fw_backend *fw_backend_of(const char *name);
int fw_backend_check_built(struct fw *fw);
const char *fw_user_hal_why(struct fw *fw);

/*
 * fw_user.c (fw_user_none.c without a simulated back-end): --user's
 * script.  fw_user_open() reads it and meets it with the board (fw->user;
 * fw->err: the whole message) before any device opens; fw_user_attach()
 * hands device i's hand to its open back-end; fw_user_end_s() is when the
 * script ends.
 */
int fw_user_open(struct fw *fw);
int fw_user_attach(struct fw *fw, unsigned device);
double fw_user_end_s(const struct fw *fw);
void fw_user_free(struct fw *fw);

/* fw_loop.c: runs until the duration is over, a fault or a signal.
 * Returns FW_EXIT_OK, FW_EXIT_FAULT, FW_EXIT_SIGNAL or FW_EXIT_NEVER_ENABLED. */
int fw_loop_run(struct fw *fw, volatile sig_atomic_t *signalled);

/* fw_signals.c: every signal's way out turns the torque off (armed before
 * any device opens; disarmed once they are closed).  flag: the loop's. */
int fw_signals_arm(struct fw *fw, volatile sig_atomic_t *flag);
/* A second signal escalates to the emergency path only while the loop
 * runs (true just before it, false as soon as it returns). */
void fw_signals_loop(bool running);
void fw_signals_disarm(void);
const char *fw_signal_name(int sig);

/* fw_monitor.c: what the summary and the frames take from each tick, off
 * the loop.  fw_monitor_open() before the real-time set-up,
 * fw_monitor_start() after it (the consumer thread, real time only),
 * fw_monitor_tick() in the loop after each tick, fw_monitor_stop() (join,
 * drain) before the frames are written, fw_monitor_free() at the end. */
int fw_monitor_open(struct fw *fw);
int fw_monitor_start(struct fw *fw);
void fw_monitor_tick(struct fw *fw, const struct irdm_ctrl_output *out);
void fw_monitor_stop(struct fw *fw);
void fw_monitor_free(struct fw *fw);

/* fw_log.c: open the log (--log) before the loop, drain and close after. */
int fw_log_open(struct fw *fw);
void fw_log_record(struct fw *fw, const struct irdm_ctrl_output *out, int64_t latency_ns,
		   int64_t compute_ns);
int fw_log_close(struct fw *fw);

/* fw_frame.c: the deformation worker and the frames it keeps;
 * fw_frame_vtk.c: writing them (--frame-at's file, --frames-every's series).
 * fw_frame_config() before the session opens (deform channel, snapshot
 * rate); fw_frame_check_args() (--frame-at against the board and the run's
 * length) and fw_frame_open() (worker, buffers) after the controller;
 * fw_frame_start() after the real-time set-up (the thread, real time only);
 * fw_frame_sample() from the run's monitor for each tick, in order (the
 * contact at a frame's tick; virtual time's update); fw_frame_stop() (join) and
 * fw_frame_write() before the session closes; fw_frame_summary() after.
 * fw_frame_claim_series() before the run: --frames-out's directory
 * (irdm/posix/outdir.h); fw_frame_free() removes it unless written. */
void fw_frame_config(struct fw *fw, struct irdm_session_config *sc);
int fw_frame_check_args(struct fw *fw, uint64_t run_ticks);
int fw_frame_open(struct fw *fw);
int fw_frame_start(struct fw *fw);
void fw_frame_sample(struct fw *fw, const struct fw_sample *s);
void fw_frame_stop(struct fw *fw);
int fw_frame_write(struct fw *fw);
int fw_frame_claim_series(struct fw *fw);
int fw_frame_write_series(struct fw *fw);
void fw_frame_summary(const struct fw *fw);
void fw_frame_free(struct fw *fw);

/* fw_view.c: --view's server and publisher (fw_view_none.c in the trimmed
 * builds: no view).  fw_view_open() after fw_frame_open(), fw_view_start()
 * after the real-time set-up, fw_view_close() after fw_frame_stop();
 * fw_view_offer() from the deformation worker's side (NULL: no view). */
struct fw_view;
int fw_view_open(struct fw *fw);
int fw_view_start(struct fw *fw);
void fw_view_offer(struct fw_view *v, const double *pos_m, uint64_t tick);
void fw_view_close(struct fw *fw);

/* fw_summary.c: fw_trace_alloc() once before the loop (the window for a
 * tick of period_us), fw_trace_add() every tick (no allocation). */
int fw_trace_alloc(struct fw_trace *t, uint64_t ticks, uint32_t period_us);
void fw_trace_add(struct fw_trace *t, double force_n, double node_u_m, bool contact);
void fw_trace_free(struct fw_trace *t);
void fw_summary_print(const struct fw *fw);
/* The first open device's one-line reason (struct irdm_hal_dev's why), or "". */
const char *fw_hal_why(const struct fw *fw);

#endif /* IRDM_FW_H */
