/* SPDX-License-Identifier: MIT */
/*
 * irdm-fw --view: the live view's publisher (docs/view.md).  One thread,
 * SCHED_OTHER at nice 10 and off the force loop's CPU, runs the view's
 * server (tools/view/view_server.c) and, VIEW_RATE_HZ times a second,
 * makes one frame from what the controller's other threads left for it:
 *
 *  - the deformed surface: the deformation worker's callback (or, in
 *    virtual time, the loop's update) offers each frame through a triple
 *    buffer (an atomic exchange; the offering side never waits, the
 *    publisher takes the newest);
 *  - the controller's state, devices and the chart: the loop pushes each
 *    tick's telemetry record into a ring of its own (irdm/telemetry.h:
 *    lock-free, drops when full), which the publisher drains.
 *
 * The loop itself does no network or file I/O and takes no lock for the
 * view; a page that is slow or gone only makes the server skip frames.
 */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/rt.h"
#include "view/view_msg.h"
#include "view/view_server.h"

#include "fw.h"

#define VIEW_RATE_HZ 50.0
#define VIEW_RING_RECORDS 1024u /* 1 s at 1 kHz: the publisher may stall that long */
#define VIEW_SAMPLES_MAX 1024u  /* chart samples in one frame */
#define VIEW_NICE 10
#define FRESH 4u /* in mid: the middle buffer holds a new frame */

struct fw_view {
	struct fw *fw;
	struct view_server *srv;
	pthread_t tid;
	bool started;
	struct irdm_telem_ring *ring;
	void *ring_mem;
	uint32_t rows;
	/* the triple buffer: the offering side owns buf[w], the publisher
	 * buf[r], and mid (with FRESH) names the third */
	float *buf[3];
	uint64_t buf_tick[3];
	unsigned w, r;
	atomic_uint mid;
	bool have_pos;
	struct irdm_tick_record pop[IRDM_LOG_WRITER_CHUNK];
	struct irdm_tick_record last;
	bool have_last;
	struct view_sample smp[VIEW_SAMPLES_MAX];
	unsigned char *msg;
	size_t msg_cap;
};

void fw_view_offer(struct fw_view *v, const double *pos_m, uint64_t tick)
{
	float *b;

	if (!v)
		return;
	b = v->buf[v->w];
	for (size_t i = 0; i < 3 * (size_t)v->rows; i++)
		b[i] = (float)pos_m[i];
	v->buf_tick[v->w] = tick;
	v->w = atomic_exchange_explicit(&v->mid, v->w | FRESH, memory_order_acq_rel) & 3u;
}

static double wall_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* The chart's samples since the last frame, and the newest record. */
static uint32_t drain_ring(struct fw_view *v, double period_s)
{
	uint32_t n = 0;
	size_t got;

	while ((got = irdm_telem_ring_pop(v->ring, v->pop, IRDM_LOG_WRITER_CHUNK)) > 0) {
		for (size_t i = 0; i < got; i++) {
			/* more than a frame's worth: keep the newest */
			if (n == VIEW_SAMPLES_MAX) {
				memmove(v->smp, v->smp + 1, (VIEW_SAMPLES_MAX - 1) * sizeof(v->smp[0]));
				n--;
			}
			view_sample_from_record(&v->smp[n++], &v->pop[i], period_s);
		}
		v->last = v->pop[got - 1];
		v->have_last = true;
	}
	return n;
}

static void publish(void *ctx, struct view_server *srv)
{
	struct fw_view *v = ctx;
	double period_s = v->fw->board.period_us * 1e-6;
	struct view_frame f;
	uint32_t n = drain_ring(v, period_s);
	bool fresh = false;
	size_t len;

	if (atomic_load_explicit(&v->mid, memory_order_acquire) & FRESH) {
		v->r = atomic_exchange_explicit(&v->mid, v->r, memory_order_acq_rel) & 3u;
		v->have_pos = fresh = true;
	}
	if (!v->have_last)
		return;
	memset(&f, 0, sizeof(f));
	view_frame_from_record(&f, &v->last);
	/* the log keeps the tip in the device frame; the page draws the object's */
	for (unsigned i = 0; i < f.n_dev; i++) {
		double tip[3];

		irdm_board_device_to_object(&v->fw->board, v->last.dev[i].tip_pos_m, tip);
		for (int k = 0; k < 3; k++)
			f.dev[i].tip_m[k] = (float)tip[k];
	}
	f.newest_tick = (double)v->last.tick;
	f.tick = v->have_pos ? (double)v->buf_tick[v->r] : f.newest_tick;
	f.t_s = f.newest_tick * period_s;
	f.sent_ms = wall_ms();
	f.dropped = (double)irdm_telem_ring_drops(v->ring);
	len = view_frame_write(v->msg, &f, fresh ? v->buf[v->r] : NULL, v->rows, v->smp, n);
	view_server_publish(srv, v->msg, len);
}

static int send_hello(struct fw_view *v)
{
	struct view_hello h = { .mode = VIEW_MODE_LIVE, .n_dev = v->fw->board.devices, .period_s = (float)(v->fw->board.period_us * 1e-6), .name = v->fw->board.name };
	unsigned char *buf;
	size_t len = view_hello_image(&buf, v->fw->s->img, &h);
	int rc = len ? view_server_set_hello(v->srv, buf, len) : IRDM_ENOMEM;

	free(buf);
	return rc;
}

/* "[ADDR:]PORT" */
static int parse_view(struct fw *fw, char *addr, size_t addrlen, unsigned *port)
{
	if (!view_parse_listen(fw->args.view, addr, addrlen, port))
		return IRDM_OK;
	snprintf(fw->err, sizeof(fw->err), "--view '%s': expected [ADDR:]PORT, PORT 0..65535",
		 fw->args.view);
	return IRDM_EINVAL;
}

static int alloc_buffers(struct fw_view *v)
{
	size_t bytes = irdm_telem_ring_mem_size(VIEW_RING_RECORDS);

	v->ring_mem = aligned_alloc(64, (bytes + 63) / 64 * 64);
	if (!v->ring_mem || irdm_telem_ring_init(&v->ring, v->ring_mem, bytes, VIEW_RING_RECORDS))
		return IRDM_ENOMEM;
	for (int i = 0; i < 3; i++) {
		v->buf[i] = calloc(3 * (size_t)(v->rows ? v->rows : 1), sizeof(float));
		if (!v->buf[i])
			return IRDM_ENOMEM;
	}
	v->w = 0;
	atomic_init(&v->mid, 1u);
	v->r = 2;
	v->msg_cap = view_frame_size(v->rows, VIEW_SAMPLES_MAX);
	v->msg = malloc(v->msg_cap);
	return v->msg ? IRDM_OK : IRDM_ENOMEM;
}

int fw_view_open(struct fw *fw)
{
	struct view_server_config c = { .rate_hz = VIEW_RATE_HZ, .tick = publish };
	struct fw_view *v;
	char addr[64];
	int rc;

	if (!fw->args.view)
		return IRDM_OK;
	rc = parse_view(fw, addr, sizeof(addr), &c.port);
	if (rc)
		return rc;
	v = calloc(1, sizeof(*v));
	if (!v)
		return IRDM_ENOMEM;
	fw->view = v;
	v->fw = fw;
	v->rows = fw->frame.every_ticks ? fw->s->img->meta->n_nodes : 0;
	rc = alloc_buffers(v);
	if (rc) {
		snprintf(fw->err, sizeof(fw->err), "--view: out of memory");
		return rc;
	}
	c.addr = addr;
	c.ctx = v;
	c.max_frame = v->msg_cap;
	rc = view_server_open(&v->srv, &c, fw->err, sizeof(fw->err));
	if (!rc && send_hello(v))
		rc = IRDM_ENOMEM;
	if (rc)
		return rc;
	if (strcmp(addr, VIEW_DEFAULT_ADDR))
		fprintf(stderr, "irdm-fw: warning: the view listens on %s:%u: whoever reaches it "
				"can watch the run (it cannot command the device)\n",
			addr,
			view_server_port(v->srv));
	printf("view: http://%s:%u/\n", addr, view_server_port(v->srv));
	fflush(stdout);
	fw->view_ring = v->ring;
	if (fw->frame.every_ticks)
		fw->frame.view = v;
	return IRDM_OK;
}

static void *serve(void *arg)
{
	struct fw_view *v = arg;
	pid_t tid = (pid_t)syscall(SYS_gettid);

	/* its name in /proc: what irdm-fw's start-up lines call it */
	prctl(PR_SET_NAME, "irdm-view", 0UL, 0UL, 0UL);
	/* below the deformation worker and beside the log writer */
	(void)setpriority(PRIO_PROCESS, (id_t)tid, VIEW_NICE);
	view_server_run(v->srv);
	return NULL;
}

int fw_view_start(struct fw *fw)
{
	struct irdm_rt_sched s = { SCHED_OTHER, 0, IRDM_RT_ANY_CPU };
	struct fw_view *v = fw->view;
	int rc;

	if (!v)
		return IRDM_OK;
	if (fw->board.cpu >= 0)
		s.cpu = IRDM_RT_CPU_EXCEPT(fw->board.cpu);
	rc = irdm_rt_thread_start(&v->tid, &s, serve, v);
	if (rc) {
		snprintf(fw->err, sizeof(fw->err), "--view: cannot start the view's thread");
		return rc;
	}
	v->started = true;
	return IRDM_OK;
}

/* After the deformation worker is joined (it offers frames to the view). */
void fw_view_close(struct fw *fw)
{
	struct fw_view *v = fw->view;
	struct view_server_stats st;

	if (!v)
		return;
	if (v->started) {
		view_server_stop(v->srv);
		pthread_join(v->tid, NULL);
	}
	if (v->srv && !fw->args.quiet) {
		view_server_stats(v->srv, &st);
		printf("view: %llu frames published, %llu sent, %llu skipped for slow pages; "
		       "%llu pages opened, %llu refused\n",
		       (unsigned long long)st.frames_published, (unsigned long long)st.frames_sent,
		       (unsigned long long)st.frames_skipped, (unsigned long long)st.ws_opened,
		       (unsigned long long)(st.ws_refused + st.ws_kicked));
	}
	view_server_close(v->srv);
	fw->view_ring = NULL;
	fw->frame.view = NULL;
	for (int i = 0; i < 3; i++)
		free(v->buf[i]);
	free(v->msg);
	free(v->ring_mem);
	free(v);
	fw->view = NULL;
}
