/* SPDX-License-Identifier: MIT */
/*
 * The live view (docs/view.md) end to end: irdm-fw with --view on the
 * simulated arm in real time, the page in headless Chromium (driven over
 * the DevTools pipe, tests/support/cdp.c), and what its screenshots show:
 *  - the object is drawn: the surface's colour where the object's centre
 *    projects, the background's in a corner;
 *  - the surface around the pressing tool turns from the colour scale's
 *    bottom (blue: no displacement) towards its top between a frame before
 *    contact and one during the hold (the hand presses 1 cm; the fixed
 *    scale tops at 1 cm);
 *  - the strip chart's force and compute-time lines and the state text
 *    ("enabled") are there, in their colours;
 *  - the page's own counters: frames received per second and the latency.
 * And bad requests: unknown paths, other methods, garbage and malformed
 * WebSocket frames, a client that talks, one from another site and one
 * that never reads are refused or dropped while a good client keeps
 * receiving and the run ends normally.
 *
 * Chromium absent: the browser test is skipped, saying so (CI installs it:
 * tools/scripts/install-deps.sh); the server's tests still run.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>
#include <png.h>

#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "support/cdp.h"
#include "support/run_prog.h"
#include "support/test_files.h"

#define BOARD "boards/sim-phantom.board"
#define VIEW_CLIENTS 8 /* the server's limit (tools/view/view_server.h) */
#define W 1000
#define H 600

static char dir[256], image[320], board[320], user[320], out_text[16384], err_text[8192];

static const char *env_or(const char *name, const char *dflt)
{
	const char *p = getenv(name);

	return p ? p : dflt;
}

static double now_s(void)
{
	struct timespec t;

	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void sleep_s(double s)
{
	struct timespec t = { (time_t)s, (long)((s - floor(s)) * 1e9) };

	nanosleep(&t, NULL);
}

/* irdm-fw with the view on any free loopback port (and a log unless
 * NULL); returns the port once the server listens (its line on stdout). */
static unsigned start_fw_at(pid_t *pid, const char *duration, const char *log, const char *view)
{
	char path[300], text[4096];
	unsigned port = 0;
	double t0 = now_s();

	*pid = rp_spawn(dir, env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){ "--board", board, "--image", image, "--user", user, "--duration", duration, "--view", view, log ? "--log" : NULL, log, NULL });
	snprintf(path, sizeof(path), "%s/stdout", dir);
	while (now_s() - t0 < 20) {
		FILE *f = fopen(path, "r");
		const char *p;

		if (f) {
			size_t n = fread(text, 1, sizeof(text) - 1, f);
			text[n] = '\0';
			fclose(f);
			p = strstr(text, "view: http://127.0.0.1:");
			if (p && sscanf(p, "view: http://127.0.0.1:%u/", &port) == 1 && port)
				return port;
		}
		if (waitpid(*pid, NULL, WNOHANG) == *pid)
			fail_msg("irdm-fw ended before its view listened");
		sleep_s(0.02);
	}
	fail_msg("irdm-fw's view did not listen within 20 s");
	return 0;
}

static unsigned start_fw_log(pid_t *pid, const char *duration, const char *log)
{
	return start_fw_at(pid, duration, log, "0");
}

static unsigned start_fw(pid_t *pid, const char *duration)
{
	return start_fw_log(pid, duration, NULL);
}

static int finish_fw(pid_t pid)
{
	return rp_finish(dir, pid, out_text, sizeof(out_text), err_text, sizeof(err_text));
}

/* ---- screenshots ---- */

struct shot {
	unsigned char *rgb;
	int w, h;
};

static void decode(struct shot *s, const unsigned char *png, size_t len)
{
	png_image im;

	memset(&im, 0, sizeof(im));
	im.version = PNG_IMAGE_VERSION;
	assert_true(png_image_begin_read_from_memory(&im, png, len));
	im.format = PNG_FORMAT_RGB;
	s->rgb = malloc(PNG_IMAGE_SIZE(im));
	assert_non_null(s->rgb);
	assert_true(png_image_finish_read(&im, NULL, s->rgb, 0, NULL));
	s->w = (int)im.width;
	s->h = (int)im.height;
}

static void screenshot(struct cdp *c, struct shot *s, const char *name)
{
	size_t len;
	unsigned char *png = cdp_screenshot(c, &len);
	char path[300];
	FILE *f;

	decode(s, png, len);
	/* kept beside the test's other files for a look when it fails */
	snprintf(path, sizeof(path), "%s/%s.png", dir, name);
	f = fopen(path, "wb");
	if (f) {
		fwrite(png, 1, len, f);
		fclose(f);
	}
	free(png);
}

/* Mean colour of the (2r+1)^2 patch at (x, y). */
static void patch(const struct shot *s, double x, double y, int r, double rgb[3])
{
	int n = 0, cx = (int)lround(x), cy = (int)lround(y);

	rgb[0] = rgb[1] = rgb[2] = 0;
	for (int j = cy - r; j <= cy + r; j++)
		for (int i = cx - r; i <= cx + r; i++) {
			if (i < 0 || j < 0 || i >= s->w || j >= s->h)
				continue;
			for (int k = 0; k < 3; k++)
				rgb[k] += s->rgb[3 * ((size_t)j * (size_t)s->w + (size_t)i) + k];
			n++;
		}
	assert_true(n > 0);
	for (int k = 0; k < 3; k++)
		rgb[k] /= n;
}

/* Pixels of the box within tol (sum of channel differences) of colour. */
static int count_colour(const struct shot *s, const int box[4], const int colour[3], int tol)
{
	int n = 0;

	for (int j = box[1]; j < box[1] + box[3] && j < s->h; j++)
		for (int i = box[0]; i < box[0] + box[2] && i < s->w; i++) {
			const unsigned char *p = s->rgb + 3 * ((size_t)j * (size_t)s->w + (size_t)i);
			if (abs(p[0] - colour[0]) + abs(p[1] - colour[1]) + abs(p[2] - colour[2]) <= tol)
				n++;
		}
	return n;
}

/* ---- the page ---- */

struct report {
	int connected, frames, fps;
	double t, latency_ms;
	char state[32];
};

static void report(struct cdp *c, struct report *r)
{
	char out[512];

	if (!cdp_eval(c, "window.irdmReport ? irdmReport() : 'loading'", out, sizeof(out)) ||
	    sscanf(out, "connected=%d frames=%d fps=%d t=%lf latency=%lf state=%31s", &r->connected,
		   &r->frames, &r->fps, &r->t, &r->latency_ms, r->state) != 6)
		memset(r, 0, sizeof(*r));
}

/* Wait (at most 30 s) until the page shows the run at t >= t_s. */
static void wait_page_time(struct cdp *c, double t_s, struct report *r)
{
	double t0 = now_s();

	for (;;) {
		report(c, r);
		if (r->connected && r->t >= t_s)
			return;
		if (now_s() - t0 > 30)
			fail_msg("the page did not reach t = %g s (at %g s, %d frames)", t_s, r->t,
				 r->frames);
		sleep_s(0.05);
	}
}

static void eval_ok(struct cdp *c, const char *expr, char *out, size_t len)
{
	if (!cdp_eval(c, expr, out, len))
		fail_msg("page: %s: %s", expr, out);
}

static void project(struct cdp *c, double x, double y, double z, double px[2])
{
	char expr[128], out[64];

	snprintf(expr, sizeof(expr), "irdmProject(%g, %g, %g)", x, y, z);
	eval_ok(c, expr, out, sizeof(out));
	assert_int_equal(sscanf(out, "%lf %lf", &px[0], &px[1]), 2);
}

static void rect(struct cdp *c, const char *id, int box[4])
{
	char expr[128], out[64];

	snprintf(expr, sizeof(expr), "irdmRect('%s')", id);
	eval_ok(c, expr, out, sizeof(out));
	assert_int_equal(sscanf(out, "%d %d %d %d", &box[0], &box[1], &box[2], &box[3]), 4);
}

/* Around the top centre the hand presses: 1.2 cm from it on the top face,
 * beside the tool, its proxy and the force arrow (drawn up from the proxy). */
static const double ring[3][3] = {
	{ 0.062, 0.05, 0.2 },
	{ 0.038, 0.05, 0.2 },
	{ 0.05, 0.038, 0.2 },
};

/* Red minus blue: the colour scale runs from blue (0) to red (its top). */
static double warmth(const struct shot *s, const double px[3][2])
{
	double sum = 0, rgb[3];

	for (int i = 0; i < 3; i++) {
		patch(s, px[i][0], px[i][1], 2, rgb);
		sum += rgb[0] - rgb[2];
	}
	return sum / 3;
}

static void test_live_view_in_chromium(void **state)
{
	static const int background[3] = { 0xf4, 0xf4, 0xf4 }, force_col[3] = { 0xe0, 0x70, 0 };
	static const int compute_col[3] = { 0x99, 0x99, 0x99 }, enabled_col[3] = { 0, 0x66, 0 };
	struct report r0, r1, r2;
	struct shot before, hold;
	double centre[2], px[3][2], rgb[3], w_before, w_hold, fps;
	int chart[4], st[4], corner[4] = { 5, 5, 20, 20 };
	char url[64], out[256];
	struct cdp *c;
	unsigned port;
	pid_t pid;

	(void)state;
	if (!cdp_browser()) {
		print_message("test_view: SKIPPED the browser test: no chromium (Debian: apt-get "
			      "install chromium; or IRDM_CHROMIUM=PATH)\n");
		skip();
	}
	port = start_fw(&pid, "10");
	snprintf(url, sizeof(url), "http://127.0.0.1:%u/", port);
	c = cdp_open(dir, url, W, H);
	/* before contact: the hand rests 1 cm above the top until 4 s */
	wait_page_time(c, 1.0, &r0);
	assert_string_equal(r0.state, "enabled");
	eval_ok(c, "irdmPause(true), 'paused'", out, sizeof(out));
	report(c, &r0);
	if (r0.t > 3.5)
		fail_msg("the browser came too late: the page first showed t = %.1f s, the hand "
			 "comes down at 4 s",
			 r0.t);
	screenshot(c, &before, "before");
	project(c, 0.05, 0.05, 0.1, centre);
	for (int i = 0; i < 3; i++)
		project(c, ring[i][0], ring[i][1], ring[i][2], px[i]);
	/* the object is drawn: blue (no displacement) at its centre, the
	 * background in the corner */
	patch(&before, centre[0], centre[1], 3, rgb);
	print_message("object centre at (%.0f, %.0f): rgb %.0f %.0f %.0f\n", centre[0], centre[1],
		      rgb[0], rgb[1], rgb[2]);
	assert_true(rgb[2] > rgb[0] + 60 && rgb[2] > 100);
	assert_true(count_colour(&before, corner, background, 6) == corner[2] * corner[3]);
	w_before = warmth(&before, px);
	/* holding: pressed 1 cm from 5.2 s to 8.2 s */
	eval_ok(c, "irdmPause(false), 'resumed'", out, sizeof(out));
	wait_page_time(c, 6.0, &r1);
	eval_ok(c, "irdmPause(true), 'paused'", out, sizeof(out));
	screenshot(c, &hold, "hold");
	w_hold = warmth(&hold, px);
	print_message("around the tool: red - blue %.0f before contact, %.0f holding\n", w_before,
		      w_hold);
	assert_true(w_before < -60);
	assert_true(w_hold > w_before + 100);
	/* the chart's lines and the state, in their colours */
	rect(c, "chart", chart);
	rect(c, "state", st);
	print_message("chart: %d force pixels, %d compute-time pixels; state: %d text pixels\n",
		      count_colour(&hold, chart, force_col, 60), count_colour(&hold, chart, compute_col, 30),
		      count_colour(&hold, st, enabled_col, 60));
	assert_true(count_colour(&hold, chart, force_col, 60) >= 50);
	assert_true(count_colour(&hold, chart, compute_col, 30) >= 50);
	assert_true(count_colour(&hold, st, enabled_col, 60) >= 30);
	eval_ok(c, "document.getElementById('state').textContent", out, sizeof(out));
	assert_string_equal(out, "enabled");
	/* the page's counters while it runs: frames received per second */
	eval_ok(c, "irdmPause(false), 'resumed'", out, sizeof(out));
	report(c, &r1);
	sleep_s(1.5);
	report(c, &r2);
	fps = (r2.frames - r1.frames) / 1.5;
	print_message("page: %d frames/s by its counter, %.1f over 1.5 s; %.1f ms behind the loop\n",
		      r2.fps, fps, r2.latency_ms);
	/* published at 50/s: a live stream, even on a loaded machine */
	assert_true(r2.fps >= 10 && fps >= 10);
	assert_true(r2.latency_ms >= 0 && r2.latency_ms < 2000);
	assert_int_equal(finish_fw(pid), 0);
	assert_non_null(strstr(out_text, "state: off"));
	assert_non_null(strstr(out_text, " 1 pages opened"));
	/* the controller gone, then back on the same port: the page says so,
	 * then reconnects by itself and shows the new run from its start */
	for (double t0 = now_s(); report(c, &r2), r2.connected; sleep_s(0.05))
		if (now_s() - t0 > 10)
			fail_msg("the page did not notice the controller's end");
	eval_ok(c, "document.getElementById('state').textContent", out, sizeof(out));
	assert_string_equal(out, "disconnected: retrying");
	snprintf(out, sizeof(out), "%u", port);
	assert_int_equal(start_fw_at(&pid, "4", NULL, out), port);
	wait_page_time(c, 0.5, &r2);
	assert_true(r2.t < 4.0);
	assert_string_equal(r2.state, "enabled");
	cdp_close(c);
	assert_int_equal(finish_fw(pid), 0);
	free(before.rgb);
	free(hold.rgb);
}

/* ---- raw clients for the bad requests ---- */

static int tcp_connect(unsigned port, int rcvbuf)
{
	struct sockaddr_in a = { .sin_family = AF_INET, .sin_port = htons((uint16_t)port) };
	struct timeval tv = { 5, 0 };
	int fd = socket(AF_INET, SOCK_STREAM, 0);

	assert_true(fd >= 0);
	if (rcvbuf)
		setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
	setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_int_equal(connect(fd, (struct sockaddr *)&a, sizeof(a)), 0);
	return fd;
}

static void send_all(int fd, const void *buf, size_t n)
{
	/* the server may close first: that is an answer too */
	while (n) {
		ssize_t w = send(fd, buf, n, MSG_NOSIGNAL);
		if (w <= 0)
			return;
		buf = (const char *)buf + w;
		n -= (size_t)w;
	}
}

/* Send req (then end the stream when eof); the status of the reply, 0 if
 * the server closed without one. */
static int http_status(unsigned port, const void *req, size_t n, bool eof)
{
	char reply[256] = "";
	int fd = tcp_connect(port, 0), status = 0;
	ssize_t r;

	send_all(fd, req, n);
	if (eof)
		shutdown(fd, SHUT_WR);
	r = recv(fd, reply, sizeof(reply) - 1, 0);
	if (r > 0) {
		reply[r] = '\0';
		if (sscanf(reply, "HTTP/1.%*d %d", &status) != 1)
			status = -1;
	}
	close(fd);
	return status;
}

static int http_get(unsigned port, const char *path)
{
	char req[512];

	snprintf(req, sizeof(req), "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%u\r\n\r\n", path, port);
	return http_status(port, req, strlen(req), false);
}

/* A WebSocket handshake (Origin: origin unless NULL); the socket if the
 * server switched protocols, else -(the reply's status or 1). */
static int ws_open(unsigned port, const char *origin, int rcvbuf)
{
	char req[512], reply[2048];
	int fd = tcp_connect(port, rcvbuf), status = 0;
	size_t n = 0;

	snprintf(req, sizeof(req), "GET / HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nUpgrade: websocket\r\n"
				   "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
				   "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: irdm-view\r\n%s%s%s\r\n",
		 port, origin ? "Origin: " : "", origin ? origin : "", origin ? "\r\n" : "");
	send_all(fd, req, strlen(req));
	/* byte by byte to the blank line: what follows is the first frame */
	while (n < sizeof(reply) - 1 && recv(fd, reply + n, 1, 0) == 1) {
		n++;
		reply[n] = '\0';
		if (n >= 4 && !strcmp(reply + n - 4, "\r\n\r\n"))
			break;
	}
	if (sscanf(reply, "HTTP/1.1 %d", &status) == 1 && status == 101)
		return fd;
	close(fd);
	return -(status ? status : 1);
}

#define WS_CLOSED (-1)
#define WS_TIMEOUT (-2)

/* 0, WS_CLOSED (end of stream, reset) or WS_TIMEOUT (SO_RCVTIMEO). */
static int recv_all(int fd, void *buf, size_t n)
{
	while (n) {
		ssize_t r = recv(fd, buf, n, 0);
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
			return WS_TIMEOUT;
		if (r <= 0)
			return WS_CLOSED;
		buf = (char *)buf + r;
		n -= (size_t)r;
	}
	return 0;
}

/* The next frame from the server: its opcode, or WS_CLOSED / WS_TIMEOUT;
 * the first 8 bytes of its payload (magic, kind) into head. */
static int ws_frame(int fd, uint32_t head[2])
{
	unsigned char h[2], ext[8], skip[4096];
	uint64_t len;
	size_t got = 0;
	int rc;

	if ((rc = recv_all(fd, h, 2)))
		return rc;
	len = h[1] & 0x7f;
	if (len == 126 || len == 127) {
		size_t k = len == 126 ? 2 : 8;
		if ((rc = recv_all(fd, ext, k)))
			return rc;
		len = 0;
		for (size_t i = 0; i < k; i++)
			len = len << 8 | ext[i];
	}
	head[0] = head[1] = 0;
	while (got < len) {
		size_t n = len - got < sizeof(skip) ? (size_t)(len - got) : sizeof(skip);
		if ((rc = recv_all(fd, skip, n)))
			return rc;
		if (!got && n >= 8)
			memcpy(head, skip, 8);
		got += n;
	}
	return h[0] & 0x0f;
}

/* The server hangs up on fd within 5 s (a close frame first is fine);
 * frames still coming or silence are not a hang-up. */
static bool hung_up(int fd)
{
	uint32_t head[2];
	double t0 = now_s();
	int op;

	while ((op = ws_frame(fd, head)) >= 0)
		if (now_s() - t0 > 5)
			return false;
	return op == WS_CLOSED;
}

/* A client frame as a client must send it: FIN, opcode, masked payload. */
static void ws_send(int fd, unsigned char first, const char *payload)
{
	unsigned char f[256];
	size_t n = strlen(payload);

	f[0] = first;
	f[1] = (unsigned char)(0x80 | n);
	memcpy(f + 2, "\x11\x22\x33\x44", 4);
	for (size_t i = 0; i < n; i++)
		f[6 + i] = (unsigned char)payload[i] ^ f[2 + i % 4];
	send_all(fd, f, 6 + n);
}

/* The good client: reads every frame in a thread of its own while the
 * test plays the bad ones, so that it is never the slow one. */
struct reader {
	int fd;
	pthread_t tid;
	atomic_int frames;
	atomic_bool lost, stop;
};

static void *read_frames(void *arg)
{
	struct reader *r = arg;
	uint32_t head[2];

	while (!atomic_load(&r->stop)) {
		if (ws_frame(r->fd, head) != 2) {
			atomic_store(&r->lost, true);
			break;
		}
		if (head[0] == 0x56445249u && head[1] == 2)
			atomic_fetch_add(&r->frames, 1);
	}
	return NULL;
}

static void test_bad_requests_leave_the_controller_alone(void **state)
{
	static const unsigned char unmasked[] = { 0x81, 0x02, 'h', 'i' };
	static const unsigned char rsv[] = { 0xc1, 0x82, 1, 2, 3, 4, 'h' ^ 1, 'i' ^ 2 };
	static const unsigned char huge[] = { 0x82, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff,
					      0xff, 1, 2, 3, 4 };
	char log[320], req[600], err[256];
	struct irdm_log_reader *lr;
	uint32_t head[2], seed = 12345;
	struct reader good = { 0 };
	int mute, fd, extra[VIEW_CLIENTS], n;
	double t0 = now_s();
	uint64_t ticks = 0;
	const char *p;
	unsigned port;
	pid_t pid;

	(void)state;
	snprintf(log, sizeof(log), "%s/bad.log", dir);
	/* long enough for a loaded machine; stopped by SIGTERM once done */
	port = start_fw_log(&pid, "60", log);
	good.fd = ws_open(port, NULL, 0);
	assert_true(good.fd >= 0);
	assert_int_equal(ws_frame(good.fd, head), 2);
	assert_true(head[0] == 0x56445249u && head[1] == 1); /* the hello first */
	assert_int_equal(pthread_create(&good.tid, NULL, read_frames, &good), 0);
	/* unknown paths, other methods, garbage: refused, never served */
	assert_int_equal(http_get(port, "/nope"), 404);
	assert_int_not_equal(http_get(port, "/../../etc/passwd"), 200);
	assert_int_not_equal(http_get(port, "/index.html/../../../etc/passwd"), 200);
	snprintf(req, sizeof(req), "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 3\r\n\r\nabc");
	assert_int_not_equal(http_status(port, req, strlen(req), false), 200);
	snprintf(req, sizeof(req), "GARBAGE\r\n\r\n");
	assert_int_not_equal(http_status(port, req, strlen(req), false), 200);
	for (int k = 0; k < 100; k++) {
		unsigned char junk[512];
		size_t len = 1 + (seed = seed * 1103515245u + 12345u) % sizeof(junk);

		for (size_t i = 0; i < len; i++)
			junk[i] = (unsigned char)((seed = seed * 1103515245u + 12345u) >> 16);
		assert_int_not_equal(http_status(port, junk, len, true), 200);
	}
	/* malformed WebSocket frames, and a client that talks: hung up on */
	fd = ws_open(port, NULL, 0);
	send_all(fd, unmasked, sizeof(unmasked));
	assert_true(hung_up(fd));
	close(fd);
	fd = ws_open(port, NULL, 0);
	send_all(fd, rsv, sizeof(rsv));
	assert_true(hung_up(fd));
	close(fd);
	fd = ws_open(port, NULL, 0);
	send_all(fd, huge, sizeof(huge));
	assert_true(hung_up(fd));
	close(fd);
	fd = ws_open(port, NULL, 0);
	ws_send(fd, 0x81, "enable"); /* the page only watches */
	assert_true(hung_up(fd));
	close(fd);
	/* another site's page: no socket */
	assert_true(ws_open(port, "http://evil.example", 0) < 0);
	/* a client that never reads, and clients up to the limit: the one
	 * past it is turned away */
	mute = ws_open(port, NULL, 4096);
	assert_true(mute >= 0);
	for (n = 0; n < VIEW_CLIENTS - 2; n++)
		extra[n] = ws_open(port, NULL, 0);
	fd = ws_open(port, NULL, 0);
	assert_true(fd < 0 || hung_up(fd));
	if (fd >= 0)
		close(fd);
	for (int i = 0; i < n; i++)
		close(extra[i]);
	/* the good client still gets its frames (50 a second are published) */
	n = atomic_load(&good.frames);
	sleep_s(2.0);
	n = atomic_load(&good.frames) - n;
	print_message("good client: %d frames in 2 s beside a client that never reads\n", n);
	assert_true(n >= 20);
	assert_int_equal(http_get(port, "/"), 200);
	assert_false(atomic_load(&good.lost));
	atomic_store(&good.stop, true);
	pthread_join(good.tid, NULL); /* its next frame, or the run's end, wakes it */
	close(good.fd);
	close(mute);
	/* the controller ran on until told to stop, every tick logged */
	print_message("bad requests: %.1f s\n", now_s() - t0);
	kill(pid, SIGTERM);
	assert_int_equal(finish_fw(pid), 6); /* a signal's documented exit (irdm-fw --help) */
	assert_non_null(strstr(err_text, "(signal 15)"));
	assert_non_null(strstr(err_text, "torque off, state off"));
	p = strstr(out_text, "ticks: ");
	assert_non_null(p);
	ticks = strtoull(p + 7, NULL, 10);
	assert_true(ticks > 1000);
	assert_int_equal(irdm_log_open(&lr, log, err, sizeof(err)), 0);
	assert_int_equal(irdm_log_header(lr)->record_count, ticks);
	assert_int_equal(irdm_log_header(lr)->dropped, 0);
	irdm_log_close(lr);
}

/* One line on stderr naming what is wrong, and the exit code. */
static void expect_error(int rc, int code, const char *needle)
{
	if (rc != code || !strstr(err_text, needle) ||
	    strchr(err_text, '\n') != err_text + strlen(err_text) - 1)
		fail_msg("expected exit %d with one line naming '%s'; got %d: %s", code, needle, rc,
			 err_text);
}

static int run_fw(const char *view)
{
	return finish_fw(rp_spawn(dir, env_or("IRDM_FW", "build/irdm-fw"), (const char *const[]){ "--board", board, "--image", image, "--duration", "0.2", "--view", view, NULL }));
}

static void test_view_arguments(void **state)
{
	struct sockaddr_in a = { .sin_family = AF_INET };
	socklen_t alen = sizeof(a);
	char taken[32];
	int fd;

	(void)state;
	expect_error(run_fw("http"), 2, "--view 'http'");
	expect_error(run_fw("127.0.0.1:65536"), 2, "--view '127.0.0.1:65536'");
	expect_error(run_fw(":80"), 2, "--view ':80'");
	expect_error(run_fw("localhost:0"), 2, "'localhost': not a numeric IPv4 address");
	/* a port someone else listens on */
	fd = socket(AF_INET, SOCK_STREAM, 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof(a)), 0);
	assert_int_equal(listen(fd, 1), 0);
	assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &alen), 0);
	snprintf(taken, sizeof(taken), "%u", ntohs(a.sin_port));
	expect_error(run_fw(taken), 4, "cannot listen on 127.0.0.1:");
	close(fd);
	/* another address than 127.0.0.1: served, with a warning */
	assert_int_equal(run_fw("127.0.0.2:0"), 0);
	assert_non_null(strstr(err_text, "warning: the view listens on 127.0.0.2:"));
	assert_non_null(strstr(out_text, "view: http://127.0.0.2:"));
}

/* irdm view on a log of the slow press, made in virtual time. */
static unsigned start_playback(pid_t *pid, char *log, size_t loglen)
{
	char path[300], text[4096];
	unsigned port = 0;
	double t0 = now_s();

	snprintf(log, loglen, "%s/play.log", dir);
	assert_int_equal(finish_fw(rp_spawn(dir, env_or("IRDM_FW", "build/irdm-fw"),
					    (const char *const[]){ "--board", board, "--image", image, "--user", user,
								   "--clock", "virtual", "--log", log, "-q", NULL })),
			 0);
	*pid = rp_spawn(dir, env_or("IRDM", "build/irdm"), (const char *const[]){ "view", log, "--board", board, "--image", image, "--listen", "0", NULL });
	snprintf(path, sizeof(path), "%s/stdout", dir);
	while (now_s() - t0 < 60) {
		FILE *f = fopen(path, "r");
		const char *p;

		if (f) {
			size_t n = fread(text, 1, sizeof(text) - 1, f);
			text[n] = '\0';
			fclose(f);
			p = strstr(text, "view: http://127.0.0.1:");
			if (p && sscanf(p, "view: http://127.0.0.1:%u/", &port) == 1 && port)
				return port;
		}
		if (waitpid(*pid, NULL, WNOHANG) == *pid)
			fail_msg("irdm view ended before it served");
		sleep_s(0.05);
	}
	fail_msg("irdm view did not serve within 60 s");
	return 0;
}

static void test_playback(void **state)
{
	char log[320], url[96], out[256];
	struct shot before, hold;
	struct report r;
	double px[3][2], w_before, w_hold;
	uint32_t head[2];
	unsigned port;
	int fd, frames = 0;
	struct cdp *c;
	pid_t pid;

	(void)state;
	port = start_playback(&pid, log, sizeof(log));
	/* 10.2 s run at 20 ms a frame: the hello, then the whole recording */
	fd = ws_open(port, NULL, 0);
	assert_true(fd >= 0);
	assert_int_equal(ws_frame(fd, head), 2);
	assert_true(head[0] == 0x56445249u && head[1] == 1);
	while (frames < 510 && ws_frame(fd, head) == 2 && head[1] == 2)
		frames++;
	assert_int_equal(frames, 510);
	close(fd);
	if (!cdp_browser()) {
		print_message("test_view: SKIPPED the playback's browser part: no chromium\n");
		kill(pid, SIGTERM);
		assert_int_equal(finish_fw(pid), 0);
		return;
	}
	snprintf(url, sizeof(url), "http://127.0.0.1:%u/?t=1.0", port);
	c = cdp_open(dir, url, W, H);
	for (double t0 = now_s();; sleep_s(0.1)) {
		char line[512];

		if (cdp_eval(c, "window.irdmReport ? irdmReport() : ''", line, sizeof(line)) &&
		    strstr(line, "loaded=1"))
			break;
		if (now_s() - t0 > 30)
			fail_msg("the page did not load the recording: %s", line);
	}
	report(c, &r);
	assert_int_equal(r.frames, 510);
	sleep_s(0.3);
	screenshot(c, &before, "play-before");
	for (int i = 0; i < 3; i++)
		project(c, ring[i][0], ring[i][1], ring[i][2], px[i]);
	eval_ok(c, "irdmSeek(6.0), document.getElementById('ptime').textContent", out, sizeof(out));
	assert_string_equal(out, "6.000 s");
	sleep_s(0.3);
	screenshot(c, &hold, "play-hold");
	w_before = warmth(&before, px);
	w_hold = warmth(&hold, px);
	print_message("playback, around the tool: red - blue %.0f at 1 s, %.0f at 6 s\n", w_before,
		      w_hold);
	assert_true(w_before < -60);
	assert_true(w_hold > w_before + 100);
	cdp_close(c);
	kill(pid, SIGTERM);
	assert_int_equal(finish_fw(pid), 0);
	assert_non_null(strstr(out_text, "510 frames; replayed forces within 0 N of the log's"));
	free(before.rgb);
	free(hold.rgb);
}

/* irdm view on dir, which it must refuse: its exit code (a serving one is
 * stopped and fails the test). */
static int view_refuses(const char *bad_dir)
{
	pid_t pid = rp_spawn(dir, env_or("IRDM", "build/irdm"), (const char *const[]){ "view", bad_dir, "--listen", "0", NULL });
	double t0 = now_s();

	while (now_s() - t0 < 30) {
		int st;

		if (waitpid(pid, &st, WNOHANG) == pid) {
			char path[300];

			snprintf(path, sizeof(path), "%s/stderr", dir);
			tf_read_text(path, err_text, sizeof(err_text));
			return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
		}
		sleep_s(0.05);
	}
	kill(pid, SIGTERM);
	waitpid(pid, NULL, 0);
	fail_msg("irdm view served %s instead of refusing it", bad_dir);
	return -1;
}

/* irdm view DIR: a directory irdm render wrote, served as it is; one that
 * is not refused, naming the file. */
static void test_render_directory(void **state)
{
	char log[320], rdir[320], path[400], bad_dir[320];
	uint32_t head[2];
	unsigned port = 0;
	int fd, frames = 0;
	pid_t pid;
	double t0 = now_s();

	(void)state;
	snprintf(log, sizeof(log), "%s/play.log", dir);
	snprintf(rdir, sizeof(rdir), "%s/render", dir);
	assert_int_equal(finish_fw(rp_spawn(dir, env_or("IRDM_FW", "build/irdm-fw"),
					    (const char *const[]){ "--board", board, "--image", image, "--user", user,
								   "--clock", "virtual", "--log", log, "-q", NULL })),
			 0);
	assert_int_equal(finish_fw(rp_spawn(dir, env_or("IRDM", "build/irdm"), (const char *const[]){ "render", "--image", image, "--log", log, "--board", board, "-o", rdir, "--every", "0.1", NULL })), 0);
	pid = rp_spawn(dir, env_or("IRDM", "build/irdm"), (const char *const[]){ "view", rdir, "--listen", "0", NULL });
	snprintf(path, sizeof(path), "%s/stdout", dir);
	while (!port && now_s() - t0 < 30) {
		char text[1024] = "";
		FILE *f = fopen(path, "r");
		const char *p;

		if (f) {
			text[fread(text, 1, sizeof(text) - 1, f)] = '\0';
			fclose(f);
		}
		p = strstr(text, "view: http://127.0.0.1:");
		if (!p || sscanf(p, "view: http://127.0.0.1:%u/", &port) != 1)
			sleep_s(0.05);
	}
	assert_true(port > 0);
	/* 10.2 s at 0.1 s a frame */
	fd = ws_open(port, NULL, 0);
	assert_true(fd >= 0);
	assert_int_equal(ws_frame(fd, head), 2);
	assert_true(head[0] == 0x56445249u && head[1] == 1);
	while (frames < 102 && ws_frame(fd, head) == 2 && head[1] == 2)
		frames++;
	assert_int_equal(frames, 102);
	close(fd);
	kill(pid, SIGTERM);
	assert_int_equal(finish_fw(pid), 0);
	assert_non_null(strstr(out_text, "102 frames to 10.200 s"));
	/* not what irdm render writes: a frame outside DIR, a frame missing */
	snprintf(bad_dir, sizeof(bad_dir), "%s/bad-render", dir);
	assert_int_equal(mkdir(bad_dir, 0755), 0);
	snprintf(path, sizeof(path), "%s/frames.pvd", bad_dir);
	tf_write_text(path, "<DataSet timestep=\"0.1\" group=\"\" part=\"0\" file=\"../render/frame_00000.vtu\"/>\n");
	assert_int_equal(view_refuses(bad_dir), 1);
	assert_non_null(strstr(err_text, "frames.pvd: a frame outside DIR"));
	tf_write_text(path, "<DataSet timestep=\"0.1\" group=\"\" part=\"0\" file=\"frame_00000.vtu\"/>\n");
	assert_int_equal(view_refuses(bad_dir), 1);
	assert_non_null(strstr(err_text, "bad-render/frame_00000.vtu: cannot open: No such file"));
	/* a FIFO for a frame or for frames.pvd: refused with the reason, where
	 * opening it to read would wait for a writer that never comes */
	snprintf(path, sizeof(path), "%s/frame_00000.vtu", bad_dir);
	assert_int_equal(mkfifo(path, 0600), 0);
	assert_int_equal(view_refuses(bad_dir), 1);
	assert_non_null(strstr(err_text, "bad-render/frame_00000.vtu: not a regular file (a FIFO)"));
	assert_int_equal(unlink(path), 0);
	snprintf(path, sizeof(path), "%s/fifo-render", dir);
	assert_int_equal(mkdir(path, 0755), 0);
	snprintf(path, sizeof(path), "%s/fifo-render/frames.pvd", dir);
	assert_int_equal(mkfifo(path, 0600), 0);
	snprintf(path, sizeof(path), "%s/fifo-render", dir);
	assert_int_equal(view_refuses(path), 1);
	assert_non_null(strstr(err_text, "fifo-render/frames.pvd: not a regular file (a FIFO)"));
	snprintf(path, sizeof(path), "%s/frame_00000.vtu", bad_dir);
	tf_write_text(path, "<Piece NumberOfPoints=\"3\" NumberOfCells=\"1\">\n");
	assert_int_equal(view_refuses(bad_dir), 1);
	assert_non_null(strstr(err_text, "frame_00000.vtu: no or bad sizes"));
}

static int setup(void **state)
{
	pid_t pid;
	char text[16384], out[16384] = "", *line, *save;

	(void)state;
	if (tf_tmpdir(dir, sizeof(dir), "view"))
		return -1;
	snprintf(image, sizeof(image), "%s/cuboid.img", dir);
	snprintf(user, sizeof(user), "%s/slow.user", dir);
	snprintf(board, sizeof(board), "%s/relaxed.board", dir);
	/* the hand rests 1 cm above the top centre for 4 s (time for the page
	 * to connect), comes down, presses 1 cm and holds 3 s */
	tf_write_text(user, "at 0.0 place 1 at 0.05,0.05,0.21\n"
			    "at 4.0 move 1 to 0.05,0.05,0.20 over 0.5\n"
			    "at 5.0 move 1 to 0.05,0.05,0.19 over 0.2\n"
			    "hold 1 for 3.0\nrelease 1\nhold 1 for 1.0\n");
	/* overruns and the watchdog relaxed: a loaded host (a browser beside
	 * the controller) may overrun, and this test is about the view */
	tf_read_text(BOARD, text, sizeof(text));
	for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		if (!strncmp(line, "overrun_fault_count", 19))
			line = "overrun_fault_count = 1000";
		else if (!strncmp(line, "watchdog_us", 11))
			line = "watchdog_us = 1000000";
		strncat(out, line, sizeof(out) - strlen(out) - 2);
		strcat(out, "\n");
	}
	tf_write_text(board, out);
	/* the paper's cuboid at 4 x 4 x 8 cells, its whole surface displayed */
	pid = rp_spawn(dir, env_or("IRDM", "build/irdm"), (const char *const[]){ "precompute", "-q", "--mesh", "cuboid", "--resolution", "4,4,8", "--fixed", "z<=0", "--touch", "z>=0.2", "--display", "surface", "--representation", "modal:40", "--static_correction", "yes", "--max_error", "none", "-o", image, NULL });
	return finish_fw(pid) == 0 ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	/* IRDM_VIEW_KEEP=1: keep the screenshots and logs to look at */
	if (getenv("IRDM_VIEW_KEEP")) {
		print_message("test_view: kept %s\n", dir);
		return 0;
	}
	return tf_rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_view_arguments),
		cmocka_unit_test(test_bad_requests_leave_the_controller_alone),
		cmocka_unit_test(test_playback),
		cmocka_unit_test(test_render_directory),
		cmocka_unit_test(test_live_view_in_chromium),
	};

	signal(SIGPIPE, SIG_IGN);
	return cmocka_run_group_tests(tests, setup, teardown);
}
