// SPDX-License-Identifier: MIT
/*
 * STL surface reader, ASCII and binary.  STL stores every triangle with
 * its own three corners, so coincident corners are merged (exact
 * equality, +0 and -0 alike) to recover the connectivity tetgen needs.
 *
 * Binary is recognised by its size (84 + 50 * count bytes), because
 * plenty of binary files also begin with the word "solid", or by bytes
 * no text has after the 80-byte header (CAD tools also append bytes after
 * the last triangle); a file that does not start with "solid" is binary,
 * trailing bytes allowed.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

#define STL_HEADER 84
#define STL_RECORD 50

struct corner {
	double x[3];
	uint32_t i; /* position in the unmerged corner list */
};

static int corner_cmp(const void *pa, const void *pb)
{
	const struct corner *a = pa, *b = pb;
	int k;

	for (k = 0; k < 3; k++)
		if (a->x[k] != b->x[k])
			return a->x[k] < b->x[k] ? -1 : 1;
	return a->i < b->i ? -1 : a->i > b->i;
}

/*
 * Turn n corners (three per triangle, in order) into a surface with
 * shared vertices.  Corners must be finite (the callers check), so the
 * comparison above is a total order.
 */
static int merge_corners(struct corner *c, size_t n, struct irdm_surface *s,
			 const char *what, char *err, size_t errlen)
{
	size_t i, nv = 0;

	s->n_tris = n / 3;
	s->tris = malloc((n ? n : 1) * sizeof(*s->tris));
	s->pos_m = malloc((n ? n : 1) * 3 * sizeof(*s->pos_m));
	if (!s->tris || !s->pos_m) {
		mesh_err(err, errlen, what, "out of memory");
		return IRDM_ENOMEM;
	}
	if (n)
		qsort(c, n, sizeof(*c), corner_cmp);
	for (i = 0; i < n; i++) {
		if (!i || memcmp(c[i].x, c[i - 1].x, sizeof(c[i].x))) {
			memcpy(s->pos_m + 3 * nv, c[i].x, sizeof(c[i].x));
			nv++;
		}
		s->tris[c[i].i] = (uint32_t)(nv - 1);
	}
	s->n_verts = nv;
	return 0;
}

/* Store a corner, folding -0 into +0 so that memcmp equality is exact. */
static int set_corner(struct corner *c, size_t i, const double x[3],
		      const char *what, char *err, size_t errlen)
{
	int k;

	for (k = 0; k < 3; k++) {
		if (!isfinite(x[k])) {
			mesh_err(err, errlen, what,
				 "triangle %zu has a non-finite coordinate", i / 3 + 1);
			return IRDM_EFORMAT;
		}
		c[i].x[k] = x[k] + 0.0;
	}
	c[i].i = (uint32_t)i;
	return 0;
}

static uint32_t le32(const unsigned char *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
	       (uint32_t)p[3] << 24;
}

static double le_float(const unsigned char *p)
{
	uint32_t u = le32(p);
	float f;

	memcpy(&f, &u, sizeof(f));
	return f;
}

static int parse_binary(const unsigned char *p, size_t n_tris,
			struct irdm_surface *s, const char *what,
			char *err, size_t errlen)
{
	struct corner *c;
	size_t t, k;
	double x[3];
	int ret;

	c = malloc((n_tris ? 3 * n_tris : 1) * sizeof(*c));
	if (!c) {
		mesh_err(err, errlen, what, "out of memory");
		return IRDM_ENOMEM;
	}
	for (t = 0; t < n_tris; t++) {
		/* 12 bytes of normal, then 3 corners of 12 bytes each */
		const unsigned char *r = p + STL_HEADER + t * STL_RECORD + 12;

		for (k = 0; k < 3; k++) {
			x[0] = le_float(r + 12 * k);
			x[1] = le_float(r + 12 * k + 4);
			x[2] = le_float(r + 12 * k + 8);
			ret = set_corner(c, 3 * t + k, x, what, err, errlen);
			if (ret)
				goto out_free;
		}
	}
	ret = merge_corners(c, 3 * n_tris, s, what, err, errlen);
out_free:
	free(c);
	return ret;
}

struct stl_ascii {
	struct corner *c;
	size_t n, cap;
	size_t in_facet; /* corners seen in the open facet, or 0 */
	bool open;
};

static int ascii_vertex(struct stl_ascii *a, struct mline *l, const char *what,
			char *err, size_t errlen)
{
	struct corner *p;
	double x[3];

	if (!a->open || a->in_facet >= 3) {
		mesh_err(err, errlen, what,
			 "line %zu: vertex outside a facet or a fourth vertex", l->lineno);
		return IRDM_EFORMAT;
	}
	if (mline_double(l, &x[0]) || mline_double(l, &x[1]) ||
	    mline_double(l, &x[2])) {
		mesh_err(err, errlen, what,
			 "line %zu: a vertex needs 3 coordinates", l->lineno);
		return IRDM_EFORMAT;
	}
	if (a->n >= 3 * (size_t)MESH_MAX_ITEMS)
		p = NULL;
	else
		p = mesh_grow(a->c, &a->cap, a->n + 1, sizeof(*p));
	if (!p) {
		mesh_err(err, errlen, what, "out of memory or too many triangles");
		return IRDM_ENOMEM;
	}
	a->c = p;
	a->in_facet++;
	return set_corner(a->c, a->n++, x, what, err, errlen);
}

static int ascii_line(struct stl_ascii *a, struct mline *l, const char *what,
		      char *err, size_t errlen)
{
	const char *tok;
	size_t n;
	char q[40];

	mline_token(l, &tok, &n);
	if (mline_is(l, "vertex"))
		return ascii_vertex(a, l, what, err, errlen);
	if (mline_is(l, "facet") && !a->open) {
		a->open = true;
		a->in_facet = 0;
		return 0;
	}
	if (mline_is(l, "endfacet") && a->open && a->in_facet == 3) {
		a->open = false;
		return 0;
	}
	if (mline_is(l, "outer") || mline_is(l, "endloop") ||
	    mline_is(l, "solid") || mline_is(l, "endsolid"))
		return 0;
	mesh_quote(q, sizeof(q), tok, n);
	mesh_err(err, errlen, what, "line %zu: unexpected '%s'", l->lineno, q);
	return IRDM_EFORMAT;
}

static int parse_ascii(const char *txt, size_t len, struct irdm_surface *s,
		       const char *what, char *err, size_t errlen)
{
	struct stl_ascii a = { NULL, 0, 0, 0, false };
	struct mtext t;
	struct mline l;
	int ret = IRDM_OK;

	mtext_init(&t, txt, len, -1);
	while (!ret && mtext_next_line(&t, &l))
		ret = ascii_line(&a, &l, what, err, errlen);
	if (ret)
		goto out_free;
	if (a.open) {
		mesh_err(err, errlen, what, "truncated inside a facet");
		ret = IRDM_EFORMAT;
		goto out_free;
	}
	ret = merge_corners(a.c, a.n, s, what, err, errlen);
out_free:
	free(a.c);
	return ret;
}

/*
 * Text: no control byte but whitespace (a binary STL's floats have NULs
 * and control bytes; bytes >= 0x80 may be UTF-8 in a solid's name).
 */
static bool all_text(const unsigned char *p, size_t len)
{
	for (size_t i = 0; i < len; i++)
		if ((p[i] < 0x20 && p[i] != '\t' && p[i] != '\r' && p[i] != '\n') ||
		    p[i] == 0x7f)
			return false;
	return true;
}

/*
 * Starts with "solid" AND is text throughout: CAD tools write binary
 * files whose 80-byte header starts with "solid", and some append bytes
 * after the last triangle, so neither the word nor an inexact size tells.
 */
static bool looks_ascii(const char *p, size_t len)
{
	size_t i = 0;

	while (i < len && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' ||
			   p[i] == '\n'))
		i++;
	return len - i >= 5 && !memcmp(p + i, "solid", 5) &&
	       all_text((const unsigned char *)p + STL_HEADER * (len > STL_HEADER),
			len > STL_HEADER ? len - STL_HEADER : 0);
}

int irdm_surface_parse_stl(const void *buf, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen)
{
	const unsigned char *p = buf;
	size_t n = 0;
	bool fits = false, exact = false;
	int ret;

	memset(s, 0, sizeof(*s));
	if (len >= STL_HEADER) {
		n = le32(p + 80);
		fits = n <= MESH_MAX_ITEMS && n <= (len - STL_HEADER) / STL_RECORD;
		exact = fits && n == (len - STL_HEADER) / STL_RECORD &&
			(len - STL_HEADER) % STL_RECORD == 0;
	}
	/* An exact size wins over "solid"; otherwise trailing bytes are allowed,
	 * unless they are whole triangles the count leaves out (a wrong count,
	 * whose dropped triangles would only show as "not closed" later). */
	if (fits && !exact && !looks_ascii(buf, len) && (len - STL_HEADER) % STL_RECORD == 0) {
		mesh_err(err, errlen, what,
			 "binary STL declares %zu triangles at byte 80 but holds %zu whole "
			 "triangle records: the count is wrong",
			 n,
			 (len - STL_HEADER) / STL_RECORD);
		ret = IRDM_EFORMAT;
	} else if (exact || (fits && !looks_ascii(buf, len))) {
		ret = parse_binary(p, n, s, what, err, errlen);
	} else if (looks_ascii(buf, len)) {
		ret = parse_ascii(buf, len, s, what, err, errlen);
	} else if (len >= STL_HEADER) {
		mesh_err(err, errlen, what,
			 "binary STL declares %zu triangles but has only %zu bytes",
			 n, len);
		ret = IRDM_EFORMAT;
	} else {
		mesh_err(err, errlen, what, "not an STL file");
		ret = IRDM_EFORMAT;
	}
	if (!ret)
		ret = surface_check(s, what, err, errlen);
	if (ret)
		irdm_surface_free(s);
	return ret;
}
