/* SPDX-License-Identifier: MIT */
/*
 * The view's server: HTTP for one page (built into the program) and
 * three.js (Debian's libjs-three, read from disk at open), and a WebSocket
 * that carries the view's messages (docs/view.md) to every page.  Built on
 * libwebsockets: one event loop, non-blocking sockets, so a client that
 * never reads costs one buffered message and never blocks the others.
 *
 * One thread runs everything (view_server_run()): the socket service and,
 * at the configured rate, the caller's tick, which may publish.  Watch
 * only: nothing a client sends is acted on; a client that sends anything is
 * disconnected.
 *
 * Messages: the hello (the mesh) goes first to each new client; after it,
 * the newest frame.  A frame published while a client still writes the
 * previous one replaces it: frames are dropped, never queued.  Playback
 * adds frames to a recording that each client receives whole (after the
 * hello), then the page plays it by itself.
 */
#ifndef IRDM_TOOLS_VIEW_SERVER_H
#define IRDM_TOOLS_VIEW_SERVER_H

#include <stddef.h>
#include <stdint.h>

#define VIEW_DEFAULT_ADDR "127.0.0.1"
#define VIEW_THREE_JS "/usr/share/javascript/three/build/three.min.js"
#define VIEW_MAX_CLIENTS 8

struct view_server;

struct view_server_config {
	const char *addr;                               /* numeric IPv4 address to bind; NULL: 127.0.0.1 */
	unsigned port;                                  /* 0: any free port (view_server_port() says which) */
	const char *three_js;                           /* NULL: VIEW_THREE_JS */
	size_t max_frame;                               /* bytes of the largest frame view_server_publish() takes */
	double rate_hz;                                 /* tick's rate, > 0 */
	void (*tick)(void *ctx, struct view_server *s); /* in the server's thread */
	void *ctx;
};

struct view_server_stats {
	uint64_t http_ok, http_refused; /* pages and files served; 404/405 */
	uint64_t ws_opened, ws_refused; /* sockets accepted; over the limit */
	uint64_t ws_kicked;             /* clients disconnected: they sent data */
	uint64_t frames_published, frames_sent;
	uint64_t frames_skipped; /* a client was still busy: it got a newer one */
	unsigned clients;        /* open WebSockets now */
};

/* "[ADDR:]PORT" (ADDR default VIEW_DEFAULT_ADDR, PORT 0..65535, 0: any):
 * IRDM_OK or IRDM_EINVAL. */
int view_parse_listen(const char *spec, char *addr, size_t addrlen, unsigned *port);

/*
 * Bind and listen; nothing runs until view_server_run().
 * Return: IRDM_OK; IRDM_EINVAL (bad address, port, rate or size);
 * IRDM_EIO (three.js unreadable, the address cannot be bound);
 * IRDM_ENOMEM.  On error *s is NULL and err says why.
 */
int view_server_open(struct view_server **s, const struct view_server_config *c, char *err,
		     size_t errlen);
unsigned view_server_port(const struct view_server *s);

/* The hello each client gets first (copied; replaces the previous one,
 * and clients connected before get it again). */
int view_server_set_hello(struct view_server *s, const void *msg, size_t len);
/* The newest frame (copied; len <= max_frame, else ignored).  Server thread. */
void view_server_publish(struct view_server *s, const void *msg, size_t len);
/* Playback: one more message of the recording (copied). */
int view_server_record(struct view_server *s, const void *msg, size_t len);

/* Serve until view_server_stop() (from any thread or the tick). */
int view_server_run(struct view_server *s);
void view_server_stop(struct view_server *s);
/* Server thread, or after view_server_run() returned. */
void view_server_stats(const struct view_server *s, struct view_server_stats *st);
void view_server_close(struct view_server *s);

/* The page's files, built in (view_page.c, generated from tools/view/page/). */
struct view_page_file {
	const char *path, *mime;
	const unsigned char *data;
	size_t len;
};
extern const struct view_page_file view_page_files[];
extern const size_t view_page_n_files;

#endif
