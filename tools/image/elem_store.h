/* SPDX-License-Identifier: MIT */
/*
 * The writer side of the storage precision: the one place the tools turn a
 * double into an f16, f32 or f64 element (firmware/include/irdm/precision.h
 * is the reading side).
 */
#ifndef IRDM_TOOLS_ELEM_STORE_H
#define IRDM_TOOLS_ELEM_STORE_H

#include <stddef.h>
#include <stdint.h>

/* Store v as element i of an array of precision elem (IRDM_ELEM_F16, _F32
 * or _F64; unaligned data is fine) and return the value stored, read back
 * as a double, so callers can judge the data the firmware will see.  Any
 * other precision stores nothing and returns v. */
double irdm_elem_put(void *data, uint32_t elem, size_t i, double v);

#endif /* IRDM_TOOLS_ELEM_STORE_H */
