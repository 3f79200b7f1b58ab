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

#include "irdm/contact.h"
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
	const struct irdm_image *img; /* the session's mapping, or the caller's image */
	struct irdm_engine *eng;
	struct irdm_deform *deform;        /* NULL unless config.deform */
	struct irdm_deform_worker *worker; /* NULL until irdm_session_deform_open() */
	/* the image's contact surface with its face-beyond table, made at
	 * open; cm.hdr NULL: the image has no CONTACT_BVH */
	struct irdm_contact_mesh cm;

	/* private */
	struct irdm_image mapped;
	void (*unmap)(struct irdm_image *img); /* of mapped; NULL: borrowed image */
	void *eng_mem, *deform_mem, *worker_mem, *contact_mem;
};

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
 * As irdm_session_open_image(), on the image that map(path, cfg->map_flags,
 * ...) fills in the session's own memory; close hands it to unmap.  The
 * platform supplies the pair (irdm_session_open(), irdm/posix/session.h).
 *
 * Return: IRDM_OK;
 * IRDM_EINVAL if path or cfg is NULL; IRDM_ENOMEM; any error of map;
 * otherwise as irdm_session_open_image().
 * On error *s is NULL, nothing is left mapped or allocated, and err says why.
 */
int irdm_session_open_with(struct irdm_session **s, const char *path,
			   const struct irdm_session_config *cfg,
			   int (*map)(const char *path, unsigned flags, struct irdm_image *img,
				      char *err, size_t errlen),
			   void (*unmap)(struct irdm_image *img), char *err, size_t errlen);

/*
 * Memory for one part of the session: *mem = n bytes, cache-line aligned
 * (the engine wants 16; 64 keeps a part's hot data off its neighbour's
 * lines).  n == 0 means the part's size call refused the image or the
 * configuration: nothing is allocated and IRDM_OK returned, so that the
 * part's init, given no memory, says why.
 *
 * For the session's parts that live apart (the platform's deformation
 * worker: irdm/posix/session.h).
 *
 * Return: IRDM_OK; IRDM_ENOMEM (err says which part) if allocation failed.
 */
int irdm_session_part_mem(void **mem, size_t n, const char *part, char *err, size_t errlen);

/* Free everything the session holds, and unmap what it mapped.  NULL is fine. */
void irdm_session_close(struct irdm_session *s);

#endif /* IRDM_SESSION_H */
