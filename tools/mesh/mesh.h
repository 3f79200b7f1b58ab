/* SPDX-License-Identifier: MIT */
/*
 * Tetrahedral meshes for the offline tools: readers (TetGen, Gmsh, surface
 * meshes through Debian's tetgen), built-in generators, validation and the
 * outward boundary surface.
 *
 * Every function that can fail returns 0 on success or -1 with a one-line
 * message in err[errlen] that names the input and the reason (for example
 * "bunny.ele: element 17 is inverted (volume -1.2e-09 m^3)").  On failure
 * the mesh is left empty (irdm_mesh_free() is still safe to call).
 */
#ifndef IRDM_TOOLS_MESH_H
#define IRDM_TOOLS_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"

struct irdm_mesh {
	size_t n_nodes;
	double *pos_m; /* 3 * n_nodes, metres */
	size_t n_tets;
	uint32_t *tets; /* 4 * n_tets, 0-based, positive volume */
	size_t n_tris;
	uint32_t *tris; /* 3 * n_tris boundary faces, CCW seen from outside */
	char name[64];  /* short name for provenance (file stem or generator) */
};

/* A triangle surface before tetrahedralisation. */
struct irdm_surface {
	size_t n_verts;
	double *pos_m; /* 3 * n_verts */
	size_t n_tris;
	uint32_t *tris; /* 3 * n_tris, 0-based */
};

void irdm_mesh_free(struct irdm_mesh *m);
void irdm_surface_free(struct irdm_surface *s);

/*
 * Read any supported mesh, chosen by extension: .node or .ele (TetGen pair,
 * 0- or 1-based), .msh (Gmsh ASCII 2.2 or 4.1), .obj/.off/.stl (surface,
 * tetrahedralised by running `tetgen`).  scale multiplies coordinates (e.g.
 * 0.001 for a mesh in mm).  tetgen_switches: tetgen switches for surface
 * meshes, replacing the default "pq1.414" (NULL or "" for the default; 'p'
 * and 'Q' are added when missing).  Surfaces are tetrahedralised in their
 * file's units, so a volume bound such as "pq1.414a0.5" is in those units;
 * scale is applied afterwards.  The result is validated and has its
 * boundary computed.  Messages name nodes and elements as the file numbers
 * them (TetGen index, Gmsh tag).
 *
 * Return: IRDM_OK; IRDM_EINVAL if there is no path, the scale is not
 * positive or the tetgen switches are unusable; IRDM_EIO if a file cannot
 * be opened or read; IRDM_ERANGE if it is larger than 2 GiB; IRDM_EFORMAT
 * if the extension is unknown or the mesh malformed or invalid;
 * IRDM_ENOMEM; IRDM_ECHILD if tetgen cannot run or fails.
 */
int irdm_mesh_read(const char *path, double scale, const char *tetgen_switches,
		   struct irdm_mesh *m, char *err, size_t errlen);

/*
 * In-memory parsers (also the fuzz targets).  `what` names the input in
 * messages.  They do not validate geometry; irdm_mesh_finish() does (the
 * surface parsers do check indices, finiteness and degenerate triangles).
 * Inputs need no terminating NUL; only len bytes are read.  The output
 * struct is overwritten, not freed first.
 * Return: IRDM_OK; IRDM_EFORMAT if the input is malformed; IRDM_ENOMEM.
 */
int irdm_mesh_parse_tetgen(const char *node_txt, size_t node_len,
			   const char *ele_txt, size_t ele_len, const char *what,
			   struct irdm_mesh *m, char *err, size_t errlen);
int irdm_mesh_parse_gmsh(const char *txt, size_t len, const char *what,
			 struct irdm_mesh *m, char *err, size_t errlen);
int irdm_surface_parse_obj(const char *txt, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen);
int irdm_surface_parse_off(const char *txt, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen);
/* STL, ASCII or binary; coincident vertices are merged. */
int irdm_surface_parse_stl(const void *buf, size_t len, const char *what,
			   struct irdm_surface *s, char *err, size_t errlen);

/*
 * Run Debian's `tetgen` on a closed surface in a private temp directory
 * (under $TMPDIR, always removed); $IRDM_TETGEN overrides the program.
 * switches as for irdm_mesh_read().
 * Return: IRDM_OK; IRDM_EFORMAT if the surface is invalid or tetgen's
 * output malformed; IRDM_EINVAL if the switches are unusable; IRDM_EIO if
 * the temporary files cannot be made; IRDM_ENOMEM; IRDM_ECHILD if tetgen
 * cannot run, fails or makes no tetrahedra.
 */
int irdm_surface_tetrahedralize(const struct irdm_surface *s, const char *switches,
				const char *what, struct irdm_mesh *m,
				char *err, size_t errlen);

/*
 * How big a surface's tetrahedralisation should be (surface_sizing.c).
 * switches, when set, win: tetgen runs once with them.  Otherwise
 * target_nodes (0: none) picks tetgen's -a bound from the enclosed volume
 * and re-runs tetgen (at most 6 times, loosening the radius-edge bound -q
 * while there are too many nodes) until the count is within a factor 2,
 * keeping the closest; max_tet_volume (file units^3, 0: none) caps the -a
 * bound, or alone is it.  note says what was done ("" if nothing).
 */
struct irdm_mesh_sizing {
	const char *switches;
	unsigned target_nodes;
	double max_tet_volume;
	char note[256];
};

int irdm_surface_tetrahedralize_sized(const struct irdm_surface *s, struct irdm_mesh_sizing *sz,
				      const char *what, struct irdm_mesh *m, char *err,
				      size_t errlen);

/* The volume a closed surface encloses (its units cubed). */
double irdm_surface_volume(const struct irdm_surface *s);

/* irdm_mesh_read() with a sizing for surfaces (sz->max_tet_volume in m^3:
 * converted to the file's units by the scale). */
int irdm_mesh_read_sized(const char *path, double scale, struct irdm_mesh_sizing *sz,
			 struct irdm_mesh *m, char *err, size_t errlen);

/*
 * Validate and finish a parsed mesh: finite coordinates, indices in range,
 * no repeated node in a tet, no zero-volume or inverted tet, no
 * unreferenced node; then compute the outward boundary triangles (a face
 * shared by more than two tets, or by two on the same side, is an error).
 * Messages name nodes and elements by 1-based position, as most mesh files
 * count; irdm_mesh_read() uses the file's own numbers instead.  Inverted
 * tets are an error, not silently flipped: a reader that knows its
 * convention orders nodes itself.  On failure the mesh is freed.
 * Return: IRDM_OK; IRDM_EFORMAT if the mesh is invalid; IRDM_ENOMEM.
 */
int irdm_mesh_finish(struct irdm_mesh *m, const char *what, char *err, size_t errlen);

/* What a mesh is made of (mesh_stats.c). */
struct irdm_mesh_stats {
	size_t n_nodes, n_tets, worst_tet;
	double size_m; /* the largest bounding-box side */
	double vol_min_m3, vol_max_m3;
	double quality_min, quality_max; /* 1: regular tet, 0: flat */
};
#define IRDM_MESH_VOL_SPAN_WARN 1e6 /* tet volumes spanning more: graded */
#define IRDM_MESH_SIZE_WARN_M 5.0   /* a desktop object larger: units? */
#define IRDM_MESH_SIZE_SMALL_M 1e-3 /* or smaller */

void irdm_mesh_stats(const struct irdm_mesh *m, struct irdm_mesh_stats *st);

/* The stats as a line, then a line per warning; returns how many (1-3). */
int irdm_mesh_stats_text(const struct irdm_mesh *m, const struct irdm_mesh_stats *st,
			 char lines[3][256]);

/*
 * Whether only straining moves the mesh (grounded: anchored by the fixed
 * nodes, fixed[i] per node) or it moves only as one rigid body (floating);
 * mesh_rigidity.c says how, without a tolerance on eigenvalues.
 * Return: 0; -1 with a "model: ..." message naming a node of a loose part
 * (or of running out of memory).
 */
int irdm_mesh_check_rigidity(const struct irdm_mesh *m, const bool *fixed, bool floating,
			     char *err, size_t errlen);

/*
 * Built-in generators: an axis-aligned box [0,lx]x[0,ly]x[0,lz] (metres)
 * split into nx*ny*nz hexahedra, each cut into 5 (alternating, conforming)
 * or 6 (Kuhn) tetrahedra.  The paper's cuboid is 0.1 x 0.1 x 0.2 m with
 * 11x11x22 hexes of 5 tets: 3312 nodes, 13310 tets.
 * Return: IRDM_OK; IRDM_EINVAL if a size or count is out of range;
 * IRDM_ENOMEM.
 */
int irdm_mesh_gen_box(double lx, double ly, double lz, unsigned nx, unsigned ny,
		      unsigned nz, unsigned tets_per_hex, struct irdm_mesh *m,
		      char *err, size_t errlen);

/* Total volume (m^3), a cheap consistency check for tests. */
double irdm_mesh_volume(const struct irdm_mesh *m);

/* FNV-1a 64 over positions and tets (provenance). */
uint64_t irdm_mesh_hash(const struct irdm_mesh *m);

#endif /* IRDM_TOOLS_MESH_H */
