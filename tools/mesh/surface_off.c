// SPDX-License-Identifier: MIT
/*
 * Geomview OFF surface reader: "OFF" (or COFF, NOFF, ...), then
 * "<vertices> <faces> <edges>" (possibly on the OFF line itself), the
 * vertices one per line, then faces "<k> i1 ... ik [colour]" with 0-based
 * indices.  Faces are fan-triangulated; '#' starts a comment.
 */
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

/* Shortest records: "0 0 0" and "3 0 1 2", plus a newline each. */
#define VERT_MIN_BYTES 6
#define FACE_MIN_BYTES 8

/* OFF with optional C (colour), N (normal), ST (texture) prefixes only. */
static int off_keyword(const char *tok, size_t n)
{
	if (n < 3 || memcmp(tok + n - 3, "OFF", 3))
		return -1;
	for (n -= 3; n; n--, tok++)
		if (!memchr("CNST", *tok, 4))
			return -1;
	return 0;
}

static int off_count(struct mline *l, size_t limit, size_t *out)
{
	long long v;

	if (mline_ll(l, &v) || v < 0 || (unsigned long long)v > limit)
		return -1;
	*out = (size_t)v;
	return 0;
}

static int off_header(struct mtext *t, size_t *nv, size_t *nf, const char *what,
		      char *err, size_t errlen)
{
	struct mline l;
	const char *tok;
	size_t n;

	if (!mtext_next_line(t, &l) || !mline_token(&l, &tok, &n) ||
	    off_keyword(tok, n)) {
		mesh_err(err, errlen, what, "not an OFF file (no OFF header)");
		return IRDM_EFORMAT;
	}
	/* The counts may follow on the same line. */
	if (l.pos >= l.len && !mtext_next_line(t, &l)) {
		mesh_err(err, errlen, what, "truncated after the OFF header");
		return IRDM_EFORMAT;
	}
	if (off_count(&l, MESH_MAX_ITEMS, nv) ||
	    off_count(&l, MESH_MAX_ITEMS, nf) ||
	    *nv > t->len / VERT_MIN_BYTES || *nf > t->len / FACE_MIN_BYTES) {
		mesh_err(err, errlen, what,
			 "line %zu: bad or impossible vertex/face counts", l.lineno);
		return IRDM_EFORMAT;
	}
	return 0;
}

static int off_face(struct surface_build *b, struct mline *l, const char *what,
		    char *err, size_t errlen)
{
	uint32_t first = 0, prev = 0;
	long long v;
	size_t k, i;

	if (off_count(l, l->len, &k) || k < 3) {
		mesh_err(err, errlen, what,
			 "line %zu: a face needs a vertex count of at least 3",
			 l->lineno);
		return IRDM_EFORMAT;
	}
	for (i = 0; i < k; i++) {
		if (mline_ll(l, &v) || v < 0 || (unsigned long long)v >= b->s->n_verts) {
			mesh_err(err, errlen, what,
				 "line %zu: bad or out-of-range vertex index", l->lineno);
			return IRDM_EFORMAT;
		}
		if (i == 0)
			first = (uint32_t)v;
		if (i >= 2 && surface_add_tri(b, first, prev, (uint32_t)v)) {
			mesh_err(err, errlen, what, "out of memory or too many triangles");
			return IRDM_ENOMEM;
		}
		prev = (uint32_t)v;
	}
	return 0;
}

static int off_body(struct mtext *t, struct surface_build *b, size_t nv,
		    size_t nf, const char *what, char *err, size_t errlen)
{
	struct mline l;
	double x[3];
	size_t i;
	int ret;

	for (i = 0; i < nv + nf; i++) {
		if (!mtext_next_line(t, &l)) {
			mesh_err(err, errlen, what, "truncated: expected %zu vertices and %zu faces",
				 nv, nf);
			return IRDM_EFORMAT;
		}
		if (i >= nv) {
			ret = off_face(b, &l, what, err, errlen);
			if (ret)
				return ret;
			continue;
		}
		if (mline_double(&l, &x[0]) || mline_double(&l, &x[1]) ||
		    mline_double(&l, &x[2])) {
			mesh_err(err, errlen, what,
				 "line %zu: a vertex needs 3 coordinates", l.lineno);
			return IRDM_EFORMAT;
		}
		if (surface_add_vert(b, x)) {
			mesh_err(err, errlen, what, "out of memory");
			return IRDM_ENOMEM;
		}
	}
	return 0;
}

int irdm_surface_parse_off(const char *txt, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen)
{
	struct surface_build b = { s, 0, 0 };
	struct mtext t;
	size_t nv, nf;
	int ret;

	memset(s, 0, sizeof(*s));
	mtext_init(&t, txt, len, '#');
	ret = off_header(&t, &nv, &nf, what, err, errlen);
	if (!ret)
		ret = off_body(&t, &b, nv, nf, what, err, errlen);
	if (!ret)
		ret = surface_check(s, what, err, errlen);
	if (ret) {
		irdm_surface_free(s);
		return ret;
	}
	return IRDM_OK;
}
