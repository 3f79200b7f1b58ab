/* SPDX-License-Identifier: MIT */
/*
 * The view's HTTP + WebSocket server on libwebsockets (view_server.h).
 * Everything happens in the thread that calls view_server_run(): the
 * callbacks, the caller's tick and the buffers, so nothing here is locked.
 * Only view_server_stop() crosses threads (an atomic flag and
 * lws_cancel_service(), which lws documents as callable from any thread).
 */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <libwebsockets.h>

#include "irdm/error.h"
#include "view/view_server.h"

#define HTTP_CHUNK 16384u
#define HELLO_MAX (256u << 20) /* a mesh of millions of nodes: refuse beyond */
#define RECORD_MAX 100000u     /* messages in a recording */

struct msg {
	unsigned char *buf; /* LWS_PRE bytes of room, then the message */
	size_t len;
};

struct view_server {
	struct lws_context *ctx;
	struct lws_protocols protocols[2];
	lws_sorted_usec_list_t sul;
	struct view_server_config cfg;
	lws_usec_t period_us;
	struct view_page_file three;
	unsigned char *three_data;
	struct msg hello, frame;
	uint64_t hello_gen, frame_seq;
	struct msg *rec;
	size_t n_rec, cap_rec;
	unsigned char chunk[LWS_PRE + HTTP_CHUNK];
	unsigned port;
	atomic_bool stop;
	struct view_server_stats st;
};

/* One connection: an HTTP transfer or a page's WebSocket. */
struct conn {
	const struct view_page_file *file;
	size_t sent;
	bool ws;
	uint64_t hello_gen, frame_seq;
	size_t rec_sent;
};

static struct view_server *server_of(struct lws *wsi)
{
	return lws_context_user(lws_get_context(wsi));
}

static const struct view_page_file *find_file(const struct view_server *s, const char *path)
{
	if (!strcmp(path, "/three.min.js"))
		return &s->three;
	if (!strcmp(path, "/"))
		path = "/index.html";
	for (size_t i = 0; i < view_page_n_files; i++)
		if (!strcmp(path, view_page_files[i].path))
			return &view_page_files[i];
	return NULL;
}

/* A page may open the socket; another site's page in the same browser may
 * not (its Origin names another host). */
static bool same_origin(struct lws *wsi)
{
	char origin[256], host[256], want[300];

	if (lws_hdr_copy(wsi, origin, sizeof(origin), WSI_TOKEN_ORIGIN) <= 0)
		return true; /* not a browser: nothing to protect from */
	if (lws_hdr_copy(wsi, host, sizeof(host), WSI_TOKEN_HOST) <= 0)
		return false;
	snprintf(want, sizeof(want), "http://%s", host);
	return !strcmp(origin, want);
}

static int refuse_http(struct view_server *s, struct lws *wsi, unsigned code)
{
	s->st.http_refused++;
	if (lws_return_http_status(wsi, code, NULL))
		return -1;
	return lws_http_transaction_completed(wsi) ? -1 : 0;
}

static int http_start(struct view_server *s, struct lws *wsi, struct conn *c, const char *path)
{
	unsigned char hdr[LWS_PRE + 1024], *start = hdr + LWS_PRE, *p = start;
	unsigned char *end = hdr + sizeof(hdr) - 1;
	static const char csp[] = "default-src 'self'; connect-src 'self'; "
				  "style-src 'self' 'unsafe-inline'";

	if (lws_hdr_total_length(wsi, WSI_TOKEN_GET_URI) <= 0)
		return refuse_http(s, wsi, HTTP_STATUS_METHOD_NOT_ALLOWED);
	c->file = find_file(s, path);
	if (!c->file)
		return refuse_http(s, wsi, HTTP_STATUS_NOT_FOUND);
	c->sent = 0;
	if (lws_add_http_common_headers(wsi, HTTP_STATUS_OK, c->file->mime, c->file->len, &p, end) ||
	    lws_add_http_header_by_name(wsi, (const unsigned char *)"cache-control:",
					(const unsigned char *)"no-store", 8, &p, end) ||
	    lws_add_http_header_by_name(wsi, (const unsigned char *)"x-content-type-options:",
					(const unsigned char *)"nosniff", 7, &p, end) ||
	    lws_add_http_header_by_name(wsi, (const unsigned char *)"content-security-policy:",
					(const unsigned char *)csp, (int)strlen(csp), &p, end) ||
	    lws_finalize_write_http_header(wsi, start, &p, end))
		return -1;
	s->st.http_ok++;
	lws_callback_on_writable(wsi);
	return 0;
}

static int http_more(struct view_server *s, struct lws *wsi, struct conn *c)
{
	size_t n;
	bool last;

	if (!c->file)
		return 0;
	n = c->file->len - c->sent;
	if (n > HTTP_CHUNK)
		n = HTTP_CHUNK;
	last = c->sent + n == c->file->len;
	memcpy(s->chunk + LWS_PRE, c->file->data + c->sent, n);
	if (lws_write(wsi, s->chunk + LWS_PRE, n, last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP) <
	    (int)n)
		return -1;
	c->sent += n;
	if (!last) {
		lws_callback_on_writable(wsi);
		return 0;
	}
	c->file = NULL;
	return lws_http_transaction_completed(wsi) ? -1 : 0;
}

static int send_msg(struct lws *wsi, const struct msg *m)
{
	return lws_write(wsi, m->buf + LWS_PRE, m->len, LWS_WRITE_BINARY) < (int)m->len ? -1 : 0;
}

/* The hello, then the recording, then the newest frame: one message a call. */
static int ws_more(struct view_server *s, struct lws *wsi, struct conn *c)
{
	if (!s->hello.len)
		return 0;
	if (c->hello_gen != s->hello_gen) {
		c->hello_gen = s->hello_gen;
		c->rec_sent = 0;
		c->frame_seq = s->frame_seq; /* an older frame may not fit the new mesh */
		if (send_msg(wsi, &s->hello))
			return -1;
	} else if (c->rec_sent < s->n_rec) {
		if (send_msg(wsi, &s->rec[c->rec_sent++]))
			return -1;
	} else if (c->frame_seq != s->frame_seq && s->frame.len) {
		if (c->frame_seq && s->frame_seq - c->frame_seq > 1)
			s->st.frames_skipped += s->frame_seq - c->frame_seq - 1;
		c->frame_seq = s->frame_seq;
		if (send_msg(wsi, &s->frame))
			return -1;
		s->st.frames_sent++;
		return 0;
	} else {
		return 0;
	}
	lws_callback_on_writable(wsi);
	return 0;
}

static int ws_open(struct view_server *s, struct lws *wsi, struct conn *c)
{
	memset(c, 0, sizeof(*c));
	if (s->st.clients >= VIEW_MAX_CLIENTS) {
		s->st.ws_refused++;
		return -1;
	}
	c->ws = true;
	s->st.clients++;
	s->st.ws_opened++;
	lws_callback_on_writable(wsi);
	return 0;
}

static int on_event(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
		    size_t len)
{
	struct view_server *s = server_of(wsi);
	struct conn *c = user;

	switch (reason) {
	case LWS_CALLBACK_HTTP:
		return http_start(s, wsi, c, in);
	case LWS_CALLBACK_HTTP_BODY:
		return -1; /* a GET has no body */
	case LWS_CALLBACK_HTTP_WRITEABLE:
		return http_more(s, wsi, c);
	case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
		if (same_origin(wsi))
			return 0;
		s->st.ws_refused++;
		return 1;
	case LWS_CALLBACK_ESTABLISHED:
		return ws_open(s, wsi, c);
	case LWS_CALLBACK_CLOSED:
		if (c->ws) {
			c->ws = false;
			s->st.clients--;
		}
		return 0;
	case LWS_CALLBACK_RECEIVE:
		/* the page only watches: whoever talks is not the page */
		s->st.ws_kicked++;
		lws_close_reason(wsi, LWS_CLOSE_STATUS_POLICY_VIOLATION,
				 (unsigned char *)"watch only", 10);
		return -1;
	case LWS_CALLBACK_SERVER_WRITEABLE:
		return ws_more(s, wsi, c);
	default:
		break;
	}
	(void)len;
	return lws_callback_http_dummy(wsi, reason, user, in, len);
}

static void on_tick(lws_sorted_usec_list_t *sul)
{
	struct view_server *s = lws_container_of(sul, struct view_server, sul);

	s->cfg.tick(s->cfg.ctx, s);
	lws_sul_schedule(s->ctx, 0, &s->sul, on_tick, s->period_us);
}

static int read_three(struct view_server *s, const char *path, char *err, size_t errlen)
{
	FILE *f = fopen(path, "rb");
	long n;

	if (!f)
		goto io;
	if (fseek(f, 0, SEEK_END) || (n = ftell(f)) <= 0 || fseek(f, 0, SEEK_SET))
		goto io_close;
	s->three_data = malloc((size_t)n);
	if (!s->three_data || fread(s->three_data, 1, (size_t)n, f) != (size_t)n)
		goto io_close;
	fclose(f);
	s->three = (struct view_page_file){ "/three.min.js", "application/javascript",
					    s->three_data, (size_t)n };
	return IRDM_OK;
io_close:
	fclose(f);
io:
	snprintf(err, errlen, "%s: %s (Debian: apt-get install libjs-three)", path,
		 errno ? strerror(errno) : "cannot read");
	return IRDM_EIO;
}

int view_parse_listen(const char *spec, char *addr, size_t addrlen, unsigned *port)
{
	const char *colon = strrchr(spec, ':'), *p = colon ? colon + 1 : spec;
	char *end;
	unsigned long v;

	if (!*p || *p < '0' || *p > '9' || colon == spec)
		return IRDM_EINVAL;
	v = strtoul(p, &end, 10);
	if (*end || v > 65535 || (colon && (size_t)(colon - spec) >= addrlen))
		return IRDM_EINVAL;
	snprintf(addr, addrlen, "%.*s", colon ? (int)(colon - spec) : (int)strlen(VIEW_DEFAULT_ADDR),
		 colon ? spec : VIEW_DEFAULT_ADDR);
	*port = (unsigned)v;
	return IRDM_OK;
}

static int check_config(const struct view_server_config *c, char *err, size_t errlen)
{
	struct in_addr a;
	const char *addr = c->addr ? c->addr : VIEW_DEFAULT_ADDR;

	if (inet_pton(AF_INET, addr, &a) != 1) {
		snprintf(err, errlen, "view address '%s': not a numeric IPv4 address", addr);
		return IRDM_EINVAL;
	}
	if (c->port > 65535) {
		snprintf(err, errlen, "view port %u: over 65535", c->port);
		return IRDM_EINVAL;
	}
	if (!(c->rate_hz > 0 && c->rate_hz <= 1000) || !c->tick || !c->max_frame) {
		snprintf(err, errlen, "view: rate %g Hz not in (0, 1000], or no tick or frame size",
			 c->rate_hz);
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

/*
 * Whether addr:port can be bound, asked of the kernel before libwebsockets
 * is: its context, refused the address, leaves an allocation behind.
 */
static int probe(const char *addr, unsigned port, char *err, size_t errlen)
{
	struct sockaddr_in a = { .sin_family = AF_INET, .sin_port = htons((uint16_t)port) };
	int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1, e = 0;

	if (fd < 0 || inet_pton(AF_INET, addr, &a.sin_addr) != 1)
		e = fd < 0 ? errno : EINVAL;
	else if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) ||
		 bind(fd, (struct sockaddr *)&a, sizeof(a)))
		e = errno;
	if (fd >= 0)
		close(fd);
	if (!e)
		return IRDM_OK;
	snprintf(err, errlen, "view: cannot listen on %s:%u: %s", addr, port, strerror(e));
	return IRDM_EIO;
}

static int make_context(struct view_server *s, char *err, size_t errlen)
{
	struct lws_context_creation_info info;
	struct lws_vhost *vh;

	memset(&info, 0, sizeof(info));
	s->protocols[0] = (struct lws_protocols){ "irdm-view", on_event, sizeof(struct conn), 4096,
						  0, NULL, 0 };
	info.port = (int)s->cfg.port;
	info.iface = s->cfg.addr ? s->cfg.addr : VIEW_DEFAULT_ADDR;
	if (probe(info.iface, s->cfg.port, err, errlen))
		return IRDM_EIO;
	info.protocols = s->protocols;
	info.user = s;
	info.options = LWS_SERVER_OPTION_DISABLE_IPV6 | LWS_SERVER_OPTION_VALIDATE_UTF8;
	info.timeout_secs = 10;
	info.max_http_header_pool = 16;
	/* its messages are not one line; ours say what failed */
	lws_set_log_level(0, NULL);
	s->ctx = lws_create_context(&info);
	vh = s->ctx ? lws_get_vhost_by_name(s->ctx, "default") : NULL;
	if (!vh || lws_get_vhost_listen_port(vh) <= 0) {
		snprintf(err, errlen, "view: cannot listen on %s:%u (in use, or not this host's)",
			 info.iface, s->cfg.port);
		return IRDM_EIO;
	}
	s->port = (unsigned)lws_get_vhost_listen_port(vh);
	return IRDM_OK;
}

static int alloc_msg(struct msg *m, size_t len)
{
	m->buf = malloc(LWS_PRE + (len ? len : 1));
	m->len = 0;
	return m->buf ? IRDM_OK : IRDM_ENOMEM;
}

int view_server_open(struct view_server **sp, const struct view_server_config *c, char *err,
		     size_t errlen)
{
	struct view_server *s;
	int rc;

	*sp = NULL;
	rc = check_config(c, err, errlen);
	if (rc)
		return rc;
	s = calloc(1, sizeof(*s));
	if (!s || alloc_msg(&s->frame, c->max_frame)) {
		snprintf(err, errlen, "view: out of memory");
		rc = IRDM_ENOMEM;
		goto fail;
	}
	s->cfg = *c;
	s->period_us = (lws_usec_t)(1e6 / c->rate_hz);
	rc = read_three(s, c->three_js ? c->three_js : VIEW_THREE_JS, err, errlen);
	if (!rc)
		rc = make_context(s, err, errlen);
	if (rc)
		goto fail;
	lws_sul_schedule(s->ctx, 0, &s->sul, on_tick, s->period_us);
	*sp = s;
	return IRDM_OK;
fail:
	view_server_close(s);
	return rc;
}

unsigned view_server_port(const struct view_server *s)
{
	return s->port;
}

int view_server_set_hello(struct view_server *s, const void *msg, size_t len)
{
	struct msg m;

	if (!len || len > HELLO_MAX || alloc_msg(&m, len))
		return len ? IRDM_ENOMEM : IRDM_EINVAL;
	memcpy(m.buf + LWS_PRE, msg, len);
	m.len = len;
	free(s->hello.buf);
	s->hello = m;
	s->hello_gen++;
	if (s->ctx)
		lws_callback_on_writable_all_protocol(s->ctx, &s->protocols[0]);
	return IRDM_OK;
}

void view_server_publish(struct view_server *s, const void *msg, size_t len)
{
	if (len > s->cfg.max_frame)
		return;
	memcpy(s->frame.buf + LWS_PRE, msg, len);
	s->frame.len = len;
	s->frame_seq++;
	s->st.frames_published++;
	lws_callback_on_writable_all_protocol(s->ctx, &s->protocols[0]);
}

int view_server_record(struct view_server *s, const void *msg, size_t len)
{
	if (s->n_rec == s->cap_rec) {
		size_t cap = s->cap_rec ? 2 * s->cap_rec : 256;
		struct msg *r;

		if (cap > RECORD_MAX)
			return IRDM_ENOMEM;
		r = realloc(s->rec, cap * sizeof(*r));
		if (!r)
			return IRDM_ENOMEM;
		s->rec = r;
		s->cap_rec = cap;
	}
	if (alloc_msg(&s->rec[s->n_rec], len))
		return IRDM_ENOMEM;
	memcpy(s->rec[s->n_rec].buf + LWS_PRE, msg, len);
	s->rec[s->n_rec++].len = len;
	return IRDM_OK;
}

int view_server_run(struct view_server *s)
{
	while (!atomic_load(&s->stop))
		if (lws_service(s->ctx, 0) < 0)
			return IRDM_EIO;
	return IRDM_OK;
}

void view_server_stop(struct view_server *s)
{
	atomic_store(&s->stop, true);
	lws_cancel_service(s->ctx);
}

void view_server_stats(const struct view_server *s, struct view_server_stats *st)
{
	*st = s->st;
}

void view_server_close(struct view_server *s)
{
	if (!s)
		return;
	if (s->ctx)
		lws_context_destroy(s->ctx);
	for (size_t i = 0; i < s->n_rec; i++)
		free(s->rec[i].buf);
	free(s->rec);
	free(s->hello.buf);
	free(s->frame.buf);
	free(s->three_data);
	free(s);
}
