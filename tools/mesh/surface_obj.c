// SPDX-License-Identifier: MIT
/*
 * Wavefront OBJ surface reader: "v x y z" vertices and "f" faces whose
 * corners may be written i, i/t, i//n or i/t/n; indices are 1-based, or
 * negative to count back from the last vertex read so far.  Polygons are
 * fan-triangulated (fine for the convex faces exporters write).  Every
 * other statement (vt, vn, g, o, s, usemtl, ...) is ignored.
 */
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

struct obj {
	struct surface_build b;
	const char *what;
	char *err;
	size_t errlen;
};

static int obj_vertex(struct obj *o, struct mline *l)
{
	double x[3];

	if (mline_double(l, &x[0]) || mline_double(l, &x[1]) ||
	    mline_double(l, &x[2])) {
		mesh_err(o->err, o->errlen, o->what,
			 "line %zu: a vertex needs 3 coordinates", l->lineno);
		return IRDM_EFORMAT;
	}
	if (surface_add_vert(&o->b, x)) {
		mesh_err(o->err, o->errlen, o->what,
			 "line %zu: out of memory or too many vertices", l->lineno);
		return IRDM_ENOMEM;
	}
	return 0;
}

/* One face corner "i[/t[/n]]" to a 0-based vertex index. */
static int obj_corner(struct obj *o, const struct mline *l, const char *tok,
		      size_t n, uint32_t *v)
{
	const char *slash = memchr(tok, '/', n);
	long long i, nv = (long long)o->b.s->n_verts;
	char q[40];

	if (slash)
		n = (size_t)(slash - tok);
	if (mesh_tok_ll(tok, n, &i) || i == 0) {
		mesh_quote(q, sizeof(q), tok, n);
		mesh_err(o->err, o->errlen, o->what,
			 "line %zu: bad vertex reference '%s'", l->lineno, q);
		return IRDM_EFORMAT;
	}
	i = i < 0 ? nv + i : i - 1;
	if (i < 0 || i >= (long long)MESH_MAX_ITEMS) {
		mesh_err(o->err, o->errlen, o->what,
			 "line %zu: vertex reference out of range", l->lineno);
		return IRDM_EFORMAT;
	}
	*v = (uint32_t)i;
	return 0;
}

static int obj_face(struct obj *o, struct mline *l)
{
	uint32_t first = 0, prev = 0, v;
	const char *tok;
	size_t n, k = 0;
	int ret;

	for (; mline_token(l, &tok, &n); k++) {
		ret = obj_corner(o, l, tok, n, &v);
		if (ret)
			return ret;
		if (k == 0)
			first = v;
		if (k >= 2 && surface_add_tri(&o->b, first, prev, v)) {
			mesh_err(o->err, o->errlen, o->what,
				 "line %zu: out of memory or too many triangles",
				 l->lineno);
			return IRDM_ENOMEM;
		}
		prev = v;
	}
	if (k < 3) {
		mesh_err(o->err, o->errlen, o->what,
			 "line %zu: a face needs at least 3 vertices", l->lineno);
		return IRDM_EFORMAT;
	}
	return 0;
}

int irdm_surface_parse_obj(const char *txt, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen)
{
	struct obj o = { { s, 0, 0 }, what, err, errlen };
	struct mtext t;
	struct mline l;
	int ret = 0;

	memset(s, 0, sizeof(*s));
	mtext_init(&t, txt, len, '#');
	while (!ret && mtext_next_line(&t, &l)) {
		const char *tok;
		size_t n;

		mline_token(&l, &tok, &n);
		if (n == 1 && tok[0] == 'v')
			ret = obj_vertex(&o, &l);
		else if (n == 1 && tok[0] == 'f')
			ret = obj_face(&o, &l);
	}
	if (!ret)
		ret = surface_check(s, what, err, errlen);
	if (ret)
		irdm_surface_free(s);
	return ret;
}
