/* SPDX-License-Identifier: MIT */
/*
 * The precompute's own accuracy figure: an image's relative RMS force
 * error against the exact linear model of the same scene, measured with
 * the machinery irdm report also uses (this folder) on a few touchable columns.
 *
 * The columns: some spread over the touchable surface (farthest-point
 * sampling of their rest positions), the ones the caller screened as
 * likely worst (screen.h: the precompute, from the modes it dropped) and
 * the worst-conditioned ones (the largest recorded spectral radius).  At each, two runs of a grab contact
 * at that node, pushed along a fixed oblique direction:
 *   step:    pushed at tick 0 and held to the end;
 *   release: pushed for the first third, let go for the second, then
 *            grabbed again at its rest position: the force that holds it
 *            there is the free vibration the image left behind.
 * The figure is |F - F_ref|_2 / |F_ref|_2 over every tick of a run, first
 * ticks included, the worst of the columns and runs.
 *
 * The reference is the exact model: the scene's mesh, material and
 * damping rebuilt with every elastic mode (a dense eigensolve), no static
 * correction, in double, touchable at the sampled nodes only; its
 * responses read back for every sample and the forces solved by direct
 * convolution in double (accuracy/reference.h), not by the engine.  A
 * floating object's reference is that model run by the engine (the
 * convolution has no rigid motion).  The image under test runs in the
 * force engine as the firmware runs it, on its stored values.
 */
#ifndef IRDM_TOOLS_ACCURACY_MEASURE_H
#define IRDM_TOOLS_ACCURACY_MEASURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/image.h"
#include "accuracy/scenario.h"
#include "modal/modal.h"
#include "scene/scene.h"

#define IRDM_MEASURE_SPREAD 4    /* columns spread over the surface */
#define IRDM_MEASURE_SCREENED 12 /* the caller's likely worst, at most */
#define IRDM_MEASURE_WORST 2     /* and the largest spectral radii */
#define IRDM_MEASURE_MAX_COLS (IRDM_MEASURE_SPREAD + IRDM_MEASURE_SCREENED + IRDM_MEASURE_WORST)
/* error_columns = auto measures every touchable column up to this many
 * (accuracy/scan.h): the sample's exact model holds as many blocks, so
 * the scan costs no more */
#define IRDM_MEASURE_EVERY_AUTO (IRDM_MEASURE_MAX_COLS * IRDM_MEASURE_MAX_COLS)

struct irdm_measure {
	double error;                          /* the worst relative RMS force error */
	uint32_t worst_node;                   /* its column (mesh node) */
	const char *worst_run;                 /* "step" or "release" */
	size_t n_cols;                         /* columns measured */
	uint32_t nodes[IRDM_MEASURE_MAX_COLS]; /* their mesh nodes */
	size_t ticks;                          /* of each run */
	double seconds;                        /* the whole measurement */
};

/*
 * Writes the reference image of scene ref_sc (the exact model) at path; a
 * precompute that already holds every mode can make it from them.
 * Return: as irdm_precompute().
 */
typedef int (*irdm_measure_ref_fn)(void *ctx, const struct irdm_scene *ref_sc, const char *path,
				   char *err, size_t errlen);

/*
 * Measure img, made from sc.  The reference image is built at ref_path by
 * build_ref(ref_ctx, ...) (never NULL) and removed.
 * Return: IRDM_OK; IRDM_ENOMEM; IRDM_EINVAL if the reference is not the
 * same mesh; any error of irdm_precompute(), irdm_image_map(), the
 * convolution or the engine's set-up.  A one-line reason goes to err.
 */
int irdm_measure_error(const struct irdm_scene *sc, const struct irdm_image *img,
		       const char *ref_path, irdm_measure_ref_fn build_ref, void *ref_ctx,
		       irdm_progress_fn fn, void *ctx, struct irdm_measure *res,
		       char *err, size_t errlen);

/*
 * The same, measuring also the first IRDM_MEASURE_SCREENED of screened
 * (n_screened columns of img, likeliest worst first; repeats skipped).
 */
int irdm_measure_error_at(const struct irdm_scene *sc, const struct irdm_image *img,
			  const uint32_t *screened, size_t n_screened, const char *ref_path,
			  irdm_measure_ref_fn build_ref, void *ref_ctx, irdm_progress_fn fn,
			  void *ctx, struct irdm_measure *res, char *err, size_t errlen);

/*
 * k columns spread over positions pos ([n_pos][3]): farthest-point
 * sampling from the first.  cols: k entries.  Return: how many (fewer
 * when the positions repeat).
 */
size_t irdm_measure_spread(const double *pos, size_t n_pos, size_t k, uint32_t *cols);

/* The number of ticks each run lasts at dt_s: about a second. */
size_t irdm_measure_ticks(double dt_s);

/* The commands of one run (a step, or a release) of N ticks at image row
 * `row`: cmds, N of them. */
void irdm_measure_cmds(bool release, uint32_t row, size_t N, struct irdm_report_cmd *cmds);

/* |F - Fref|_2 / |Fref|_2 over n values (0 when both are zero, infinite
 * when only Fref is). */
double irdm_measure_rel_rms(const double *F, const double *Fref, size_t n);

/* The push, oblique so that every axis of the contact's 3x3 response is
 * excited; the model is linear: its size only sets the units. */
extern const double irdm_measure_push_m[3];

/* Tick t of a run of N: the contact holds the push (a step always, a
 * release its first third) ... */
static inline bool irdm_measure_held(bool release, size_t t, size_t N)
{
	return !release || t < N / 3;
}

/* ... and is on (a release lets go for the second third). */
static inline bool irdm_measure_active(bool release, size_t t, size_t N)
{
	return !release || t < N / 3 || t >= 2 * N / 3;
}

#endif
