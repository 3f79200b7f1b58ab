/* SPDX-License-Identifier: MIT */
/*
 * Session set-up: image, engine and deformation channel, each sized,
 * allocated and initialised here, and freed in one place.  No BLAS, no
 * threads, no file: the platform maps the image and runs the worker
 * (platform/posix/session/).
 */
#include <stdio.h>
#include <stdlib.h>

#include "irdm/build_config.h"

#include "irdm/session.h"

#define SESSION_ALIGN 64u

int irdm_session_part_mem(void **mem, size_t n, const char *part, char *err, size_t errlen)
{
	*mem = NULL;
	if (!n)
		return IRDM_OK;
	*mem = aligned_alloc(SESSION_ALIGN, (n + SESSION_ALIGN - 1) & ~(size_t)(SESSION_ALIGN - 1));
	if (!*mem) {
		snprintf(err, errlen, "%s: out of memory (%zu bytes)", part, n);
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

static int open_engine(struct irdm_session *s, const struct irdm_engine_config *cfg,
		       char *err, size_t errlen)
{
	size_t n = irdm_engine_mem_size(s->img, cfg);
	int rc = irdm_session_part_mem(&s->eng_mem, n, "engine", err, errlen);

	if (rc)
		return rc;
	return irdm_engine_init(&s->eng, s->img, cfg, s->eng_mem, n, err, errlen);
}

static int open_deform(struct irdm_session *s, char *err, size_t errlen)
{
#if IRDM_CONFIG_DEFORM
	size_t n = irdm_deform_mem_size(s->img);
	int rc = irdm_session_part_mem(&s->deform_mem, n, "deform", err, errlen);

	if (!rc)
		rc = irdm_deform_init(&s->deform, s->img, s->deform_mem, n, err, errlen);
	if (!rc)
		irdm_engine_attach_deform(s->eng, s->deform);
	return rc;
#else
	(void)s;
	snprintf(err, errlen, "session: the deformed surface is asked for (a board's "
			      "deform_rate_hz > 0); this build has CONFIG_IRDM_DEFORM off (docs/build-config.md)");
	return IRDM_ENOTSUP;
#endif
}

/*
 * The contact surface, when the image has one: its face-beyond table is
 * made here so that the force loop never searches the surface.
 */
static int open_contact(struct irdm_session *s, char *err, size_t errlen)
{
	int rc;

	if (irdm_contact_mesh_init(&s->cm, s->img))
		return IRDM_OK; /* no CONTACT_BVH: the engine alone */
	rc = irdm_session_part_mem(&s->contact_mem, irdm_contact_beyond_size(&s->cm), "contact",
				   err, errlen);
	if (rc)
		return rc;
	irdm_contact_beyond_build(&s->cm, s->contact_mem);
	return IRDM_OK;
}

/*
 * The parts on s->img; then s is the caller's.  On error everything goes,
 * the mapping too if the session made it.
 */
static int open_parts(struct irdm_session **sp, struct irdm_session *s,
		      const struct irdm_session_config *cfg, char *err, size_t errlen)
{
	int rc = open_engine(s, &cfg->engine, err, errlen);

	if (!rc)
		rc = open_contact(s, err, errlen);
	if (!rc && cfg->deform)
		rc = open_deform(s, err, errlen);
	if (rc) {
		irdm_session_close(s);
		return rc;
	}
	*sp = s;
	return IRDM_OK;
}

static struct irdm_session *new_session(char *err, size_t errlen)
{
	struct irdm_session *s = calloc(1, sizeof(*s));

	if (!s)
		snprintf(err, errlen, "session: out of memory");
	return s;
}

int irdm_session_open_image(struct irdm_session **sp, const struct irdm_image *img,
			    const struct irdm_session_config *cfg, char *err, size_t errlen)
{
	struct irdm_session *s;

	*sp = NULL;
	if (!img || !img->meta || !cfg) {
		snprintf(err, errlen, "session: no image or no configuration");
		return IRDM_EINVAL;
	}
	s = new_session(err, errlen);
	if (!s)
		return IRDM_ENOMEM;
	s->img = img;
	return open_parts(sp, s, cfg, err, errlen);
}

int irdm_session_open_with(struct irdm_session **sp, const char *path,
			   const struct irdm_session_config *cfg,
			   int (*map)(const char *path, unsigned flags, struct irdm_image *img,
				      char *err, size_t errlen),
			   void (*unmap)(struct irdm_image *img), char *err, size_t errlen)
{
	struct irdm_session *s;
	int rc;

	*sp = NULL;
	if (!path || !cfg) {
		snprintf(err, errlen, "session: no image path or no configuration");
		return IRDM_EINVAL;
	}
	s = new_session(err, errlen);
	if (!s)
		return IRDM_ENOMEM;
	rc = map(path, cfg->map_flags, &s->mapped, err, errlen);
	if (rc) {
		free(s);
		return rc;
	}
	s->img = &s->mapped;
	s->unmap = unmap;
	return open_parts(sp, s, cfg, err, errlen);
}

void irdm_session_close(struct irdm_session *s)
{
	if (!s)
		return;
	free(s->worker_mem);
	free(s->deform_mem);
	free(s->eng_mem);
	free(s->contact_mem);
	if (s->img == &s->mapped && s->unmap)
		s->unmap(&s->mapped);
	free(s);
}
