/* SPDX-License-Identifier: MIT */
/*
 * A CAD-like part for tests and benchmarks: a 60 x 40 x 16 mm box with
 * 0.5 mm fillets on every edge and corner, 972 triangles, written as
 * binary STL in millimetres (as CAD tools export it; scale 0.001 to metres).
 * The fillets are what makes a quality-bounded tetrahedralisation refine.
 */
#ifndef IRDM_TESTS_CAD_PART_H
#define IRDM_TESTS_CAD_PART_H

/* Half sizes of the part (mm), for callers that place supports on it. */
extern const double cad_part_half_mm[3];

/* Write the part to path with the given 80-byte header text (CAD tools
 * often start it with "solid", which must not make it read as ASCII).
 * Return: 0, or -1 if the file cannot be written. */
int cad_part_write_stl(const char *path, const char *header);

#endif
