/* SPDX-License-Identifier: MIT */
/*
 * A session: an image, the force engine on it and, when asked, the
 * deformation channel the engine publishes to, set up and torn down in one
 * place.  Every program that runs the engine (the controller, replay, the
 * tests and benches) opens one instead of sizing, allocating and
 * initialising each part itself.
 *
 * irdm_session_open*() allocate, at init time only; the tick then runs on
 * the session's engine with no allocation (irdm/engine.h).  The deformation
 * worker (BLAS, a thread) is opened apart, by irdm_session_deform_open(),
 * which lives in its own object file: a program that never calls it links
 * with neither BLAS nor threads.
 *
 *	struct irdm_session_config sc = { .deform = false };
 *	struct irdm_session *s;
 *
 *	irdm_engine_config_default(&sc.engine);
 *	if (irdm_session_open(&s, "object.img", &sc, err, sizeof(err)))
 *		... err says why ...
 *	irdm_engine_site_node(s->eng, row, &site);
 *	... irdm_engine_tick(s->eng, cmd) ...
 *	irdm_session_close(s);
 */
#ifndef IRDM_SESSION_H
#define IRDM_SESSION_H

#include <stdbool.h>
#include <stddef.h>

#include "irdm/deform.h"
#include "irdm/engine.h"
#include "irdm/error.h"
#include "irdm/image.h"

struct irdm_deform_worker;

struct irdm_session_config {
	struct irdm_engine_config engine;
	/* also a deformation channel, attached to the engine (it publishes
	 * every engine.publish_every ticks) */
	bool deform;
	/* irdm_image_map() flags (IRDM_IMAGE_MAP_*); irdm_session_open() only */
	unsigned map_flags;
};

/* Read-only for the caller; valid from open to close. */
struct irdm_session {
	const struct irdm_image *img;       /* the session's mapping, or the caller's image */
	struct irdm_engine *eng;
	struct irdm_deform *deform;         /* NULL unless config.deform */
	struct irdm_deform_worker *worker;  /* NULL until irdm_session_deform_open() */

	/* private */
	struct irdm_image mapped;
	void *eng_mem, *deform_mem, *worker_mem;
};

/*
 * Map and validate the image at path, then set up as
 * irdm_session_open_image() does.  The session unmaps it on close.
 *
 * Return: IRDM_OK;
 * any error of irdm_image_map() (IRDM_EIO, IRDM_ETRUNC, IRDM_EMAGIC,
 * IRDM_EVERSION, IRDM_ECRC, IRDM_ERANGE, IRDM_EMISSING, IRDM_EFORMAT);
 * otherwise as irdm_session_open_image().
 * On error *s is NULL, nothing is left mapped or allocated, and err says why.
 */
int irdm_session_open(struct irdm_session **s, const char *path,
		      const struct irdm_session_config *cfg, char *err, size_t errlen);

/*
 * A session on an image the caller has mapped or parsed (borrowed: it must
 * stay valid until irdm_session_close(), which leaves it alone).  Allocates
 * and initialises the engine with cfg->engine and, if cfg->deform, the
 * deformation channel, attached to the engine.
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if cfg->engine is not valid for this image (irdm_engine_init()),
 * or cfg->deform and the image is not a usable FIR or modal image;
 * IRDM_ENOMEM if an allocation failed.
 * On error *s is NULL, nothing is left allocated, and err says why.
 */
int irdm_session_open_image(struct irdm_session **s, const struct irdm_image *img,
			    const struct irdm_session_config *cfg, char *err, size_t errlen);

/*
 * The deformation worker (irdm/deform_worker.h) on the session's channel,
 * in memory the session frees on close.  Its own object file: calling it
 * links BLAS and threads.  A deformation thread started on s->worker must
 * be stopped before irdm_session_close().
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if the session has no deformation channel (config.deform was
 * false) or its image is not one the update can read;
 * IRDM_EBUSY if the session already has a worker;
 * IRDM_ENOMEM if the allocation failed.
 */
int irdm_session_deform_open(struct irdm_session *s, char *err, size_t errlen);

/* Free everything the session holds, and unmap what it mapped.  NULL is fine. */
void irdm_session_close(struct irdm_session *s);

#endif /* IRDM_SESSION_H */
