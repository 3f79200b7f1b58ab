/* SPDX-License-Identifier: MIT */
/*
 * Contact detection on the deformed surface of a mapped image: the closest
 * point query over the image's CONTACT_BVH, and a frictionless god-object
 * (proxy) that stays on the surface and slides across triangle edges.
 *
 * Everything here runs in the force loop: no allocation, no system call,
 * no recursion (a fixed stack of IRDM_CONTACT_STACK nodes, enough for the
 * depth limit the loader enforces), bounded time (a query visits each BVH
 * node at most once; a proxy walk takes at most max_walk steps).
 *
 * Frames: positions in metres in the object frame.  The surface is the
 * REST positions of the image nodes plus their current displacements u
 * (struct irdm_contact_disp).  Triangles are named by SURFACE index and are
 * counter-clockwise seen from outside: the normal points out.
 */
#ifndef IRDM_CONTACT_H
#define IRDM_CONTACT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/error.h"
#include "irdm/image.h"

#define IRDM_CONTACT_STACK 64    /* > IRDM_BVH_MAX_DEPTH */
#define IRDM_CONTACT_MAX_WALK 64 /* upper limit of max_walk */

/*
 * Where a contact acts, as the force engine takes it (irdm/engine.h): on a
 * triangle of the image surface, or on a node.  Made by irdm_proxy_site()
 * here, or by irdm_engine_site_node() / irdm_engine_site_point().
 */
struct irdm_contact_site {
	uint32_t n_nodes; /* 1 (node) or 3 (triangle) */
	uint32_t col[3];  /* column index of each node, or UINT32_MAX if fixed */
	uint32_t row[3];  /* image node (row) index of each node */
	double weight[3]; /* barycentric, sum 1 */
	double rest_m[3]; /* rest position of the contact point */
	double normal[3]; /* outward unit normal at the point */
};

/* Views of a validated image's CONTACT_BVH (set up once, read only). */
struct irdm_contact_mesh {
	const struct irdm_image *img;
	const struct irdm_bvh_header *hdr;
	const struct irdm_bvh_node *nodes;
	const uint32_t *index;        /* contactable triangles, by leaf */
	const uint32_t *adj;          /* [n_surface_tris][3] */
	const uint32_t *col_of_row;   /* [n_rows] */
	const uint32_t *tris;         /* SURFACE */
	const struct irdm_node *rest; /* NODES */
	uint32_t n_tris;              /* SURFACE triangles */
	uint32_t n_rows;
	/* [n_tris][3]: the SURFACE triangle beyond each edge of a touchable
	 * triangle, touchable or not (adj knows only touchable ones), or
	 * IRDM_BVH_NONE on an open surface's edge; built at set-up by
	 * irdm_contact_beyond_build().  NULL: not built, and the proxy
	 * takes every edge of the touchable area's rim for an open edge. */
	const uint32_t *beyond;
};

/*
 * Current displacement of the image nodes: the array u_m (3 doubles a row)
 * if not NULL, else the callback fn(ctx, row, u) if not NULL, else zero.
 * (irdm_engine_node_disp() fits the callback through a one-line wrapper.)
 */
struct irdm_contact_disp {
	const double *u_m;
	void (*fn)(const void *ctx, uint32_t row, double u_m[3]);
	const void *ctx;
};

/* Result of a closest point query. */
struct irdm_contact_hit {
	uint32_t tri;      /* SURFACE triangle */
	double bary[3];    /* weights of its vertices v0, v1, v2; sum 1 */
	double point_m[3]; /* closest point on the displaced surface */
	double normal[3];  /* outward unit normal of the displaced triangle */
	double dist_m;     /* signed distance of the query point:
					 * < 0 behind the triangle (inside) */
};

/*
 * Set up the views (cm is zeroed first).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if img is NULL, has no metadata or has no CONTACT_BVH.
 */
int irdm_contact_mesh_init(struct irdm_contact_mesh *cm, const struct irdm_image *img);

/* Bytes of cm's face-beyond table: 3 words a SURFACE triangle. */
size_t irdm_contact_beyond_size(const struct irdm_contact_mesh *cm);

/*
 * Fill table (irdm_contact_beyond_size() bytes, the caller's) and point
 * cm->beyond at it.  At set-up, never in the force loop: an edge of the
 * touchable area's rim costs a pass over the surface's triangles (the
 * lowest-index other triangle on that edge is taken), so the proxy's
 * update then reads one word.  Returns the number of rim edges searched.
 */
uint32_t irdm_contact_beyond_build(struct irdm_contact_mesh *cm, uint32_t *table);

/* True when every vertex of SURFACE triangle t is a column. */
bool irdm_contact_tri_contactable(const struct irdm_contact_mesh *cm, uint32_t t);

/* Displaced vertex positions of SURFACE triangle t. */
void irdm_contact_tri_pos(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			  uint32_t t, double v[3][3]);

/*
 * Outward unit normal of SURFACE triangle t displaced by d, computed as the
 * proxy computes its own (irdm_proxy_site()'s normal), so a replay can
 * hand the engine the same one.  False for a zero-area triangle.
 */
bool irdm_contact_tri_normal(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			     uint32_t t, double n[3]);

/*
 * Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision
 * Detection 5.1.5): writes the point q and the barycentric weights of
 * a, b, c; returns |p - q|^2.  Works for degenerate triangles too.
 */
double irdm_contact_closest_on_tri(const double a[3], const double b[3], const double c[3],
				   const double p[3], double bary[3], double q[3]);

/*
 * Closest point to p on the displaced contactable surface within radius_m.
 * max_disp_m must bound |u| of every node (the boxes are the rest boxes
 * grown by it).  Zero-area triangles are skipped (their edges belong to
 * their neighbours).  Of equally distant triangles (an edge or a vertex)
 * the one whose plane p is farthest from wins, so the sign of an edge hit
 * comes from the face that sees p best.
 *
 * Return: 1 and *hit filled; 0 when nothing is within radius_m;
 * IRDM_EINVAL if cm (or its BVH), p or hit is NULL, p is not finite,
 * radius_m or max_disp_m is negative or not finite, or the BVH is deeper
 * than IRDM_CONTACT_STACK (the loader never lets such an image through).
 */
int irdm_contact_closest(const struct irdm_contact_mesh *cm, const struct irdm_contact_disp *d,
			 double max_disp_m, const double p[3], double radius_m,
			 struct irdm_contact_hit *hit);

/* ------------------------------------------------------------ god-object */

struct irdm_proxy_config {
	double radius_m;   /* detection radius of the closest point query */
	double max_disp_m; /* bound on |u| (see irdm_contact_closest) */
	unsigned max_walk; /* edge crossings per update, 1..IRDM_CONTACT_MAX_WALK */
	/* Coulomb friction: static and dynamic coefficients, 0 <= mu_d <=
	 * mu_s; mu_s = 0: frictionless (the default) */
	double mu_s, mu_d;
};

/* State of one proxy: zero it (or irdm_proxy_reset) to start inactive. */
struct irdm_proxy {
	bool active;
	uint32_t tri; /* SURFACE triangle of the proxy */
	double bary[3];
	/* outputs of the last update, valid while active */
	double point_m[3]; /* proxy on the displaced surface */
	double normal[3];  /* outward normal of its triangle */
	double depth_m;    /* signed distance of the device from that
					 * plane (<= 0 while in contact) */
	unsigned steps;    /* edge crossings taken by the last update */
	/* the force the coupling put on the object at the last update's
	 * point, when the caller gave it (irdm_proxy_force()): friction's
	 * cone is then judged on it */
	bool force_known;
	double force_n[3];
};

enum irdm_proxy_event {
	IRDM_PROXY_FREE = 0,    /* no contact before or after */
	IRDM_PROXY_TOUCH = 1,   /* contact began this update */
	IRDM_PROXY_SLIDE = 2,   /* contact continues */
	IRDM_PROXY_RELEASE = 3, /* the device left the surface: contact ended */
};

void irdm_proxy_config_default(struct irdm_proxy_config *cfg);
void irdm_proxy_reset(struct irdm_proxy *px);

/*
 * One update with the device at p (object frame).  Inactive: when the
 * closest point within radius_m has signed distance <= 0 (the device has
 * crossed the surface) and the device is not outside the object by a face
 * beyond that triangle's edges, the proxy starts there.  Active: the
 * device is projected on the plane of the proxy's displaced triangle;
 * while the projection leaves the triangle the proxy walks to the
 * neighbour across the edge it left by (at most max_walk steps); at a
 * boundary of the touchable region (or a concave crease) it stops at the
 * closest point of its triangle.  On a shared edge or vertex the triangle
 * of lowest index that holds the projection is taken.  The contact ends
 * when the device is outside the plane of the proxy's triangle (depth >
 * 0), or in front of the face beyond a convex edge it projects past or
 * beyond an edge of the touchable area's rim (that face touchable or not).
 *
 * Return: an enum irdm_proxy_event (>= 0);
 * IRDM_EINVAL if px, cm (or its BVH), cfg or p is NULL (px untouched), if
 * p is not finite or the active proxy's triangle is no longer contactable
 * (the proxy is released), or as irdm_contact_closest() for an inactive
 * proxy.
 */
int irdm_proxy_update(struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		      const struct irdm_contact_disp *d, const struct irdm_proxy_config *cfg,
		      const double p[3]);

/*
 * The force on the object (proxy's frame) that the contact at the last
 * update's site gave: with friction, the next update judges the cone on
 * it (the force the device renders, the coupling's damper and the
 * object's compliance included) instead of on the coupling spring's
 * geometry alone.  Forgotten when the proxy is released.
 */
void irdm_proxy_force(struct irdm_proxy *px, const double force_n[3]);

/*
 * The engine's contact site of an active proxy: n_nodes 3, rows and
 * columns of its triangle, weights = its barycentrics, rest_m = the same
 * barycentric point on the REST surface, normal = the displaced normal.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if px, cm (or its BVH) or site is NULL, or the proxy is not
 * active or its triangle is out of range.
 */
int irdm_proxy_site(const struct irdm_proxy *px, const struct irdm_contact_mesh *cm,
		    struct irdm_contact_site *site);

#endif /* IRDM_CONTACT_H */
