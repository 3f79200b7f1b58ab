/* SPDX-License-Identifier: MIT */
/*
 * What the steps of one tick share: the contact system and the functions of
 * the files that hold each step (docs/architecture.md, "Where each step
 * lives").  Private to firmware/engine.
 */
#ifndef IRDM_TICK_PRIV_H
#define IRDM_TICK_PRIV_H

#include "irdm/build_config.h"

#include "engine_priv.h"

struct system {
	int m;                                /* active contacts */
	unsigned idx[IRDM_MAX_CONTACTS];      /* their slots */
	double u_body[IRDM_MAX_CONTACTS][3];  /* history term, object (body) frame */
	double w_body[MAX_SOLVE * MAX_SOLVE]; /* W in the object frame */
	/* in the solve frame: the object frame, or the world for a floating object */
	double u_free[IRDM_MAX_CONTACTS][3];
	double normal[IRDM_MAX_CONTACTS][3];
	double w[MAX_SOLVE * MAX_SOLVE]; /* row-major 3m x 3m */
	double f[MAX_SOLVE];
	double f_body[MAX_SOLVE];
	bool contradictory;                 /* the targets cannot all be met (solve.c) */
	double x_now[IRDM_MAX_CONTACTS][3]; /* floating: world position of each point */
	/* The free displacement of each distinct site node this tick, summed
	 * once (the history does not change within a tick; a node two
	 * contacts share is summed once) and read by the history terms and
	 * the per-vertex solve. */
	uint32_t n_free;
	uint32_t free_col[IRDM_MAX_FORCE_NODES];
	double free_u[IRDM_MAX_FORCE_NODES][3];
};

/* The index of col among cols[0 .. *n), appended (and *n grown) if missing:
 * the distinct columns of the contact sites. */
static inline uint32_t tick_col_slot(uint32_t *cols, uint32_t *n, uint32_t col)
{
	uint32_t k = 0;

	while (k < *n && cols[k] != col)
		k++;
	if (k == *n)
		cols[(*n)++] = col;
	return k;
}

/* r0_table.c */
void tick_r0_refresh(struct irdm_engine *e, const unsigned *idx, int m);
const double *tick_r0_block(const struct irdm_engine *e, uint32_t col_force, uint32_t col_disp);

/* contact_system.c */
void tick_free_disp(const struct irdm_engine *e, const struct system *s, uint32_t col,
		    double u[3]);
void tick_history_terms(struct irdm_engine *e, struct system *s);
void tick_assemble(struct irdm_engine *e, struct system *s);
void tick_contact_disp(const struct system *s, int i, double u[3]);

/* engage.c: the commands with each softly engaging contact's anchor moved
 * back by its fading offset (into eff), or cmd itself when none fades. */
const struct irdm_contact_cmd *tick_engage(struct irdm_engine *e, const struct system *s,
					   const struct irdm_contact_cmd *cmd,
					   struct irdm_contact_cmd *eff);

/* floating.c; a build without floating objects (irdm/build_config.h) has
 * none: the engine refuses their images, and these are never reached */
#if IRDM_CONFIG_FLOATING
#define FLOATING(e) ((e)->floating)
void tick_to_world(struct irdm_engine *e, struct system *s);
void tick_floating_disp(const struct irdm_engine *e, const struct system *s, int i, double d[3]);
void tick_newton_floating(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd);
int tick_move_rigid(struct irdm_engine *e, const struct system *s);

/* The floating object's pose; false for a grounded one. */
static inline bool tick_pose(const struct irdm_engine *e, struct irdm_pose *pose)
{
	if (!e->floating)
		return false;
	irdm_rigid_pose(&e->rb, pose);
	return true;
}
#else
static inline bool tick_pose(const struct irdm_engine *e, struct irdm_pose *pose)
{
	(void)e, (void)pose;
	return false;
}

#define FLOATING(e) ((void)(e), false)
static inline void tick_to_world(struct irdm_engine *e, struct system *s)
{
	(void)e, (void)s;
}

static inline void tick_floating_disp(const struct irdm_engine *e, const struct system *s, int i,
				      double d[3])
{
	(void)e, (void)s, (void)i, (void)d;
}

static inline void tick_newton_floating(struct irdm_engine *e, struct system *s,
					const struct irdm_contact_cmd *cmd)
{
	(void)e, (void)s, (void)cmd;
}

static inline int tick_move_rigid(struct irdm_engine *e, const struct system *s)
{
	(void)e, (void)s;
	return 0;
}
#endif

/* contact_solve.c */
void tick_solve(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd);
void tick_release_pulling(struct irdm_engine *e, struct system *s, const struct irdm_contact_cmd *cmd);

/* passivity.c */
void tick_passivity(struct irdm_engine *e, struct system *s);
/* After a tick with m ports active: none left, the observation ends. */
void tick_port_leak(struct irdm_engine *e, int m);

#endif
