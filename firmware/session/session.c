/* SPDX-License-Identifier: MIT */
/*
 * Session set-up: image, engine and deformation channel, each sized,
 * allocated and initialised here, and freed in one place.  No BLAS, no
 * threads: the worker is session_deform.c's.
 */
#include <stdio.h>
#include <string.h>

#include "session_priv.h"

static int open_engine(struct irdm_session *s, const struct irdm_engine_config *cfg,
		       char *err, size_t errlen)
{
	size_t n = irdm_engine_mem_size(s->img, cfg);

	/* size 0: the configuration does not fit; init says which way */
	if (!n)
		return irdm_engine_init(&s->eng, s->img, cfg, NULL, 0, err, errlen);
	s->eng_mem = session_alloc(n);
	if (!s->eng_mem) {
		snprintf(err, errlen, "engine: out of memory (%zu bytes)", n);
		return IRDM_ENOMEM;
	}
	return irdm_engine_init(&s->eng, s->img, cfg, s->eng_mem, n, err, errlen);
}

static int open_deform(struct irdm_session *s, char *err, size_t errlen)
{
	size_t n = irdm_deform_mem_size(s->img);
	int rc;

	if (!n)
		return irdm_deform_init(&s->deform, s->img, NULL, 0, err, errlen);
	s->deform_mem = session_alloc(n);
	if (!s->deform_mem) {
		snprintf(err, errlen, "deform: out of memory (%zu bytes)", n);
		return IRDM_ENOMEM;
	}
	rc = irdm_deform_init(&s->deform, s->img, s->deform_mem, n, err, errlen);
	if (!rc)
		irdm_engine_attach_deform(s->eng, s->deform);
	return rc;
}

/* s->img is set; the rest of s is zero. */
static int open_parts(struct irdm_session *s, const struct irdm_session_config *cfg,
		      char *err, size_t errlen)
{
	int rc = open_engine(s, &cfg->engine, err, errlen);

	if (!rc && cfg->deform)
		rc = open_deform(s, err, errlen);
	return rc;
}

int irdm_session_open_image(struct irdm_session **sp, const struct irdm_image *img,
			    const struct irdm_session_config *cfg, char *err, size_t errlen)
{
	struct irdm_session *s;
	int rc;

	*sp = NULL;
	if (!img || !img->meta || !cfg) {
		snprintf(err, errlen, "session: no image or no configuration");
		return IRDM_EINVAL;
	}
	s = calloc(1, sizeof(*s));
	if (!s) {
		snprintf(err, errlen, "session: out of memory");
		return IRDM_ENOMEM;
	}
	s->img = img;
	rc = open_parts(s, cfg, err, errlen);
	if (rc)
		goto out_close;
	*sp = s;
	return IRDM_OK;
out_close:
	irdm_session_close(s);
	return rc;
}

int irdm_session_open(struct irdm_session **sp, const char *path,
		      const struct irdm_session_config *cfg, char *err, size_t errlen)
{
	struct irdm_session *s;
	int rc;

	*sp = NULL;
	if (!path || !cfg) {
		snprintf(err, errlen, "session: no image path or no configuration");
		return IRDM_EINVAL;
	}
	s = calloc(1, sizeof(*s));
	if (!s) {
		snprintf(err, errlen, "session: out of memory");
		return IRDM_ENOMEM;
	}
	rc = irdm_image_map(path, cfg->map_flags, &s->mapped, err, errlen);
	if (rc)
		goto out_close;
	s->img = &s->mapped;
	rc = open_parts(s, cfg, err, errlen);
	if (rc)
		goto out_close;
	*sp = s;
	return IRDM_OK;
out_close:
	irdm_session_close(s);
	return rc;
}

void irdm_session_close(struct irdm_session *s)
{
	if (!s)
		return;
	free(s->worker_mem);
	free(s->deform_mem);
	free(s->eng_mem);
	if (s->img == &s->mapped)
		irdm_image_unmap(&s->mapped);
	free(s);
}
