/* SPDX-License-Identifier: MIT */
/* Scene keys -> a scratch image, mapped. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/image_map.h"
#include "precompute/precompute.h"
#include "report/report_image.h"

/* "key=value key=value ..." onto the scene. */
static int set_keys(struct irdm_scene *sc, const char *keys, char *err, size_t errlen)
{
	char buf[1024], *save = NULL;

	if (snprintf(buf, sizeof(buf), "%s", keys) >= (int)sizeof(buf)) {
		snprintf(err, errlen, "report: key string too long: %.60s...", keys);
		return IRDM_EINVAL;
	}
	for (char *tok = strtok_r(buf, " \t", &save); tok; tok = strtok_r(NULL, " \t", &save)) {
		char *eq = strchr(tok, '=');
		int ret;

		if (!eq) {
			snprintf(err, errlen, "report: '%s' in '%s': expected key=value", tok, keys);
			return IRDM_EINVAL;
		}
		*eq = 0;
		ret = irdm_scene_set(sc, tok, eq + 1, "report", err, errlen);
		if (ret)
			return ret;
	}
	return IRDM_OK;
}

int irdm_report_image_build(struct irdm_report_image *ri, const char *dir, const char *name,
			    const char *const *keys, irdm_progress_fn fn, void *ctx,
			    char *err, size_t errlen)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { .progress = fn, .ctx = ctx };
	struct irdm_precompute_report rep;
	struct stat st;
	int ret;

	memset(ri, 0, sizeof(*ri));
	irdm_scene_defaults(&sc);
	/* the report measures uncertified representations too: it says so */
	sc.uncertified = true;
	sc.max_error = 0; /* and measures them itself, on more scenarios */
	snprintf(sc.name, sizeof(sc.name), "%s", name);
	for (size_t i = 0; keys[i]; i++) {
		ret = set_keys(&sc, keys[i], err, errlen);
		if (ret)
			return ret;
	}
	snprintf(ri->path, sizeof(ri->path), "%s/%s.img", dir, name);
	o.out_path = ri->path;
	ret = irdm_precompute(&sc, &o, &rep, err, errlen);
	if (ret)
		return ret;
	ret = irdm_image_map(ri->path, 0, &ri->img, err, errlen);
	if (ret)
		return ret;
	ri->bytes = stat(ri->path, &st) ? 0 : (size_t)st.st_size;
	return IRDM_OK;
}

void irdm_report_image_drop(struct irdm_report_image *ri, int keep)
{
	irdm_image_unmap(&ri->img);
	if (!keep && ri->path[0])
		unlink(ri->path);
}
