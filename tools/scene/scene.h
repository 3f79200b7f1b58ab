/* SPDX-License-Identifier: MIT */
/*
 * A scene says what an image must hold: the object (mesh, material,
 * damping, constraints), the sample period, the representation, and which
 * nodes can be touched (columns) or are displayed (rows).  It is given as a
 * small "key = value" file, as --key value options, or both (options win).
 * The keys are one table (irdm_scene_options); docs/scene-format.md is
 * generated from it.
 */
#ifndef IRDM_TOOLS_SCENE_H
#define IRDM_TOOLS_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/options.h"
#include "fem/fem.h"
#include "irdm/error.h"
#include "modal/modal.h"

enum irdm_region_kind {
	IRDM_REGION_NONE = 0,
	IRDM_REGION_SURFACE, /* every boundary node */
	IRDM_REGION_PLANE,   /* coordinate <= or >= value */
	IRDM_REGION_BOX,     /* axis-aligned box, inclusive */
	IRDM_REGION_NODES,   /* explicit 0-based mesh node list */
};

#define IRDM_REGION_MAX_NODES 4096

struct irdm_region {
	enum irdm_region_kind kind;
	int axis;        /* PLANE: 0, 1, 2 */
	bool below;      /* PLANE: <= (true) or >= */
	double value_m;  /* PLANE */
	double box_m[6]; /* BOX: x0 y0 z0 x1 y1 z1 */
	size_t n_nodes;  /* NODES */
	uint32_t nodes[IRDM_REGION_MAX_NODES];
	char text[128]; /* as written, for messages and provenance */
};

/* The force error an image may have by default (scene key max_error). */
#define IRDM_MAX_ERROR_DEFAULT 1e-3
/* The largest exact head auto builds by default, MiB as stored (scene key
 * max_head_mib): stored by pairs, some 256 MiB of blocks.  The cap decides
 * image size, which auto's cheapest-tick order does not weigh: a lower tick
 * from a head twice the size is not worth it when every candidate ticks in
 * microseconds of a millisecond. */
#define IRDM_MAX_HEAD_MIB_DEFAULT 128.0

/* contacts: up to two at once are measured (accuracy/pairs.h) */
#define IRDM_SCENE_CONTACTS_MAX 2

enum irdm_damping_kind { IRDM_DAMP_RATIOS = 0,
			 IRDM_DAMP_RAYLEIGH = 1 };
enum irdm_method { IRDM_METHOD_MODAL = 0,
		   IRDM_METHOD_TIME_DOMAIN = 1 };

/* Where the force error is measured (scene key error_columns). */
enum irdm_error_columns { IRDM_ERROR_COLUMNS_AUTO = 0,   /* every one when it costs no more */
			  IRDM_ERROR_COLUMNS_SAMPLE = 1, /* spread, screened, worst-conditioned */
			  IRDM_ERROR_COLUMNS_EVERY = 2 };

struct irdm_scene {
	char name[64];
	char mesh[512];           /* "cuboid", "cube", "box:LX,LY,LZ" or a file path */
	unsigned res[3];          /* builtin resolution (hexes per axis) */
	unsigned tets_per_hex;    /* 5 or 6 */
	double mesh_scale;        /* multiplies file coordinates */
	char tetgen[32];          /* tetgen switches for surface meshes */
	bool tetgen_given;        /* set by the scene: then they win over the sizes */
	unsigned target_nodes;    /* surface meshes: about this many nodes (0: default) */
	double max_tet_volume_m3; /* surface meshes: largest tet (0: none) */
	struct irdm_material mat;
	enum irdm_mass_kind mass;
	bool symmetry; /* split a dense all-modes eigensolve by the model's symmetries */
	enum irdm_damping_kind damping;
	double damp_ratio[2];
	double damp_hz[2]; /* 0 for the first: "the first elastic mode" */
	struct irdm_rayleigh rayleigh;
	bool floating;
	struct irdm_region fixed;
	double dt_s;
	uint32_t representation; /* enum irdm_repr */
	bool repr_auto;          /* chosen by the precompute to meet max_error */
	unsigned fir_length;
	unsigned fir_tail; /* FIR: samples windowed past fir_length (0: none) */
	/* FIR, fir_tail = window (the default): the precompute chooses
	 * fir_tail, the shortest of 2T, 4T, ... 16T that certifies */
	bool fir_tail_auto;
	unsigned modes; /* modes kept (0 = all) */
	bool static_correction;
	double static_corr_tol;       /* drop blocks below tol sqrt(|S_cc| |S_rr|) */
	unsigned static_corr_rank;    /* far field of the dropped blocks: rank (0: none) */
	unsigned static_corr_cluster; /* nodes per cluster of the clustered correction (0: off) */
	unsigned exact_head;          /* modal: exact samples of the dropped modes' head (0: none; stored: 2x) */
	uint32_t precision;           /* enum irdm_elem */
	struct irdm_region touch;
	struct irdm_region display;
	enum irdm_method method;
	unsigned substeps;
	enum irdm_eig_method eigensolver;
	unsigned threads;
	bool uncertified;                      /* write an image whose stability certificate fails */
	double max_error;                      /* largest measured force error written (0: none, not measured) */
	enum irdm_error_columns error_columns; /* where max_error is measured */
	double max_head_mib;                   /* auto: the largest exact head it builds, MiB */
	double max_memory_mib;                 /* the precompute's memory budget, MiB (0: the machine's) */
	unsigned contacts;                     /* contacts at once max_error holds: 1, or 2 (the two-contact figure too) */
};

/* The defaults: the paper's cuboid at its resolution, modal 300 + static
 * correction, 1 ms, float32, top face touchable, whole surface displayed. */
void irdm_scene_defaults(struct irdm_scene *sc);

/* Every scene key: type, range, unit, help and where it goes in the struct. */
extern const struct irdm_opt_table irdm_scene_options;

/*
 * Set one key.  `where` names the source for messages ("cube.scene:7").
 * Return: IRDM_OK; IRDM_EINVAL if the key is unknown; IRDM_EFORMAT if the
 * value is invalid or out of range.
 */
int irdm_scene_set(struct irdm_scene *sc, const char *key, const char *value,
		   const char *where, char *err, size_t errlen);

/*
 * Read a scene file on top of *sc; messages name the line ("cube.scene:7").
 * Return: IRDM_OK; IRDM_EIO if the file cannot be opened or read;
 * IRDM_EINVAL for an unknown key; IRDM_EFORMAT for a line that is not
 * "key = value", too long, or has an invalid value.
 */
int irdm_scene_load(struct irdm_scene *sc, const char *path, char *err, size_t errlen);

/* Cross-field checks (after all keys are set).  Return: IRDM_OK;
 * IRDM_EINVAL naming the first conflict. */
int irdm_scene_check(const struct irdm_scene *sc, char *err, size_t errlen);

/* A surface mesh's node target when the scene names none (and no
 * max_tet_volume): a CAD part becomes a model of a few thousand nodes. */
#define IRDM_SCENE_TARGET_NODES 3000

/* cuboid, cube or box:...: generated, not read (no tetgen, no sizing). */
bool irdm_scene_builtin_mesh(const struct irdm_scene *sc);

/* The node target for a surface mesh: the scene's, or the default unless
 * the scene gives max_tet_volume (0: no target). */
unsigned irdm_scene_target_nodes(const struct irdm_scene *sc);

/* Canonical text of every key (provenance, scene hash). */
int irdm_scene_format(const struct irdm_scene *sc, char *buf, size_t len);

/* Whether mesh node i (position p) is in region r; on_surface: i is a
 * boundary node. */
bool irdm_region_contains(const struct irdm_region *r, uint32_t node, const double p[3],
			  bool on_surface);

#endif
