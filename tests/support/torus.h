/* SPDX-License-Identifier: MIT */
/*
 * The torus of tests/test_static_torus.c and of its benchmark
 * (tests/bench/bench_torus.c): a closed surface written as OFF, and the
 * scene settings both use, so that the test's figures and the benchmark's
 * time are of the same precompute.
 */
#ifndef IRDM_TESTS_TORUS_H
#define IRDM_TESTS_TORUS_H

#define TORUS_NU 36              /* vertices around the ring */
#define TORUS_NV 18              /* and around the tube */
#define TORUS_SCALE 0.05         /* mesh_scale: tube 2 cm, ring 5 cm */
#define TORUS_NODES 3250         /* target_nodes: about 2,500 touchable */
#define TORUS_CLUSTER "256"      /* static_correction_cluster */
#define TORUS_CLUSTER_TOL "8e-4" /* its static_correction_tol */

/* Ring radius 1 and tube radius 0.4: nu x nv vertices, two triangles per
 * quad, outward (counter-clockwise seen from outside).
 * Return: 0, or -1 if the file cannot be written. */
int torus_write_off(const char *path, unsigned nu, unsigned nv);

/* The same torus as a generator writes it: (nu + 1) x (nv + 1) vertices,
 * the last row and column of each ring repeating the first, computed
 * from their own angle (2 pi) and moved by about 1e-9 (a generator's
 * rounding), so that the seams are equal but not bit for bit: the
 * precompute welds them (mesh/surface_weld.c).
 * Return: 0, or -1 if the file cannot be written. */
int torus_write_off_seams(const char *path, unsigned nu, unsigned nv);

#endif
