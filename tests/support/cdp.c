/* SPDX-License-Identifier: MIT */
#include "cdp.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

extern char **environ;

#define REPLY_TIMEOUT_MS 30000

struct cdp {
	pid_t pid;
	int to, from; /* our ends: commands, replies */
	int next_id;
	char session[128];
	char *buf; /* bytes read, not yet a whole message */
	size_t len, cap;
};

const char *cdp_browser(void)
{
	const char *b = getenv("IRDM_CHROMIUM");

	if (!b)
		b = "/usr/bin/chromium";
	return access(b, X_OK) ? NULL : b;
}

static void send_msg(struct cdp *c, const char *msg)
{
	size_t n = strlen(msg) + 1, off = 0;

	while (off < n) {
		ssize_t w = write(c->to, msg + off, n - off);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			fail_msg("chromium: the command pipe closed");
		off += (size_t)w;
	}
}

/* The next whole message (NUL-terminated, malloc'd). */
static char *read_msg(struct cdp *c)
{
	for (;;) {
		char *nul = c->len ? memchr(c->buf, '\0', c->len) : NULL;
		struct pollfd p = { c->from, POLLIN, 0 };
		ssize_t r;

		if (nul) {
			size_t n = (size_t)(nul - c->buf) + 1;
			char *m = malloc(n);
			assert_non_null(m);
			memcpy(m, c->buf, n);
			memmove(c->buf, c->buf + n, c->len - n);
			c->len -= n;
			return m;
		}
		if (c->cap - c->len < 65536) {
			c->cap = c->cap ? 2 * c->cap : 1 << 20;
			c->buf = realloc(c->buf, c->cap);
			assert_non_null(c->buf);
		}
		if (poll(&p, 1, REPLY_TIMEOUT_MS) != 1)
			fail_msg("chromium: no reply in %d ms", REPLY_TIMEOUT_MS);
		r = read(c->from, c->buf + c->len, c->cap - c->len);
		if (r < 0 && errno == EINTR)
			continue;
		if (r <= 0)
			fail_msg("chromium: the reply pipe closed (see chromium.log)");
		c->len += (size_t)r;
	}
}

/* Send method(params) (in the page's session when there is one) and
 * return its reply (malloc'd); events in between are dropped. */
static char *call(struct cdp *c, const char *method, const char *params)
{
	size_t n = strlen(method) + strlen(params) + 256;
	char *msg = malloc(n), key[32];
	int id = ++c->next_id;

	assert_non_null(msg);
	if (c->session[0])
		snprintf(msg, n, "{\"id\":%d,\"sessionId\":\"%s\",\"method\":\"%s\",\"params\":%s}", id,
			 c->session, method, params);
	else
		snprintf(msg, n, "{\"id\":%d,\"method\":\"%s\",\"params\":%s}", id, method, params);
	send_msg(c, msg);
	free(msg);
	snprintf(key, sizeof(key), "{\"id\":%d,", id);
	for (;;) {
		char *m = read_msg(c);
		if (!strncmp(m, key, strlen(key)))
			return m;
		free(m);
	}
}

/* The string value of "key":"..." in m (no escapes inside), or NULL. */
static char *string_of(const char *m, const char *key, char *out, size_t outlen)
{
	char pat[64];
	const char *p, *e;

	snprintf(pat, sizeof(pat), "\"%s\":\"", key);
	p = strstr(m, pat);
	if (!p)
		return NULL;
	p += strlen(pat);
	e = strchr(p, '"');
	if (!e || (size_t)(e - p) >= outlen)
		return NULL;
	memcpy(out, p, (size_t)(e - p));
	out[e - p] = '\0';
	return out;
}

struct cdp *cdp_open(const char *dir, const char *url, int w, int h)
{
	struct cdp *c = calloc(1, sizeof(*c));
	int to[2], from[2];
	char log[300], size[64], prof[300], params[1024], target[128], *m;
	const char *argv[16];
	posix_spawn_file_actions_t fa;
	int n = 0;

	assert_non_null(c);
	assert_int_equal(pipe(to), 0);
	assert_int_equal(pipe(from), 0);
	/* our ends stay ours: the browser must see EOF when we close them */
	fcntl(to[1], F_SETFD, FD_CLOEXEC);
	fcntl(from[0], F_SETFD, FD_CLOEXEC);
	snprintf(log, sizeof(log), "%s/chromium.log", dir);
	snprintf(size, sizeof(size), "--window-size=%d,%d", w, h);
	snprintf(prof, sizeof(prof), "--user-data-dir=%s/chromium-profile", dir);
	argv[n++] = cdp_browser();
	argv[n++] = "--headless";
	argv[n++] = "--no-sandbox"; /* tests run as root in CI */
	argv[n++] = "--remote-debugging-pipe";
	argv[n++] = "--force-device-scale-factor=1";
	argv[n++] = "--hide-scrollbars";
	argv[n++] = "--no-first-run";
	argv[n++] = size;
	argv[n++] = prof;
	argv[n++] = "about:blank";
	argv[n] = NULL;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_adddup2(&fa, to[0], 3);
	posix_spawn_file_actions_adddup2(&fa, from[1], 4);
	posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	posix_spawn_file_actions_adddup2(&fa, 1, 2);
	assert_int_equal(posix_spawn(&c->pid, argv[0], &fa, NULL, (char *const *)argv, environ), 0);
	posix_spawn_file_actions_destroy(&fa);
	close(to[0]);
	close(from[1]);
	c->to = to[1];
	c->from = from[0];
	snprintf(params, sizeof(params), "{\"url\":\"%s\"}", url);
	m = call(c, "Target.createTarget", params);
	if (!string_of(m, "targetId", target, sizeof(target)))
		fail_msg("chromium: no target: %.300s", m);
	free(m);
	snprintf(params, sizeof(params), "{\"targetId\":\"%s\",\"flatten\":true}", target);
	m = call(c, "Target.attachToTarget", params);
	if (!string_of(m, "sessionId", c->session, sizeof(c->session)))
		fail_msg("chromium: cannot attach: %.300s", m);
	free(m);
	return c;
}

bool cdp_eval(struct cdp *c, const char *expr, char *out, size_t outlen)
{
	size_t n = 2 * strlen(expr) + 64, k = 0;
	char *params = malloc(n), *m;
	bool ok;

	assert_non_null(params);
	k = (size_t)snprintf(params, n, "{\"returnByValue\":true,\"expression\":\"");
	for (const char *p = expr; *p; p++) {
		if (*p == '"' || *p == '\\')
			params[k++] = '\\';
		params[k++] = *p;
	}
	snprintf(params + k, n - k, "\"}");
	m = call(c, "Runtime.evaluate", params);
	free(params);
	ok = !strstr(m, "\"exceptionDetails\"") && string_of(m, "value", out, outlen);
	if (!ok && outlen)
		snprintf(out, outlen, "%.200s", m);
	free(m);
	return ok;
}

static int b64(int ch)
{
	if (ch >= 'A' && ch <= 'Z')
		return ch - 'A';
	if (ch >= 'a' && ch <= 'z')
		return ch - 'a' + 26;
	if (ch >= '0' && ch <= '9')
		return ch - '0' + 52;
	return ch == '+' ? 62 : ch == '/' ? 63 :
					    -1;
}

unsigned char *cdp_screenshot(struct cdp *c, size_t *len)
{
	char *m = call(c, "Page.captureScreenshot", "{\"format\":\"png\"}");
	const char *p = strstr(m, "\"data\":\"");
	unsigned char *out;
	uint32_t acc = 0;
	int bits = 0;

	if (!p)
		fail_msg("chromium: no screenshot: %.300s", m);
	p += 8;
	out = malloc(strlen(p));
	assert_non_null(out);
	*len = 0;
	for (; *p && *p != '"'; p++) {
		int v = b64(*p);
		if (v < 0)
			continue; /* '=' padding */
		acc = acc << 6 | (uint32_t)v;
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			out[(*len)++] = (unsigned char)(acc >> bits);
		}
	}
	free(m);
	return out;
}

void cdp_close(struct cdp *c)
{
	struct timespec t = { 0, 50000000 };
	int status;

	if (!c)
		return;
	c->session[0] = '\0';
	send_msg(c, "{\"id\":999999,\"method\":\"Browser.close\",\"params\":{}}");
	close(c->to);
	for (int i = 0; i < 100 && waitpid(c->pid, &status, WNOHANG) == 0; i++)
		nanosleep(&t, NULL);
	if (waitpid(c->pid, &status, WNOHANG) == 0) {
		kill(c->pid, SIGKILL);
		waitpid(c->pid, &status, 0);
	}
	close(c->from);
	free(c->buf);
	free(c);
}
