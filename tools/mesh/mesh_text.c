// SPDX-License-Identifier: MIT
/*
 * Bounded text scanning for the mesh readers.  Inputs are arbitrary bytes
 * of a given length with no terminating NUL, so nothing here may call a
 * string function on the input itself: numbers are copied into a local,
 * terminated buffer before strtod()/strtoll() see them.
 */
#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/posix/textfile.h"
#include "mesh/mesh_priv.h"

/* Long enough for any sane number ("-1.2345678901234567e-308" is 24). */
#define NUM_BUF 64

void mesh_err(char *err, size_t errlen, const char *what, const char *fmt, ...)
{
	va_list ap;
	size_t used, i;
	int n;

	if (!err || !errlen)
		return;
	n = snprintf(err, errlen, "%s: ", what ? what : "mesh");
	used = n < 0 ? 0 : (size_t)n;
	if (used < errlen) {
		va_start(ap, fmt);
		vsnprintf(err + used, errlen - used, fmt, ap);
		va_end(ap);
	}
	/* The contract is one line, whatever `what` or the input contained. */
	for (i = 0; err[i]; i++)
		if (err[i] == '\n' || err[i] == '\r')
			err[i] = ' ';
}

void mesh_quote(char *dst, size_t dstlen, const char *tok, size_t n)
{
	size_t i;

	if (!dstlen)
		return;
	for (i = 0; i < n && i + 1 < dstlen && i < 32; i++) {
		unsigned char c = (unsigned char)tok[i];

		dst[i] = isprint(c) ? (char)c : '?';
	}
	dst[i] = '\0';
}

void mesh_set_name(struct irdm_mesh *m, const char *what)
{
	const char *base, *dot;
	size_t n;

	if (!what)
		what = "mesh";
	base = strrchr(what, '/');
	base = base ? base + 1 : what;
	dot = strrchr(base, '.');
	n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
	if (n >= sizeof(m->name))
		n = sizeof(m->name) - 1;
	memcpy(m->name, base, n);
	m->name[n] = '\0';
}

void *mesh_grow(void *p, size_t *cap, size_t need, size_t elsize)
{
	size_t ncap;
	void *np;

	if (need <= *cap && p)
		return p;
	if (need > (size_t)MESH_MAX_ITEMS * 4 || !elsize)
		return NULL;
	ncap = *cap ? *cap : 64;
	while (ncap < need)
		ncap *= 2;
	if (ncap > SIZE_MAX / elsize)
		return NULL;
	np = realloc(p, ncap * elsize);
	if (!np)
		return NULL;
	*cap = ncap;
	return np;
}

static bool is_space(char c)
{
	return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

void mtext_init(struct mtext *t, const char *p, size_t len, int comment)
{
	t->p = p;
	t->len = p ? len : 0;
	t->pos = 0;
	t->lineno = 0;
	t->has_comment = comment >= 0;
	t->comment = (char)(comment >= 0 ? comment : 0);
}

/* The raw next line, without its '\n'; false at the end of the text. */
static bool raw_line(struct mtext *t, struct mline *l)
{
	const char *start, *nl;
	size_t n;

	if (t->pos >= t->len)
		return false;
	start = t->p + t->pos;
	nl = memchr(start, '\n', t->len - t->pos);
	n = nl ? (size_t)(nl - start) : t->len - t->pos;
	t->pos += n + (nl ? 1 : 0);
	t->lineno++;
	l->p = start;
	l->len = n;
	l->pos = 0;
	l->lineno = t->lineno;
	return true;
}

bool mtext_next_line(struct mtext *t, struct mline *l)
{
	while (raw_line(t, l)) {
		const char *c = NULL;

		if (t->has_comment)
			c = memchr(l->p, t->comment, l->len);
		if (c)
			l->len = (size_t)(c - l->p);
		while (l->len && is_space(l->p[l->len - 1]))
			l->len--;
		while (l->pos < l->len && is_space(l->p[l->pos]))
			l->pos++;
		if (l->pos < l->len)
			return true;
	}
	return false;
}

bool mline_token(struct mline *l, const char **tok, size_t *n)
{
	size_t s;

	while (l->pos < l->len && is_space(l->p[l->pos]))
		l->pos++;
	if (l->pos >= l->len)
		return false;
	s = l->pos;
	while (l->pos < l->len && !is_space(l->p[l->pos]))
		l->pos++;
	*tok = l->p + s;
	*n = l->pos - s;
	return true;
}

bool mline_is(const struct mline *l, const char *word)
{
	struct mline c = *l;
	const char *tok;
	size_t n;

	c.pos = 0;
	if (!mline_token(&c, &tok, &n))
		return false;
	return n == strlen(word) && !memcmp(tok, word, n);
}

/* Copy a token into buf as a C string; -1 if it does not fit or is empty. */
static int tok_copy(char *buf, size_t buflen, const char *tok, size_t n)
{
	if (!n || n >= buflen || memchr(tok, '\0', n))
		return -1;
	memcpy(buf, tok, n);
	buf[n] = '\0';
	return 0;
}

int mesh_tok_double(const char *tok, size_t n, double *v)
{
	char buf[NUM_BUF];
	char *end;

	if (tok_copy(buf, sizeof(buf), tok, n))
		return -1;
	errno = 0;
	*v = strtod(buf, &end);
	/* Underflow to a tiny value is harmless; only reject junk. */
	if (end != buf + n)
		return -1;
	return 0;
}

int mesh_tok_ll(const char *tok, size_t n, long long *v)
{
	char buf[NUM_BUF];
	char *end;

	if (tok_copy(buf, sizeof(buf), tok, n))
		return -1;
	errno = 0;
	*v = strtoll(buf, &end, 10);
	if (end != buf + n || errno == ERANGE)
		return -1;
	return 0;
}

int mline_double(struct mline *l, double *v)
{
	const char *tok;
	size_t n;

	if (!mline_token(l, &tok, &n))
		return -1;
	return mesh_tok_double(tok, n, v);
}

int mline_ll(struct mline *l, long long *v)
{
	const char *tok;
	size_t n;

	if (!mline_token(l, &tok, &n))
		return -1;
	return mesh_tok_ll(tok, n, v);
}

int mesh_read_file(const char *path, char **buf, size_t *len,
		   char *err, size_t errlen)
{
	size_t cap = 0, n = 0, got;
	char *p = NULL, *np;
	FILE *f;
	int ret;

	*buf = NULL;
	*len = 0;
	ret = irdm_file_fopen(path, MESH_MAX_FILE_BYTES, &f, err, errlen);
	if (ret)
		return ret;
	do {
		if (n == cap) {
			if (cap >= MESH_MAX_FILE_BYTES) {
				mesh_err(err, errlen, path,
					 "file is larger than %zu bytes",
					 (size_t)MESH_MAX_FILE_BYTES);
				ret = IRDM_ERANGE;
				goto fail_free;
			}
			cap = cap ? cap * 2 : 65536;
			np = realloc(p, cap);
			if (!np) {
				mesh_err(err, errlen, path,
					 "out of memory reading the file");
				ret = IRDM_ENOMEM;
				goto fail_free;
			}
			p = np;
		}
		got = fread(p + n, 1, cap - n, f);
		n += got;
	} while (got);
	if (ferror(f)) {
		mesh_err(err, errlen, path, "read failed: %s", strerror(errno));
		ret = IRDM_EIO;
		goto fail_free;
	}
	fclose(f);
	*buf = p;
	*len = n;
	return IRDM_OK;

fail_free:
	free(p);
	fclose(f);
	return ret;
}
