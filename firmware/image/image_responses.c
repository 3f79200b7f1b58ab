/* SPDX-License-Identifier: MIT */
/*
 * The responses: STABILITY of the force recursion per column, then either
 * the FIR (R[s] blocks) or the modal form (MODES, MODE_SHAPES and the
 * optional STATIC_CORR: image_static_corr.c), every value scanned for NaN and infinity.
 */
#include <stdbool.h>
#include <stdint.h>

#include "image_priv.h"

/* The table is the one truth about stability: the flag of each column and
 * the meta's largest radius are copies, and must say what it says. */
int img_check_stability(struct parse *p)
{
	const struct irdm_stability *st;
	double max = 0;
	uint32_t at = 0;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_STABILITY, true, "always");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_STABILITY,
				      (uint64_t[]){ p->meta.n_cols, sizeof(*st) }, 2,
				      "n_cols x 8");
	if (ret)
		return ret;
	st = img_payload(p, IRDM_SEC_STABILITY);
	for (uint32_t i = 0; i < p->meta.n_cols; i++) {
		float rho = st[i].spectral_radius;

		if (!f32_finite(rho) || rho < 0)
			return img_fail(p, IRDM_EFORMAT,
					"column %u: spectral radius %g is not a finite value >= 0",
					i, (double)rho);
		if (!(st[i].flags & IRDM_STAB_STABLE) != !(rho < 1))
			return img_fail(p, IRDM_EFORMAT,
					"column %u is flagged %s with spectral radius %g",
					i, rho < 1 ? "unstable" : "stable", (double)rho);
		if (rho > max) {
			max = rho;
			at = i;
		}
	}
	if (p->meta.max_spectral_radius != max)
		return img_fail(p, IRDM_EFORMAT,
				"meta max_spectral_radius %.9g disagrees with the STABILITY table, whose largest radius is %.9g (column %u)",
				p->meta.max_spectral_radius, max, at);
	p->img.stability = st;
	return IRDM_OK;
}

int img_check_fir(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint64_t f[] = { m->n_cols, m->n_nodes, m->fir_length, 9 };
	int ret;

	ret = img_check_presence(p, IRDM_SEC_FIR, true, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_MODES, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_MODE_SHAPES, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_INDEX, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_LOWRANK, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_CLUSTERS, false, "FIR image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_EXACT_HEAD, false, "FIR image");
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_FIR, f, 4, "n_cols x n_nodes x T x 9");
	if (!ret)
		ret = img_check_finite(p, IRDM_SEC_FIR, p->by_kind[IRDM_SEC_FIR]->size / p->es);
	if (ret)
		return ret;
	p->img.fir = img_payload(p, IRDM_SEC_FIR);
	return IRDM_OK;
}

static int check_modes(struct parse *p)
{
	const struct irdm_mode *modes;
	int ret;

	ret = img_check_shape(p, IRDM_SEC_MODES,
			      (uint64_t[]){ p->meta.n_modes, sizeof(*modes) }, 2,
			      "n_modes x 64");
	if (ret)
		return ret;
	modes = img_payload(p, IRDM_SEC_MODES);
	for (uint32_t k = 0; k < p->meta.n_modes; k++) {
		const struct irdm_mode *md = &modes[k];
		bool ok = f64_finite(md->omega_rad_s) && md->omega_rad_s >= 0 &&
			  f64_finite(md->zeta) && md->zeta >= 0;

		for (unsigned i = 0; i < 4; i++)
			ok = ok && f64_finite(md->a[i]);
		ok = ok && f64_finite(md->b[0]) && f64_finite(md->b[1]);
		if (!ok)
			return img_fail(p, IRDM_EFORMAT,
					"mode %u: omega %g, zeta %g: need finite omega >= 0, zeta >= 0, A and b",
					k, md->omega_rad_s, md->zeta);
	}
	p->img.modes = modes;
	return IRDM_OK;
}

int img_check_modal(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	bool corr = m->flags & IRDM_META_STATIC_CORR;
	const uint64_t shapes[] = { m->n_nodes, 3, m->n_modes };
	int ret;

	ret = img_check_presence(p, IRDM_SEC_FIR, false, "modal image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_MODES, true, "modal image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_MODE_SHAPES, true, "modal image");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR, corr,
					 corr ? "meta flags say STATIC_CORR" :
						"meta flags lack STATIC_CORR");
	if (!ret)
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_INDEX, corr,
					 corr ? "meta flags say STATIC_CORR" :
						"meta flags lack STATIC_CORR");
	if (!ret)
		ret = check_modes(p);
	if (!ret)
		ret = img_check_shape(p, IRDM_SEC_MODE_SHAPES, shapes, 3,
				      "n_nodes x 3 x n_modes");
	if (!ret)
		ret = img_check_finite(p, IRDM_SEC_MODE_SHAPES,
				       p->by_kind[IRDM_SEC_MODE_SHAPES]->size / p->es);
	if (!ret && !corr && p->by_kind[IRDM_SEC_STATIC_CORR_LOWRANK])
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_LOWRANK, false,
					 "its far field needs STATIC_CORR");
	if (!ret && !corr && p->by_kind[IRDM_SEC_STATIC_CORR_CLUSTERS])
		ret = img_check_presence(p, IRDM_SEC_STATIC_CORR_CLUSTERS, false,
					 "its clusters need STATIC_CORR");
	if (!ret && corr)
		ret = img_check_static_corr(p);
	if (!ret && corr)
		ret = img_check_corr_clusters(p);
	if (!ret && corr)
		ret = img_check_corr_lowrank(p);
	if (!ret)
		ret = img_check_exact_head(p);
	if (ret)
		return ret;
	p->img.mode_shapes = img_payload(p, IRDM_SEC_MODE_SHAPES);
	return IRDM_OK;
}
