/* SPDX-License-Identifier: MIT */
/*
 * Internals shared by the mesh readers: bounded text scanning (inputs are
 * not NUL-terminated), error formatting, growable arrays and the labelled
 * form of irdm_mesh_finish() that names nodes and elements the way the
 * input file does.
 */
#ifndef IRDM_TOOLS_MESH_PRIV_H
#define IRDM_TOOLS_MESH_PRIV_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mesh/mesh.h"

/*
 * Upper bound on nodes, tets or triangles.  It keeps every index inside
 * uint32_t and stops a hostile header from asking for gigabytes.
 */
#define MESH_MAX_ITEMS 50000000u

/* Largest file irdm_mesh_read() loads into memory. */
#define MESH_MAX_FILE_BYTES ((size_t)1 << 31)

void mesh_err(char *err, size_t errlen, const char *what, const char *fmt, ...);

/* Copy a token for an error message: printable, short, always terminated. */
void mesh_quote(char *dst, size_t dstlen, const char *tok, size_t n);

/* Six times the signed volume of the tet with nodes t[0..3] of positions x:
 * (b-a)x(c-a).(d-a), positive for our node order (mesh_base.c). */
double mesh_tet_vol6(const double *x, const uint32_t *t);

/* m->name = basename of `what` without its extension. */
void mesh_set_name(struct irdm_mesh *m, const char *what);

/*
 * Grow p (*cap elements of elsize bytes) to hold at least need elements,
 * at most MESH_MAX_ITEMS * 4.  Returns the new block, or NULL with p
 * untouched (and still owned by the caller).
 */
void *mesh_grow(void *p, size_t *cap, size_t need, size_t elsize);

/* Scanner over a whole text; lines end at '\n', an optional '\r' is blank. */
struct mtext {
	const char *p;
	size_t len;
	size_t pos;
	size_t lineno;
	bool has_comment; /* cut each line at `comment` */
	char comment;
};

/* One line being split into whitespace-separated tokens. */
struct mline {
	const char *p;
	size_t len;
	size_t pos;
	size_t lineno; /* 1-based line number in the text */
};

void mtext_init(struct mtext *t, const char *p, size_t len, int comment);
/* Next non-blank line (comments removed); false at the end of the text. */
bool mtext_next_line(struct mtext *t, struct mline *l);

bool mline_token(struct mline *l, const char **tok, size_t *n);
/* 0, or -1 if the next token is missing or not a number. */
int mline_double(struct mline *l, double *v);
int mline_ll(struct mline *l, long long *v);
/* True if the line's first token is exactly `word`. */
bool mline_is(const struct mline *l, const char *word);

int mesh_tok_double(const char *tok, size_t n, double *v);
int mesh_tok_ll(const char *tok, size_t n, long long *v);

/*
 * How the input names things, for messages.  A NULL tag array means
 * "1-based position"; the whats default to the `what` of the caller.
 */
struct mesh_labels {
	const char *node_what;
	const char *tet_what;
	uint64_t *node_tag; /* n_nodes entries or NULL */
	uint64_t *tet_tag;  /* n_tets entries or NULL */
};

void mesh_labels_free(struct mesh_labels *lab);
uint64_t mesh_node_label(const struct mesh_labels *lab, size_t i);
uint64_t mesh_tet_label(const struct mesh_labels *lab, size_t i);

int mesh_finish_labeled(struct irdm_mesh *m, const struct mesh_labels *lab,
			char *err, size_t errlen);

/* Parsers that also report the file's own node and element numbers. */
int mesh_parse_tetgen_labeled(const char *node_txt, size_t node_len,
			      const char *ele_txt, size_t ele_len,
			      struct irdm_mesh *m, struct mesh_labels *lab,
			      char *err, size_t errlen);
int mesh_parse_gmsh_labeled(const char *txt, size_t len, const char *what,
			    struct irdm_mesh *m, struct mesh_labels *lab,
			    char *err, size_t errlen);

/* Load a whole file (at most MESH_MAX_FILE_BYTES). */
int mesh_read_file(const char *path, char **buf, size_t *len,
		   char *err, size_t errlen);

/*
 * Check a surface before it is handed to tetgen: finite coordinates,
 * indices in range, no repeated vertex in a triangle, at least 4
 * triangles.  Every surface parser ends with it.
 */
int surface_check(const struct irdm_surface *s, const char *what,
		  char *err, size_t errlen);

/* Vertices closer than this fraction of the bounding box's diagonal are
 * one vertex (surface_weld.c): 1e-9 is far below any meshable feature and
 * far above a generator's rounding. */
#define IRDM_WELD_REL 1e-9

/* Weld s's coincident vertices in place: welded counts the vertices
 * removed, tol the distance used (file units).  0 or IRDM_ENOMEM. */
int surface_weld(struct irdm_surface *s, size_t *welded, double *tol);

/* Every edge in exactly two triangles (surface_closed.c); else
 * IRDM_EFORMAT naming the count and the first bad edge. */
int surface_check_closed(const struct irdm_surface *s, const char *what, char *err,
			 size_t errlen);

/* Growing a surface while parsing; 0 or -1 (out of memory / too many). */
struct surface_build {
	struct irdm_surface *s;
	size_t cap_verts;
	size_t cap_tris;
};

int surface_add_vert(struct surface_build *b, const double x[3]);
int surface_add_tri(struct surface_build *b, uint32_t v0, uint32_t v1,
		    uint32_t v2);

#endif /* IRDM_TOOLS_MESH_PRIV_H */
