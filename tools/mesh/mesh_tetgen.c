// SPDX-License-Identifier: MIT
/*
 * TetGen .node/.ele reader.
 *
 * .node: "<n> <dim> <attrs> <bmarker>", then "<index> <x> <y> <z> [attrs]
 * [marker]".  .ele: "<n> <nodes per tet> <attrs>", then "<index> <n1> ...".
 * '#' starts a comment.  The first node index (0 or 1) sets the base that
 * element node references use; 10-node tets keep their 4 corners.
 *
 * Orientation: Debian's tetgen 1.5 writes every tet with
 * (n2-n1)x(n3-n1).(n4-n1) > 0 (checked on its output), which is our
 * convention, so nodes are taken in file order.  A tet that is inverted
 * in the file is therefore a real defect and irdm_mesh_finish() reports it.
 */
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

/* Shortest possible records, "1 0 0 0" and "1 1 2 3 4": bounds headers. */
#define NODE_MIN_BYTES 7
#define ELE_MIN_BYTES 9

#define ATTRS_MAX 1000 /* attributes a record may declare: far above tetgen's use */

/*
 * Reads "<count> <second> [<attributes> [<marker>]]" from the first line;
 * count must be positive, attributes 0..ATTRS_MAX, the marker flag 0 or 1
 * (both 0 when absent).  Each record must then hold what it declares.
 */
static int parse_header(struct mtext *t, const char *what, const char *kind,
			size_t min_bytes, long long *count, long long *second,
			long long extra[2], char *err, size_t errlen)
{
	struct mline l;

	if (!mtext_next_line(t, &l)) {
		mesh_err(err, errlen, what, "empty %s file", kind);
		return IRDM_EFORMAT;
	}
	if (mline_ll(&l, count) || mline_ll(&l, second)) {
		mesh_err(err, errlen, what, "line %zu: bad %s header", l.lineno, kind);
		return IRDM_EFORMAT;
	}
	extra[0] = extra[1] = 0;
	if (!mline_ll(&l, &extra[0]))
		mline_ll(&l, &extra[1]);
	if (extra[0] < 0 || extra[0] > ATTRS_MAX || extra[1] < 0 || extra[1] > 1) {
		mesh_err(err, errlen, what,
			 "line %zu: %lld attributes and marker flag %lld per %s (0..%d and 0 or 1)",
			 l.lineno, extra[0], extra[1], kind, ATTRS_MAX);
		return IRDM_EFORMAT;
	}
	if (*count <= 0) {
		mesh_err(err, errlen, what, "declares %lld %ss (nothing to read)",
			 *count, kind);
		return IRDM_EFORMAT;
	}
	if (*count > (long long)MESH_MAX_ITEMS) {
		mesh_err(err, errlen, what, "declares %lld %ss (limit %u)", *count,
			 kind, MESH_MAX_ITEMS);
		return IRDM_EFORMAT;
	}
	if ((unsigned long long)*count > t->len / min_bytes) {
		mesh_err(err, errlen, what,
			 "declares %lld %ss but has only %zu bytes (truncated?)",
			 *count, kind, t->len);
		return IRDM_EFORMAT;
	}
	return 0;
}

/* The attributes (and marker) the header declared are on the record. */
static int record_rest(struct mline *l, long long want, const char *kind, const char *what,
		       char *err, size_t errlen)
{
	double v;

	for (long long k = 0; k < want; k++)
		if (mline_double(l, &v)) {
			mesh_err(err, errlen, what,
				 "line %zu: the header declares %lld attribute or marker value%s per %s, the line has %lld",
				 l->lineno, want, want == 1 ? "" : "s", kind, k);
			return IRDM_EFORMAT;
		}
	return 0;
}

static int parse_node_line(struct mline *l, size_t i, long long *base,
			   double *x, uint64_t *tag, const char *what,
			   char *err, size_t errlen)
{
	long long idx;

	if (mline_ll(l, &idx)) {
		mesh_err(err, errlen, what, "line %zu: bad node index", l->lineno);
		return IRDM_EFORMAT;
	}
	if (i == 0) {
		if (idx != 0 && idx != 1) {
			mesh_err(err, errlen, what,
				 "line %zu: first node index is %lld (expected 0 or 1)",
				 l->lineno, idx);
			return IRDM_EFORMAT;
		}
		*base = idx;
	} else if (idx != *base + (long long)i) {
		mesh_err(err, errlen, what,
			 "line %zu: node index %lld, expected %lld (indices must be consecutive)",
			 l->lineno, idx, *base + (long long)i);
		return IRDM_EFORMAT;
	}
	if (mline_double(l, &x[0]) || mline_double(l, &x[1]) ||
	    mline_double(l, &x[2])) {
		mesh_err(err, errlen, what, "line %zu: node %lld needs 3 coordinates",
			 l->lineno, idx);
		return IRDM_EFORMAT;
	}
	*tag = (uint64_t)idx;
	return 0;
}

static int parse_nodes(const char *txt, size_t len, const char *what,
		       struct irdm_mesh *m, struct mesh_labels *lab,
		       long long *base, char *err, size_t errlen)
{
	struct mtext t;
	struct mline l;
	long long n, dim, extra[2];
	size_t i;
	int ret;

	mtext_init(&t, txt, len, '#');
	ret = parse_header(&t, what, "node", NODE_MIN_BYTES, &n, &dim, extra, err, errlen);
	if (ret)
		return ret;
	if (dim != 3) {
		mesh_err(err, errlen, what, "dimension is %lld, expected 3", dim);
		return IRDM_EFORMAT;
	}
	m->pos_m = malloc((size_t)n * 3 * sizeof(*m->pos_m));
	lab->node_tag = malloc((size_t)n * sizeof(*lab->node_tag));
	if (!m->pos_m || !lab->node_tag) {
		mesh_err(err, errlen, what, "out of memory for %lld nodes", n);
		return IRDM_ENOMEM;
	}
	for (i = 0; i < (size_t)n; i++) {
		if (!mtext_next_line(&t, &l)) {
			mesh_err(err, errlen, what,
				 "truncated: %zu of %lld nodes present", i, n);
			return IRDM_EFORMAT;
		}
		ret = parse_node_line(&l, i, base, m->pos_m + 3 * i,
				      &lab->node_tag[i], what, err, errlen);
		if (!ret)
			ret = record_rest(&l, extra[0] + extra[1], "node", what, err, errlen);
		if (ret)
			return ret;
	}
	m->n_nodes = (size_t)n;
	return 0;
}

static int parse_ele_line(struct mline *l, struct irdm_mesh *m, size_t i,
			  long long base, uint64_t *tag, const char *what,
			  char *err, size_t errlen)
{
	long long idx, ref;
	int k;

	if (mline_ll(l, &idx) || idx < 0) {
		mesh_err(err, errlen, what, "line %zu: bad element index", l->lineno);
		return IRDM_EFORMAT;
	}
	for (k = 0; k < 4; k++) {
		if (mline_ll(l, &ref)) {
			mesh_err(err, errlen, what,
				 "line %zu: element %lld needs 4 node numbers",
				 l->lineno, idx);
			return IRDM_EFORMAT;
		}
		if (ref < base || (unsigned long long)(ref - base) >= m->n_nodes) {
			mesh_err(err, errlen, what,
				 "line %zu: element %lld refers to node %lld, which is not in the node file",
				 l->lineno, idx, ref);
			return IRDM_EFORMAT;
		}
		m->tets[4 * i + k] = (uint32_t)(ref - base);
	}
	*tag = (uint64_t)idx;
	return 0;
}

static int parse_eles(const char *txt, size_t len, const char *what,
		      struct irdm_mesh *m, struct mesh_labels *lab,
		      long long base, char *err, size_t errlen)
{
	struct mtext t;
	struct mline l;
	long long n, npt, extra[2];
	size_t i;
	int ret;

	mtext_init(&t, txt, len, '#');
	ret = parse_header(&t, what, "element", ELE_MIN_BYTES, &n, &npt, extra, err, errlen);
	if (ret)
		return ret;
	if (npt != 4 && npt != 10) {
		mesh_err(err, errlen, what,
			 "%lld nodes per element (expected 4 or 10)", npt);
		return IRDM_EFORMAT;
	}
	m->tets = malloc((size_t)n * 4 * sizeof(*m->tets));
	lab->tet_tag = malloc((size_t)n * sizeof(*lab->tet_tag));
	if (!m->tets || !lab->tet_tag) {
		mesh_err(err, errlen, what, "out of memory for %lld elements", n);
		return IRDM_ENOMEM;
	}
	for (i = 0; i < (size_t)n; i++) {
		if (!mtext_next_line(&t, &l)) {
			mesh_err(err, errlen, what,
				 "truncated: %zu of %lld elements present", i, n);
			return IRDM_EFORMAT;
		}
		ret = parse_ele_line(&l, m, i, base, &lab->tet_tag[i], what,
				     err, errlen);
		if (!ret)
			ret = record_rest(&l, extra[0], "element", what, err, errlen);
		if (ret)
			return ret;
	}
	m->n_tets = (size_t)n;
	return 0;
}

int mesh_parse_tetgen_labeled(const char *node_txt, size_t node_len,
			      const char *ele_txt, size_t ele_len,
			      struct irdm_mesh *m, struct mesh_labels *lab,
			      char *err, size_t errlen)
{
	long long base = 0;
	int ret;

	memset(m, 0, sizeof(*m));
	lab->node_tag = NULL;
	lab->tet_tag = NULL;
	ret = parse_nodes(node_txt, node_len, lab->node_what, m, lab, &base,
			  err, errlen);
	if (ret)
		goto fail;
	ret = parse_eles(ele_txt, ele_len, lab->tet_what, m, lab, base, err, errlen);
	if (ret)
		goto fail;
	mesh_set_name(m, lab->tet_what);
	return IRDM_OK;

fail:
	mesh_labels_free(lab);
	irdm_mesh_free(m);
	return ret;
}

int irdm_mesh_parse_tetgen(const char *node_txt, size_t node_len,
			   const char *ele_txt, size_t ele_len, const char *what,
			   struct irdm_mesh *m, char *err, size_t errlen)
{
	struct mesh_labels lab = { what, what, NULL, NULL };
	int ret;

	ret = mesh_parse_tetgen_labeled(node_txt, node_len, ele_txt, ele_len, m,
					&lab, err, errlen);
	mesh_labels_free(&lab);
	return ret;
}
