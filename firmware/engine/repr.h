/* SPDX-License-Identifier: MIT */
/*
 * The tick's calls into the response representation (modal states or the
 * FIR ring), in one place: a build without one of them (irdm/build_config.h)
 * compiles its calls out here, and the engine never starts on an image of
 * that representation (engine.c refuses it).  Private to firmware/engine.
 */
#ifndef IRDM_ENGINE_REPR_H
#define IRDM_ENGINE_REPR_H

#include "irdm/build_config.h"

#include "engine_priv.h"

static inline bool repr_is_modal(const struct irdm_engine *e)
{
	return IRDM_CONFIG_MODAL && (!IRDM_CONFIG_FIR || e->repr == IRDM_REPR_MODAL);
}

static inline void repr_free_disp(const struct irdm_engine *e, uint32_t col, double u[3])
{
#if IRDM_CONFIG_MODAL
	if (repr_is_modal(e)) {
		irdm_modal_free_disp(e, col, u);
		return;
	}
#endif
#if IRDM_CONFIG_FIR
	irdm_fir_free_disp(e, col, u);
#else
	(void)e, (void)col, (void)u;
#endif
}

/* The free displacement at n distinct columns: FIR images sum them in one
 * pass over the ring (fir_sum.c), a hybrid's head in one pass over its
 * lanes. */
static inline void repr_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
				   double (*u)[3])
{
#if IRDM_CONFIG_MODAL
	if (repr_is_modal(e)) {
		irdm_modal_free_disps(e, n, cols, u);
		return;
	}
#endif
#if IRDM_CONFIG_FIR
	irdm_fir_free_disps(e, n, cols, u);
#else
	(void)e, (void)n, (void)cols, (void)u;
#endif
}

static inline void repr_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp,
			   double blk[9])
{
#if IRDM_CONFIG_MODAL
	if (repr_is_modal(e)) {
		irdm_modal_r0(e, col_force, col_disp, blk);
		return;
	}
#endif
#if IRDM_CONFIG_FIR
	irdm_fir_r0(e, col_force, col_disp, blk);
#else
	(void)e, (void)col_force, (void)col_disp, (void)blk;
#endif
}

static inline void repr_apply(struct irdm_engine *e, const struct irdm_force_tick *f)
{
#if IRDM_CONFIG_MODAL
	if (repr_is_modal(e)) {
		irdm_modal_apply(e, f);
		return;
	}
#endif
#if IRDM_CONFIG_FIR
	irdm_fir_apply(e, f);
#else
	(void)e, (void)f;
#endif
}

#endif /* IRDM_ENGINE_REPR_H */
