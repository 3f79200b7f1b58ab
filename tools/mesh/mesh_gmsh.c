// SPDX-License-Identifier: MIT
/*
 * Gmsh ASCII .msh reader, formats 2.2 and 4.1: nodes and tetrahedra
 * (element type 4, or the corners of type 11).  Other element types (points, lines,
 * triangles) and unknown sections ($PhysicalNames, $Entities, ...) are
 * skipped.  Node tags may be arbitrary, so elements are first stored by
 * tag and mapped at the end through a sorted tag table.
 *
 * Only nodes used by a tetrahedron are kept: Gmsh files routinely carry
 * nodes of lower-dimensional entities, which mean nothing to the FEM.
 *
 * Gmsh's reference tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) has
 * positive volume in our convention, so node order is kept as written.
 */
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "mesh/mesh_priv.h"

/* Shortest node record "1 0 0 0\n" (2.2) or tag line + "0 0 0" (4.1). */
#define NODE_MIN_BYTES 8

struct gmsh {
	const char *what;
	struct mtext t;
	int major; /* 2 or 4; 0 before $MeshFormat */
	bool have_nodes;
	bool have_elements;

	size_t n_nodes;
	double *pos; /* 3 per node */
	uint64_t *node_tag;

	size_t n_tets, cap_tets, cap_tet_tags;
	uint64_t *tet_nodes; /* 4 node tags per tet, mapped at the end */
	uint64_t *tet_tag;

	/* The helpers below return 0 or -1 with the reason in err; oom says
	 * which kind of failure it was (IRDM_ENOMEM, else IRDM_EFORMAT). */
	char *err;
	size_t errlen;
	bool oom;
};

struct tag_index {
	uint64_t tag;
	uint32_t index;
};

/* Next line or an error saying which section was cut short. */
static int next_line(struct gmsh *g, struct mline *l, const char *section)
{
	if (mtext_next_line(&g->t, l))
		return 0;
	mesh_err(g->err, g->errlen, g->what, "truncated inside %s", section);
	return -1;
}

static int expect_end(struct gmsh *g, const char *end)
{
	struct mline l;

	if (!mtext_next_line(&g->t, &l)) {
		mesh_err(g->err, g->errlen, g->what, "truncated: missing %s", end);
		return -1;
	}
	if (!mline_is(&l, end)) {
		mesh_err(g->err, g->errlen, g->what, "line %zu: expected %s",
			 l.lineno, end);
		return -1;
	}
	return 0;
}

/* A non-negative count no larger than limit. */
static int read_count(struct gmsh *g, struct mline *l, unsigned long long limit,
		      const char *name, size_t *out)
{
	long long v;

	if (mline_ll(l, &v) || v < 0) {
		mesh_err(g->err, g->errlen, g->what, "line %zu: bad %s",
			 l->lineno, name);
		return -1;
	}
	if ((unsigned long long)v > limit) {
		mesh_err(g->err, g->errlen, g->what,
			 "line %zu: %s %lld is too large for this file", l->lineno,
			 name, v);
		return -1;
	}
	*out = (size_t)v;
	return 0;
}

static int read_tag(struct gmsh *g, struct mline *l, const char *name,
		    uint64_t *out)
{
	long long v;

	if (mline_ll(l, &v) || v < 0) {
		mesh_err(g->err, g->errlen, g->what, "line %zu: bad %s",
			 l->lineno, name);
		return -1;
	}
	*out = (uint64_t)v;
	return 0;
}

static int parse_format(struct gmsh *g)
{
	struct mline l;
	double version;
	long long type;

	if (next_line(g, &l, "$MeshFormat"))
		return -1;
	if (mline_double(&l, &version) || mline_ll(&l, &type)) {
		mesh_err(g->err, g->errlen, g->what, "line %zu: bad $MeshFormat",
			 l.lineno);
		return -1;
	}
	if (type != 0) {
		mesh_err(g->err, g->errlen, g->what,
			 "binary Gmsh files are not supported (save as ASCII)");
		return -1;
	}
	if (version >= 2.0 && version < 3.0) {
		g->major = 2;
	} else if (version == 4.1) {
		g->major = 4;
	} else {
		mesh_err(g->err, g->errlen, g->what,
			 "Gmsh format %g is not supported (use 2.2 or 4.1)", version);
		return -1;
	}
	return expect_end(g, "$EndMeshFormat");
}

static int alloc_nodes(struct gmsh *g, size_t n)
{
	/* n >= 1 so that an empty section still gives non-NULL arrays. */
	g->pos = malloc((n ? n : 1) * 3 * sizeof(*g->pos));
	g->node_tag = malloc((n ? n : 1) * sizeof(*g->node_tag));
	if (!g->pos || !g->node_tag) {
		mesh_err(g->err, g->errlen, g->what, "out of memory for %zu nodes", n);
		g->oom = true;
		return -1;
	}
	return 0;
}

static int read_xyz(struct gmsh *g, struct mline *l, double *x)
{
	if (mline_double(l, &x[0]) || mline_double(l, &x[1]) ||
	    mline_double(l, &x[2])) {
		mesh_err(g->err, g->errlen, g->what,
			 "line %zu: a node needs 3 coordinates", l->lineno);
		return -1;
	}
	return 0;
}

static int parse_nodes_v2(struct gmsh *g)
{
	struct mline l;
	size_t n, i;

	if (next_line(g, &l, "$Nodes") ||
	    read_count(g, &l, g->t.len / NODE_MIN_BYTES, "node count", &n) ||
	    alloc_nodes(g, n))
		return -1;
	for (i = 0; i < n; i++) {
		if (next_line(g, &l, "$Nodes") ||
		    read_tag(g, &l, "node tag", &g->node_tag[i]) ||
		    read_xyz(g, &l, g->pos + 3 * i))
			return -1;
	}
	g->n_nodes = n;
	return 0;
}

/* One 4.1 entity block: <count> tag lines, then <count> coordinate lines. */
static int parse_node_block_v4(struct gmsh *g, size_t total)
{
	struct mline l;
	long long dim, entity, param;
	size_t count, i, first = g->n_nodes;

	if (next_line(g, &l, "$Nodes"))
		return -1;
	/* entityDim entityTag parametric numNodesInBlock */
	if (mline_ll(&l, &dim) || mline_ll(&l, &entity) || mline_ll(&l, &param)) {
		mesh_err(g->err, g->errlen, g->what,
			 "line %zu: bad node block header", l.lineno);
		return -1;
	}
	if (read_count(g, &l, total - first, "node block size", &count))
		return -1;
	for (i = 0; i < count; i++)
		if (next_line(g, &l, "$Nodes") ||
		    read_tag(g, &l, "node tag", &g->node_tag[first + i]))
			return -1;
	for (i = 0; i < count; i++)
		if (next_line(g, &l, "$Nodes") ||
		    read_xyz(g, &l, g->pos + 3 * (first + i)))
			return -1;
	g->n_nodes = first + count;
	return 0;
}

static int parse_nodes_v4(struct gmsh *g)
{
	struct mline l;
	size_t blocks, n, b;

	if (next_line(g, &l, "$Nodes") ||
	    read_count(g, &l, MESH_MAX_ITEMS, "node block count", &blocks) ||
	    read_count(g, &l, g->t.len / NODE_MIN_BYTES, "node count", &n) ||
	    alloc_nodes(g, n))
		return -1;
	for (b = 0; b < blocks; b++)
		if (parse_node_block_v4(g, n))
			return -1;
	if (g->n_nodes != n) {
		mesh_err(g->err, g->errlen, g->what,
			 "$Nodes declares %zu nodes but its blocks hold %zu",
			 n, g->n_nodes);
		return -1;
	}
	return 0;
}

/*
 * Type 4 is the linear tet; type 11 (10-node) lists its corners first,
 * so both give the same 4 nodes and the mid-edge nodes fall away unused.
 */
static bool is_tet(long long type)
{
	return type == 4 || type == 11;
}

static int add_tet(struct gmsh *g, struct mline *l, uint64_t tag)
{
	uint64_t *p;
	size_t k;

	p = mesh_grow(g->tet_nodes, &g->cap_tets, g->n_tets + 1,
		      4 * sizeof(*g->tet_nodes));
	if (!p)
		goto fail_oom;
	g->tet_nodes = p;
	p = mesh_grow(g->tet_tag, &g->cap_tet_tags, g->n_tets + 1,
		      sizeof(*g->tet_tag));
	if (!p)
		goto fail_oom;
	g->tet_tag = p;
	for (k = 0; k < 4; k++)
		if (read_tag(g, l, "tetrahedron node", &g->tet_nodes[4 * g->n_tets + k]))
			return -1;
	g->tet_tag[g->n_tets++] = tag;
	return 0;

fail_oom:
	mesh_err(g->err, g->errlen, g->what, "out of memory (or too many elements)");
	g->oom = true;
	return -1;
}

/* "tag type ntags tags... nodes..." */
static int parse_element_v2(struct gmsh *g, struct mline *l)
{
	long long type;
	uint64_t tag;
	size_t ntags, i, n;
	const char *tok;

	if (read_tag(g, l, "element tag", &tag))
		return -1;
	if (mline_ll(l, &type)) {
		mesh_err(g->err, g->errlen, g->what, "line %zu: bad element type",
			 l->lineno);
		return -1;
	}
	if (!is_tet(type))
		return 0;
	if (read_count(g, l, l->len, "element tag count", &ntags))
		return -1;
	for (i = 0; i < ntags; i++) {
		if (!mline_token(l, &tok, &n)) {
			mesh_err(g->err, g->errlen, g->what,
				 "line %zu: element %llu is cut short", l->lineno,
				 (unsigned long long)tag);
			return -1;
		}
	}
	return add_tet(g, l, tag);
}

static int parse_elements_v2(struct gmsh *g)
{
	struct mline l;
	size_t n, i;

	if (next_line(g, &l, "$Elements") ||
	    read_count(g, &l, MESH_MAX_ITEMS, "element count", &n))
		return -1;
	for (i = 0; i < n; i++)
		if (next_line(g, &l, "$Elements") || parse_element_v2(g, &l))
			return -1;
	return 0;
}

static int parse_element_block_v4(struct gmsh *g, size_t *left)
{
	struct mline l;
	long long dim, entity, type;
	size_t count, i;
	uint64_t tag;

	if (next_line(g, &l, "$Elements"))
		return -1;
	if (mline_ll(&l, &dim) || mline_ll(&l, &entity) || mline_ll(&l, &type)) {
		mesh_err(g->err, g->errlen, g->what,
			 "line %zu: bad element block header", l.lineno);
		return -1;
	}
	if (read_count(g, &l, *left, "element block size", &count))
		return -1;
	*left -= count;
	for (i = 0; i < count; i++) {
		if (next_line(g, &l, "$Elements") ||
		    read_tag(g, &l, "element tag", &tag))
			return -1;
		if (is_tet(type) && add_tet(g, &l, tag))
			return -1;
	}
	return 0;
}

static int parse_elements_v4(struct gmsh *g)
{
	struct mline l;
	size_t blocks, n, b;

	if (next_line(g, &l, "$Elements") ||
	    read_count(g, &l, MESH_MAX_ITEMS, "element block count", &blocks) ||
	    read_count(g, &l, MESH_MAX_ITEMS, "element count", &n))
		return -1;
	for (b = 0; b < blocks; b++)
		if (parse_element_block_v4(g, &n))
			return -1;
	return 0;
}

/* Skip "$Name" ... "$EndName". */
static int skip_section(struct gmsh *g, const char *name, size_t n)
{
	struct mline l;
	const char *tok;
	size_t tn;

	while (mtext_next_line(&g->t, &l)) {
		if (!mline_token(&l, &tok, &tn))
			continue;
		if (tn == n + 3 && !memcmp(tok, "$End", 4) &&
		    !memcmp(tok + 4, name + 1, n - 1))
			return 0;
	}
	mesh_err(g->err, g->errlen, g->what, "unterminated section");
	return -1;
}

static int parse_section(struct gmsh *g, struct mline *l)
{
	const char *tok;
	size_t n;
	char q[40];

	mline_token(l, &tok, &n);
	if (tok[0] != '$') {
		mesh_quote(q, sizeof(q), tok, n);
		mesh_err(g->err, g->errlen, g->what,
			 "line %zu: expected a $Section, found '%s'", l->lineno, q);
		return -1;
	}
	if (mline_is(l, "$MeshFormat"))
		return g->major ? skip_section(g, tok, n) : parse_format(g);
	if (!g->major) {
		mesh_err(g->err, g->errlen, g->what,
			 "no $MeshFormat before line %zu (not a Gmsh 2.2/4.1 file)",
			 l->lineno);
		return -1;
	}
	if (mline_is(l, "$Nodes") || mline_is(l, "$Elements")) {
		bool nodes = mline_is(l, "$Nodes");
		bool *have = nodes ? &g->have_nodes : &g->have_elements;

		if (*have) {
			mesh_err(g->err, g->errlen, g->what,
				 "line %zu: second %s section", l->lineno,
				 nodes ? "$Nodes" : "$Elements");
			return -1;
		}
		*have = true;
		if (nodes && (g->major == 2 ? parse_nodes_v2(g) : parse_nodes_v4(g)))
			return -1;
		if (!nodes && (g->major == 2 ? parse_elements_v2(g) :
					       parse_elements_v4(g)))
			return -1;
		return expect_end(g, nodes ? "$EndNodes" : "$EndElements");
	}
	return skip_section(g, tok, n);
}

static int tag_cmp(const void *pa, const void *pb)
{
	const struct tag_index *a = pa, *b = pb;

	if (a->tag != b->tag)
		return a->tag < b->tag ? -1 : 1;
	return a->index < b->index ? -1 : a->index > b->index;
}

static const struct tag_index *find_tag(const struct tag_index *t, size_t n,
					uint64_t tag)
{
	size_t lo = 0, hi = n;

	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2;

		if (t[mid].tag < tag)
			lo = mid + 1;
		else
			hi = mid;
	}
	return lo < n && t[lo].tag == tag ? &t[lo] : NULL;
}

static struct tag_index *sorted_tags(struct gmsh *g)
{
	struct tag_index *t;
	size_t i;

	t = malloc((g->n_nodes ? g->n_nodes : 1) * sizeof(*t));
	if (!t) {
		mesh_err(g->err, g->errlen, g->what, "out of memory");
		g->oom = true;
		return NULL;
	}
	for (i = 0; i < g->n_nodes; i++) {
		t[i].tag = g->node_tag[i];
		t[i].index = (uint32_t)i;
	}
	qsort(t, g->n_nodes, sizeof(*t), tag_cmp);
	for (i = 1; i < g->n_nodes; i++) {
		if (t[i].tag == t[i - 1].tag) {
			mesh_err(g->err, g->errlen, g->what,
				 "node tag %llu is defined twice",
				 (unsigned long long)t[i].tag);
			free(t);
			return NULL;
		}
	}
	return t;
}

/*
 * Resolve tet node tags to indices of the nodes kept (those used by a
 * tet, in file order); remap[] first marks use, then holds new indices.
 */
static int map_nodes(struct gmsh *g, struct irdm_mesh *m, struct mesh_labels *lab)
{
	struct tag_index *tags;
	const struct tag_index *hit;
	uint32_t *remap = NULL;
	size_t i, kept = 0;
	int ret = -1;

	tags = sorted_tags(g);
	if (!tags)
		return -1;
	remap = calloc(g->n_nodes ? g->n_nodes : 1, sizeof(*remap));
	m->tets = malloc(4 * g->n_tets * sizeof(*m->tets));
	if (!remap || !m->tets)
		goto fail_oom;
	for (i = 0; i < 4 * g->n_tets; i++) {
		hit = find_tag(tags, g->n_nodes, g->tet_nodes[i]);
		if (!hit) {
			mesh_err(g->err, g->errlen, g->what,
				 "element %llu refers to undefined node %llu",
				 (unsigned long long)g->tet_tag[i / 4],
				 (unsigned long long)g->tet_nodes[i]);
			goto out_free;
		}
		m->tets[i] = hit->index;
		remap[hit->index] = 1;
	}
	for (i = 0; i < g->n_nodes; i++) {
		if (!remap[i])
			continue;
		remap[i] = (uint32_t)kept;
		memmove(g->pos + 3 * kept, g->pos + 3 * i, 3 * sizeof(*g->pos));
		g->node_tag[kept++] = g->node_tag[i];
	}
	for (i = 0; i < 4 * g->n_tets; i++)
		m->tets[i] = remap[m->tets[i]];
	m->n_tets = g->n_tets;
	m->n_nodes = kept;
	m->pos_m = g->pos;
	lab->node_tag = g->node_tag;
	lab->tet_tag = g->tet_tag;
	g->pos = NULL;
	g->node_tag = NULL;
	g->tet_tag = NULL;
	ret = 0;
	goto out_free;

fail_oom:
	mesh_err(g->err, g->errlen, g->what, "out of memory");
	g->oom = true;
out_free:
	free(remap);
	free(tags);
	return ret;
}

static int parse_all(struct gmsh *g, struct irdm_mesh *m, struct mesh_labels *lab)
{
	struct mline l;

	while (mtext_next_line(&g->t, &l))
		if (parse_section(g, &l))
			return -1;
	if (!g->major || !g->have_nodes || !g->have_elements) {
		mesh_err(g->err, g->errlen, g->what,
			 "missing %s section", !g->major ? "$MeshFormat" : !g->have_nodes ? "$Nodes" :
											    "$Elements");
		return -1;
	}
	if (!g->n_tets) {
		mesh_err(g->err, g->errlen, g->what,
			 "no tetrahedra (element type 4): is this a surface mesh?");
		return -1;
	}
	return map_nodes(g, m, lab);
}

int mesh_parse_gmsh_labeled(const char *txt, size_t len, const char *what,
			    struct irdm_mesh *m, struct mesh_labels *lab,
			    char *err, size_t errlen)
{
	struct gmsh g;
	int ret;

	memset(m, 0, sizeof(*m));
	memset(&g, 0, sizeof(g));
	lab->node_tag = NULL;
	lab->tet_tag = NULL;
	g.what = what;
	g.err = err;
	g.errlen = errlen;
	mtext_init(&g.t, txt, len, -1);

	ret = parse_all(&g, m, lab);
	free(g.pos);
	free(g.node_tag);
	free(g.tet_nodes);
	free(g.tet_tag);
	if (ret) {
		mesh_labels_free(lab);
		irdm_mesh_free(m);
		return g.oom ? IRDM_ENOMEM : IRDM_EFORMAT;
	}
	mesh_set_name(m, what);
	return IRDM_OK;
}

int irdm_mesh_parse_gmsh(const char *txt, size_t len, const char *what,
			 struct irdm_mesh *m, char *err, size_t errlen)
{
	struct mesh_labels lab = { what, what, NULL, NULL };
	int ret;

	ret = mesh_parse_gmsh_labeled(txt, len, what, m, &lab, err, errlen);
	mesh_labels_free(&lab);
	return ret;
}
