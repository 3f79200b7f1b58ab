/* SPDX-License-Identifier: MIT */
/*
 * The IRDM force engine: from contact displacements (or device positions
 * through a virtual coupling) to contact forces, one tick at a time, with
 * the force history of a mapped image (FIR ring or exact modal states).
 *
 * One struct owned by the caller, sized by irdm_engine_mem_size() and
 * initialised once in caller-provided memory; irdm_engine_tick() then never
 * allocates, blocks, or makes a system call.  It is *given* the contact
 * targets of the tick; it reads no clock.
 *
 * Frames and signs (docs/architecture.md, "Frames and signs" and "Sample
 * convention"): positions in metres in the object frame (for a floating
 * object: targets, forces and contact displacements in the world frame,
 * which coincides with the object frame at start); a contact's force is the
 * force applied TO the object (the device renders its negative); the
 * displacement u[t] is observed at (t+1) dt.
 */
#ifndef IRDM_ENGINE_H
#define IRDM_ENGINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/contact.h" /* struct irdm_contact_site */
#include "irdm/error.h"
#include "irdm/image.h"
#include "irdm/limits.h" /* IRDM_MAX_CONTACTS */

enum irdm_solve_mode {
	IRDM_SOLVE_COUPLED = 0,    /* all contact points in one system (default) */
	IRDM_SOLVE_PER_VERTEX = 1, /* the paper's eq. 10-11, each contact alone */
};

enum irdm_contact_mode {
	IRDM_CONTACT_OFF = 0,
	IRDM_CONTACT_PUSH = 1, /* unilateral: released when the object would pull */
	IRDM_CONTACT_GRAB = 2, /* bilateral: held until released */
};

struct irdm_engine_config {
	unsigned max_contacts; /* 1..IRDM_MAX_CONTACTS */
	enum irdm_solve_mode solve;
	/*
	 * Virtual coupling between the target (device) and the contact point:
	 * F = k (p - u) + b ((p - p') - (u - u')) / dt.  k = 0 means rigid:
	 * the target IS the contact displacement (eq. 8; replay, references).
	 */
	double coupling_k_n_per_m;
	double coupling_b_ns_per_m;
	/* Hannaford-Ryu passivity observer/controller at each contact port. */
	bool passivity_control;
	/* The most damping the controller may add (N s/m; 0: unbounded).  A
	 * virtual damper beyond the device's own damping margin makes the
	 * sampled loop active (Colgate), so the haptic default bounds it by
	 * what the coupling leaves of that margin. */
	double passivity_max_damping_ns_per_m;
	/*
	 * Unstable recursions are never run unprotected: an FIR image whose
	 * largest recorded spectral radius (meta max_spectral_radius) is >= 1
	 * gets the tail of every column damped by w[s] = r^s, r =
	 * stable_radius / that radius, so that its radius becomes <=
	 * stable_radius (<1).  This distorts the response from the first
	 * sample; an image made with fir_tail = window:L is stable as stored
	 * and runs undamped.  0 = IRDM_ENGINE_STABLE_RADIUS.
	 */
	double stable_radius;
	double max_force_n; /* > 0: a larger force faults the engine (torque off) */
	/* sum an FIR history, a hybrid image's head and the modes'
	 * recursion with the portable code even on a processor with AVX2
	 * and FMA (the history sums agree to rounding, the modes' to the
	 * bit; tests compare them) */
	bool fir_portable_sum;
	unsigned publish_every; /* deformation snapshot every N ticks (0: never) */
	/*
	 * A contact begun with irdm_engine_contact_soften() (the tool already
	 * inside the object: out of a fault, at enable) starts at zero force
	 * and reaches the full coupling over this time (seconds; 0: at once).
	 * Only a coupled contact (k > 0) fades; a rigid one is its target.
	 */
	double engage_fade_s;
};

/* The default re-engagement fade (irdm_engine_config_default()): long
 * against a hand's reaction (~0.1 s), short against a user's patience. */
#define IRDM_ENGINE_ENGAGE_FADE_S 0.25
/* The default stable_radius, also what 0 asks for: just inside the unit
 * circle, so the damping distorts the response as little as it can. */
#define IRDM_ENGINE_STABLE_RADIUS 0.999
/* The longest fade a configuration may ask for (seconds). */
#define IRDM_ENGINE_ENGAGE_FADE_MAX_S 10.0

/* One contact's command for a tick. */
struct irdm_contact_cmd {
	enum irdm_contact_mode mode;
	/* target displacement of the contact point from its rest position (k = 0)
	 * or device position minus the contact's rest position (k > 0) */
	double target_m[3];
};

struct irdm_contact_state {
	enum irdm_contact_mode mode; /* OFF after a push released */
	struct irdm_contact_site site;
	double force_n[3]; /* on the object this tick */
	double disp_m[3];  /* contact point displacement u[t] */
	double target_prev_m[3];
	double disp_prev_m[3];
	double port_energy_j;       /* passivity observer: work done on the object */
	double port_disp_prev_m[3]; /* the observer's last displacement: before
					 * its controller's force, like this tick's */
	double pc_damping_ns_per_m; /* passivity controller's damping this tick */
	uint32_t fresh;             /* began since the last tick */
	/* soft engagement (irdm_engine_contact_soften()): the coupling's
	 * anchor is target - offset * w, w falling from 1 to 0 over the fade */
	uint32_t engage_ticks;     /* the fade's length in ticks (0: none) */
	uint32_t engage_done;      /* ticks of it gone */
	double engage_offset_m[3]; /* target - free displacement at its start */
};

struct irdm_engine_stats {
	uint64_t ticks;
	uint64_t releases;        /* push contacts released */
	uint64_t singular_solves; /* regularised coupled systems */
	uint64_t pc_activations;  /* passivity controller added damping */
};

struct irdm_engine; /* opaque; lives in the caller's memory */

/* Bytes irdm_engine_init() needs (0 on invalid configuration). */
size_t irdm_engine_mem_size(const struct irdm_image *img, const struct irdm_engine_config *cfg);

/* Defaults: 2 contacts, coupled, rigid coupling, no PC, IRDM_ENGINE_STABLE_RADIUS, no
 * force limit, no snapshots, IRDM_ENGINE_ENGAGE_FADE_S. */
void irdm_engine_config_default(struct irdm_engine_config *cfg);

/*
 * Virtual coupling from a device's limits (Colgate & Schenkel: passive iff
 * b_device > K T / 2 + |B|): the stiffest K <= k_max_n_per_m that leaves
 * half of the device's damping margin, and B = the other half.
 */
void irdm_engine_coupling_for_device(double k_max_n_per_m, double b_device_ns_per_m,
				     double dt_s, double *k_n_per_m, double *b_ns_per_m);

/*
 * The haptic default: a virtual coupling sized from the device (above),
 * the passivity controller on, and the device's force limit.  A device
 * described by CHAI3D's PHANToM Desktop figures: 1000 N/m, 7.9 N; its
 * damping margin b_device (N s/m) bounds the coupling (Colgate).
 */
void irdm_engine_config_haptic(struct irdm_engine_config *cfg, double dt_s, double k_max_n_per_m,
			       double b_device_ns_per_m, double max_force_n);

/*
 * Initialise in `mem` (16-byte aligned, at least irdm_engine_mem_size()
 * bytes, pre-faulted by this call).  The image must stay mapped.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if img is NULL or has no metadata, cfg is not valid (contacts
 * 1..IRDM_MAX_CONTACTS, coupling >= 0, stable radius in [0, 1), force
 * limit >= 0, a known solve mode, a fade in [0, IRDM_ENGINE_ENGAGE_FADE_MAX_S]), or the image's rigid-body section is not
 * usable (irdm_rigid_init());
 * IRDM_ENOMEM if mem is NULL, not 16-byte aligned or smaller than
 * irdm_engine_mem_size().
 * On error *eng is NULL and err says why.
 */
int irdm_engine_init(struct irdm_engine **eng, const struct irdm_image *img,
		     const struct irdm_engine_config *cfg, void *mem, size_t mem_size,
		     char *err, size_t errlen);

/*
 * Contact sites (init-time helpers; they do not allocate either).
 *
 * The site of image node `image_node` (a row index), with the area-weighted
 * normal of the surface triangles around it.
 *
 * Return: IRDM_OK;
 * IRDM_ECONTACT if image_node is out of range or not a column.
 */
int irdm_engine_site_node(const struct irdm_engine *eng, uint32_t image_node,
			  struct irdm_contact_site *site);

/*
 * The site of the point of barycentric weights bary on SURFACE triangle tri.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if the weights do not sum to 1 (to 1e-9) or one is negative;
 * IRDM_ECONTACT if tri is out of range, the triangle has no area, or (modal
 * images) a vertex of positive weight is not a column yet moves (a non-zero
 * mode shape).
 */
int irdm_engine_site_point(const struct irdm_engine *eng, uint32_t tri, const double bary[3],
			   struct irdm_contact_site *site);

/*
 * Begin a contact in slot i (0..max_contacts-1), or move an active one to a
 * new site (sliding: it keeps its past target, displacement and energy).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if i >= max_contacts, site is NULL or has no 1..3 nodes, or
 * mode is neither IRDM_CONTACT_PUSH nor IRDM_CONTACT_GRAB.
 */
int irdm_engine_contact_begin(struct irdm_engine *eng, unsigned i,
			      const struct irdm_contact_site *site, enum irdm_contact_mode mode);

/*
 * Let the contact begun in slot i since the last tick engage softly: the
 * tool is already inside the object (out of a fault, at enable), so the
 * virtual coupling's anchor starts at the contact point (zero force) and
 * moves to the target over engage_fade_s along a raised cosine (no jump in
 * force or in the damper's velocity at either end).  Sliding during the
 * fade keeps it.  A hard engagement would pull the spring's whole depth at
 * once, and the object's rebound then releases and re-touches the push.
 *
 * The energy the moving anchor can hand the object is at most
 * |offset| (k |offset| + b pi |offset| / (2 engage_fade_s)), the largest
 * coupling force times the anchor's path.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if i >= max_contacts or slot i holds no contact begun since
 * the last tick.
 */
int irdm_engine_contact_soften(struct irdm_engine *eng, unsigned i);

/* End the contact in slot i (any i: out of range does nothing). */
void irdm_engine_contact_end(struct irdm_engine *eng, unsigned i);

/*
 * One tick: cmd[i] for each slot (mode OFF = no contact).  Solves the
 * contact forces, advances the history, optionally publishes a snapshot.
 *
 * Return: IRDM_OK;
 * IRDM_EFAULT if a target is not finite or beyond IRDM_MAX_TARGET_M, the
 * targets contradict each other (rigid contacts on one node, or on fixed
 * nodes, asked for displacements no force can give), a force is not finite
 * or over max_force_n, or a floating object's rigid step failed, or the
 * engine had already faulted: it then holds zero force until
 * irdm_engine_reset().
 */
int irdm_engine_tick(struct irdm_engine *eng, const struct irdm_contact_cmd *cmd);

/* The state of slot i, or NULL if i >= IRDM_MAX_CONTACTS. */
const struct irdm_contact_state *irdm_engine_contact(const struct irdm_engine *eng, unsigned i);
const struct irdm_engine_stats *irdm_engine_stats(const struct irdm_engine *eng);

/* Why the engine faulted (a constant sentence), or NULL if it has not. */
const char *irdm_engine_fault_reason(const struct irdm_engine *eng);

/* Which history sum the engine runs, of an FIR image or of a hybrid image's
 * head: "avx2" (fir_sum_avx2.c or engine_head_avx2.c, chosen at init where
 * the processor has AVX2, FMA and F16C), "portable", or "none" (a modal
 * image without a head). */
const char *irdm_engine_fir_sum_name(const struct irdm_engine *eng);

/*
 * Points between the world frame and the object's own frame (the frame of
 * the image's rest nodes, which node displacements and sites use).  A
 * floating object has moved and turned since the start: world_to_object
 * undoes its rigid motion so far, object_to_world applies it; for a
 * grounded object both copy.  A contact query (the proxy) runs in the
 * object frame; targets stay in the world frame (above).
 */
void irdm_engine_world_to_object(const struct irdm_engine *eng, const double x_world_m[3],
				 double p_obj_m[3]);
void irdm_engine_object_to_world(const struct irdm_engine *eng, const double p_obj_m[3],
				 double x_world_m[3]);

/* The floating object's rigid body (its pose, velocities, momentum:
 * irdm/rigid.h), read-only; NULL for a grounded object or a build without
 * floating objects. */
struct irdm_rigid_body;
const struct irdm_rigid_body *irdm_engine_rigid_body(const struct irdm_engine *eng);

/* Free response of image node `row` (a column): its displacement at the
 * next sample if no new force acts (object frame, without rigid motion).
 * The surface a new contact meets.  Zero for nodes that are not columns. */
void irdm_engine_node_disp(const struct irdm_engine *eng, uint32_t row, double u_m[3]);

/*
 * An upper bound (metres) on |u| of every touchable node for the free
 * response irdm_engine_node_disp() returns in the engine's current state
 * (a true bound up to rounding, which it covers): modal images
 * sum_k max_v |phi_v,k| |yq_k|, FIR images sum_s w[s] max ||R[s]||_F
 * sum_e |f_e[t-s]| (a bound from the force history, not a constant).
 * O(modes), or O(FIR length x force nodes); no allocation.  A
 * closest-point query may grow its boxes by this instead of a fixed guess.
 */
double irdm_engine_disp_bound(const struct irdm_engine *eng);

/* Publish snapshots to a deformation context (init-time). */
struct irdm_deform;
void irdm_engine_attach_deform(struct irdm_engine *eng, struct irdm_deform *d);

/* Zero the history and all contacts (out of a fault). */
void irdm_engine_reset(struct irdm_engine *eng);

#endif /* IRDM_ENGINE_H */
