/* SPDX-License-Identifier: MIT */
/* Internals of the force engine shared by its files. */
#ifndef IRDM_ENGINE_PRIV_H
#define IRDM_ENGINE_PRIV_H

#include "irdm/build_config.h"
#include "irdm/deform.h"
#include "irdm/engine.h"
#include "irdm/history.h"
#include "irdm/rigid.h"
#include "irdm/vec3.h"

#define NO_COL UINT32_MAX
#define MAX_SOLVE (3 * IRDM_MAX_CONTACTS)

/*
 * R[0] blocks between the distinct nodes of the active contact sites (at
 * most IRDM_MAX_FORCE_NODES): blk[a][b] = displacement at node a per force
 * at node b.  Rebuilt only for nodes that are new when the sites change.
 */
struct r0_table {
	uint32_t n;
	uint32_t col[IRDM_MAX_FORCE_NODES];
	double blk[IRDM_MAX_FORCE_NODES][IRDM_MAX_FORCE_NODES][9];
};

#define FREE_MEMO 16 /* entries, direct-mapped by column */

/*
 * A hybrid image's force history by column (head_lanes.c), beside the ring
 * of ticks: a lane holds one force column's samples, one per tick and zero
 * at a tick without its force, so that the head sum for one kept block is
 * a dot product over contiguous samples.  A sample is eight doubles, the
 * force in the pattern of a block's elements, (f0 f1 f2 f0)(f1 f2 f0 f1),
 * f2 at [2]: two vector loads (wide_block.h).  The newest sample sits one
 * place before the previous one, so that ages run forward through memory.
 * Twice the columns one tick can hold: a sliding contact's old columns stay
 * in the window for H ticks after it left them.
 */
#define HEAD_LANES (2 * IRDM_MAX_FORCE_NODES)
#define HEAD_SAMPLE 8 /* doubles */

struct head_lane {
	uint32_t col;        /* NO_COL: free */
	uint64_t first;      /* the lane's first sample (a count of samples applied) */
	uint64_t last_force; /* its newest sample with a force */
};

struct head_lanes {
	uint64_t applied;       /* samples applied since init or reset */
	uint64_t complete_from; /* a force found no free lane: the ring until then */
	struct head_lane lane[HEAD_LANES];
	double *f;         /* HEAD_LANES x H samples, fixed memory */
	const void *zeros; /* H blocks of zeros in any precision: a dropped block */
};

/* Where a lane's samples of ages s .. s + n - 1 are: at most two runs (they
 * wrap around the lane's end). */
struct head_run {
	const double *f; /* the first sample */
	uint32_t s, n;   /* its age, the number of samples */
};

struct head_span {
	uint32_t col; /* the lane's force column */
	uint32_t n_runs;
	struct head_run run[2];
};

struct irdm_engine {
	const struct irdm_image *img;
	struct irdm_engine_config cfg;
	double dt_s;
	uint32_t engage_ticks; /* cfg.engage_fade_s in ticks */
	uint32_t repr, n_nodes, n_cols, K, T;
	uint32_t H;                 /* modal: exact head samples (0: none; engine_head.c) */
	const uint32_t *col_of_row; /* n_nodes, NO_COL if not touchable */
	/* modal: arrays of Kp = K rounded up to a multiple of MODE_LANES
	 * modes, the padding modes zero (their shapes, A, b and state), so
	 * that the sums over modes run in whole groups of four */
	uint32_t Kp;
	const double *phi;            /* [col][3][Kp], converted at init */
	double *x;                    /* 2 Kp: (q, q') per mode, x[t] */
	double *y;                    /* 2 Kp: A x[t], the free evolution: kept
			    * with x (irdm_modal_apply()), so it is
			    * current between ticks too */
	const struct mode_coef *coef; /* Kp / 2: A and b of two modes each */
	bool modal_wide;              /* recursion and sums by engine_modal_avx2.c */
	/* FIR, and a modal image's exact head (ring of H ticks) */
	struct irdm_fir_ring ring;
	const double *tail_w; /* T: r^s tail damping (1 when stable) */
	bool fir_wide;        /* history sum by fir_sum_avx2.c */
	/* disp_bound.c: K (modal) max |phi_k| at a column, or T (FIR) max
	 * ||R[s]||_F over force columns and touchable rows; set at init */
	const double *bound_w;
	const double *head_bound_w; /* H: max ||D_s||_F over kept blocks */
	double *head_norm;          /* H: sum of |f| of each ring slot (0 if empty) */
	bool head_wide;             /* head sum by engine_head_avx2.c */
	struct head_lanes lanes;    /* head_lanes.c */
	/* contacts and solve */
	struct irdm_contact_state c[IRDM_MAX_CONTACTS];
	/* passivity observer (passivity.c): the work done on the object
	 * through ports that ended while others go on (zero once none is) */
	double port_energy_left_j;
	struct r0_table r0, r0_next;
	struct irdm_force_tick last; /* forces applied this tick */
	struct irdm_engine_stats stats;
	uint64_t tick;
	/* modal: free displacements of columns computed since the state last
	 * changed (stamp tick + 1; 0 empty): the proxy's surface and the
	 * contacts' history term ask for the same nodes in one tick */
	struct free_memo {
		uint64_t stamp;
		uint32_t col;
		double u[3];
	} free_memo[FREE_MEMO];
	bool faulted;
	const char *fault_why; /* the fault's reason, a constant string */
	struct irdm_deform *deform;
	/* floating objects: the rigid motion, integrated with the contact forces */
	bool floating;
	struct irdm_rigid_body rb;
	double com_rest_m[3]; /* body origin in the object frame */
};

/*
 * A pair of modes' recursion coefficients in the order the state is laid
 * out, (q_k, q'_k, q_k+1, q'_k+1): x = y + b g takes b, y = A x takes
 * (a00 a10) times q and (a01 a11) times q'.  Made at init from the image's
 * MODES (struct irdm_mode), so that four coefficients load as one vector.
 */
struct mode_coef {
	double b[4];  /* b0 b1 of mode k, of mode k + 1 */
	double aq[4]; /* a[0] a[2] of mode k, of mode k + 1 */
	double av[4]; /* a[1] a[3] of mode k, of mode k + 1 */
};

/*
 * A mode let go decays geometrically (|A_k| < 1) through the subnormal
 * range, where a multiply-add on a subnormal operand can cost a hundred
 * cycles on x86 (microcode assist); a released cuboid handed 10^6
 * subnormal displacements to the contact query in 600 s.
 * A state below 1e-200 (metres, metres per second) is no physics any
 * more: it is set to zero, where it stays until a force excites the mode.
 */
#define MODE_STATE_FLUSH 1e-200

/* The sums over modes run in groups of this many (the lanes of an AVX2
 * vector of doubles); Kp is K rounded up to it. */
#define MODE_LANES 4

/* engine_modal.c / engine_fir.c: the history term and the R[0] blocks. */
void irdm_modal_free_disp(const struct irdm_engine *e, uint32_t col, double u[3]);
void irdm_modal_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			   double (*u)[3]);
void irdm_modal_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9]);
void irdm_modal_apply(struct irdm_engine *e, const struct irdm_force_tick *f);
/* engine_modal_avx2.c: the modes' recursion, a column's kept-modes
 * displacement and their part of an R[0] block with AVX2 (modal_wide only), to the bit what the portable
 * loops of engine_modal.c give: the same products and sums in the same
 * order, none fused. */
void irdm_modal_recur_wide(struct irdm_engine *e, const struct irdm_force_tick *f);
void irdm_modal_disp_wide(const struct irdm_engine *e, uint32_t col, double u[3]);
void irdm_modal_r0_wide(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp,
			double s[9]);
void irdm_fir_free_disp(const struct irdm_engine *e, uint32_t col, double u[3]);
/* fir_sum.c: the free displacement at n <= IRDM_MAX_FORCE_NODES columns,
 * one pass over the ring for all of them. */
void irdm_fir_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			 double (*u)[3]);
/* fir_sum_avx2.c: the same sum with AVX2 + FMA, at n image rows (not
 * columns); only where irdm_wide_usable() said so at init. */
/* wide_usable.c: AVX2, FMA and F16C usable (CPUID and XCR0), for both wide sums */
bool irdm_wide_usable(void);
void irdm_fir_sum_wide(const struct irdm_engine *e, uint32_t n, const uint32_t *rows,
		       double (*u)[3]);
void irdm_fir_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9]);
void irdm_fir_apply(struct irdm_engine *e, const struct irdm_force_tick *f);
/* force_ring.c: f into a ring slot, each force times its column's storage
 * scale (irdm_image_col_scale()): the FIR and head sums read the stored
 * values unscaled.  Readers of the ring's forces divide it back out. */
void irdm_ring_put(const struct irdm_engine *e, struct irdm_force_tick *slot,
		   const struct irdm_force_tick *f);

/* engine_head.c: a modal image's exact head (H >= 1 only).  The kept
 * blocks from force columns to one column, looked up once a sum: the ring
 * holds the same few columns tick after tick. */
struct irdm_head_cache {
	uint32_t n;
	uint32_t col[IRDM_MAX_FORCE_NODES];
	long k[IRDM_MAX_FORCE_NODES];
};

static inline long irdm_head_cached_block(const struct irdm_engine *e, struct irdm_head_cache *c,
					  uint32_t col_force, uint32_t col_disp)
{
	for (uint32_t i = 0; i < c->n; i++)
		if (c->col[i] == col_force)
			return c->k[i];
	long k = irdm_image_corr_block(e->img, col_force, col_disp);
	if (c->n < IRDM_MAX_FORCE_NODES) {
		c->col[c->n] = col_force;
		c->k[c->n++] = k;
	}
	return k;
}

/* D_0 of the kept block into blk; false (blk untouched) if the block was dropped */
bool irdm_head_r0(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp, double blk[9]);
/* u[v] += the head sum at cols[v], n <= IRDM_MAX_FORCE_NODES distinct
 * columns; each column's figure is the same whether it is summed alone or
 * with others (a memo may hold either). */
void irdm_head_free_disps(const struct irdm_engine *e, uint32_t n, const uint32_t *cols,
			  double (*u)[3]);
void irdm_head_apply(struct irdm_engine *e, const struct irdm_force_tick *f);
void irdm_head_bound_init(const struct irdm_engine *e, double *w);
double irdm_head_bound(const struct irdm_engine *e, const double *w);
/* The ring's sum at one column, for while the lanes are incomplete; the
 * kept block of a force column to col, cached for the sum. */
void irdm_head_ring_sum(const struct irdm_engine *e, uint32_t col, double u[3]);
/* engine_head_avx2.c: the head sums with AVX2 + FMA (head_wide only). */
void irdm_head_ring_sum_wide(const struct irdm_engine *e, uint32_t col, double u[3]);
void irdm_head_lane_sums_wide(const struct irdm_engine *e, uint32_t n_spans,
			      const struct head_span *sp, uint32_t n, const uint32_t *cols,
			      double (*u)[3]);

/* head_lanes.c: the history by column (struct head_lanes). */
void irdm_head_lanes_init(struct irdm_engine *e, double *f, const void *zeros);
void irdm_head_lanes_reset(struct irdm_engine *e);
void irdm_head_lanes_apply(struct irdm_engine *e, const struct irdm_force_tick *f);
/* The lanes' samples the head sum reads now, into sp[HEAD_LANES]; the
 * number of spans, or -1 while the lanes miss a force (the ring then). */
int irdm_head_spans(const struct irdm_engine *e, struct head_span *sp);

/* disp_bound.c: fill bound_w (K or T doubles) once phi or the FIR is set. */
void irdm_bound_init(const struct irdm_engine *e, double *w);

/* solve.c: (W + C) F = rhs, n = 3 m unknowns, SPD up to regularisation.
 * Returns 1 if the system had to be regularised, 0 otherwise, -1 if it had
 * to be and the regularised F does not solve it (contradictory targets). */
int irdm_solve_spd(double *a, double *rhs, int n);

/* Contact c (a slot of e) ends: its port's energy stays with the object
 * (passivity.c). */
void tick_port_end(struct irdm_engine *e, struct irdm_contact_state *c);

#endif
