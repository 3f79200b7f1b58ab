/* SPDX-License-Identifier: MIT */
/*
 * irdm view DIR: a directory irdm render wrote (tools/render/: frames.pvd
 * and its frame_NNNNN.vtu, ASCII) as the view's recording.  Such a
 * directory holds the surface and each contact's point and force per
 * frame, not the controller: the frames carry no state (the page says
 * "surface only") and the chart only the forces, one sample a frame.
 * Only what irdm render writes is read; anything else is refused, naming
 * the file and what is wrong.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/posix/textfile.h"
#include "view/view_msg.h"
#include "view/view_playback.h"

#define FILE_MAX (512u << 20)
#define FRAMES_MAX 5000u /* irdm render's own limit */

struct rdir {
	const char *dir;
	char path[4200];
	char *pvd, *vtu;   /* whole files, NUL-terminated */
	uint32_t n, m, nc; /* points, triangles, contacts */
	float *rest, *pos;
	uint32_t *tris;
	double *disp, *pt, *force;
	unsigned char *msg;
	char *err;
	size_t errlen;
};

static int bad(struct rdir *r, const char *what)
{
	snprintf(r->err, r->errlen, "%s: %s (not a directory irdm render wrote?)", r->path, what);
	return IRDM_EFORMAT;
}

/*
 * A whole file, NUL-terminated.  Opened without blocking and refused
 * unless a regular file within FILE_MAX, so a FIFO or a device named like
 * a frame fails at once with the reason instead of hanging the view.
 */
static int slurp(struct rdir *r, const char *name, char **out)
{
	FILE *f;
	long n;
	int ret;

	snprintf(r->path, sizeof(r->path), "%s/%s", r->dir, name);
	free(*out);
	*out = NULL;
	ret = irdm_file_fopen(r->path, FILE_MAX, &f, r->err, r->errlen);
	if (ret)
		return ret;
	ret = IRDM_EIO;
	if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || (unsigned long)n > FILE_MAX ||
	    fseek(f, 0, SEEK_SET)) {
		snprintf(r->err, r->errlen, "%s: cannot read: %s", r->path, strerror(errno));
		goto out_close;
	}
	*out = malloc((size_t)n + 1);
	if (!*out) {
		snprintf(r->err, r->errlen, "%s: %ld bytes: out of memory", r->path, n);
		ret = IRDM_ENOMEM;
		goto out_close;
	}
	if (fread(*out, 1, (size_t)n, f) != (size_t)n) {
		snprintf(r->err, r->errlen, "%s: cannot read: %s", r->path,
			 ferror(f) ? strerror(errno) : "shorter than its size");
		free(*out);
		*out = NULL;
		goto out_close;
	}
	(*out)[n] = '\0';
	ret = IRDM_OK;
out_close:
	fclose(f);
	return ret;
}

/* count numbers of the DataArray named name, after its '>'. */
static int numbers(struct rdir *r, const char *name, size_t count, double *out)
{
	char key[64];
	const char *p;
	char *end;

	snprintf(key, sizeof(key), "Name=\"%s\"", name);
	p = strstr(r->vtu, key);
	p = p ? strchr(p, '>') : NULL;
	if (!p)
		return bad(r, name);
	p++;
	for (size_t i = 0; i < count; i++, p = end) {
		out[i] = strtod(p, &end);
		if (end == p || !isfinite(out[i]))
			return bad(r, name);
	}
	return IRDM_OK;
}

/* The Points array (the only unnamed one irdm render writes). */
static int points(struct rdir *r, double *out)
{
	const char *p = strstr(r->vtu, "<Points>");
	char *end;

	p = p ? strstr(p, "<DataArray") : NULL;
	p = p ? strchr(p, '>') : NULL;
	if (!p)
		return bad(r, "no Points");
	p++;
	for (size_t i = 0; i < 3 * (size_t)r->n; i++, p = end) {
		out[i] = strtod(p, &end);
		if (end == p || !isfinite(out[i]))
			return bad(r, "Points");
	}
	return IRDM_OK;
}

static int sizes(struct rdir *r, uint32_t *n, uint32_t *m, uint32_t *nc)
{
	const char *p = strstr(r->vtu, "<Piece NumberOfPoints=\"");
	const char *c = strstr(r->vtu, "Name=\"contact\" NumberOfTuples=\"");

	if (!p || sscanf(p, "<Piece NumberOfPoints=\"%u\" NumberOfCells=\"%u\"", n, m) != 2 ||
	    !c || sscanf(c, "Name=\"contact\" NumberOfTuples=\"%u\"", nc) != 1 || !*n ||
	    *n > (1u << 22) || *m > (1u << 23) || *nc > 64)
		return bad(r, "no or bad sizes");
	return IRDM_OK;
}

/* The first frame: the sizes, the triangles and the rest shape. */
static int first(struct rdir *r)
{
	double *conn;
	int rc = sizes(r, &r->n, &r->m, &r->nc);

	if (rc)
		return rc;
	r->rest = malloc(12 * (size_t)r->n);
	r->pos = malloc(12 * (size_t)r->n);
	r->tris = malloc(12 * (size_t)(r->m ? r->m : 1));
	r->disp = malloc(24 * (size_t)r->n);
	r->pt = malloc(24 * (size_t)(r->nc ? r->nc : 1));
	r->force = malloc(24 * (size_t)(r->nc ? r->nc : 1));
	conn = malloc(24 * (size_t)(r->m ? r->m : 1));
	r->msg = malloc(view_frame_size(r->n, 1));
	if (!r->rest || !r->pos || !r->tris || !r->disp || !r->pt || !r->force || !conn || !r->msg) {
		free(conn);
		snprintf(r->err, r->errlen, "out of memory for %u points", r->n);
		return IRDM_ENOMEM;
	}
	rc = numbers(r, "connectivity", 3 * (size_t)r->m, conn);
	for (size_t i = 0; !rc && i < 3 * (size_t)r->m; i++) {
		if (conn[i] < 0 || conn[i] >= r->n || conn[i] != floor(conn[i]))
			rc = bad(r, "connectivity");
		r->tris[i] = (uint32_t)conn[i];
	}
	free(conn);
	return rc;
}

static int frame(struct rdir *r, struct view_server *s, double t, size_t k)
{
	uint32_t n, m, nc;
	double *xyz = malloc(24 * (size_t)r->n);
	struct view_frame f = { .state = VIEW_STATE_NONE, .tick = (double)k, .t_s = t };
	struct view_sample smp = { .t_s = (float)t };
	int rc = xyz ? sizes(r, &n, &m, &nc) : IRDM_ENOMEM;

	if (!rc && (n != r->n || m != r->m || nc != r->nc))
		rc = bad(r, "sizes differ from the first frame's");
	if (!rc)
		rc = points(r, xyz);
	if (!rc)
		rc = numbers(r, "displacement_m", 3 * (size_t)r->n, r->disp);
	if (!rc && nc)
		rc = numbers(r, "contact_point_m", 3 * (size_t)nc, r->pt);
	if (!rc && nc)
		rc = numbers(r, "contact_force_n", 3 * (size_t)nc, r->force);
	for (size_t i = 0; !rc && i < 3 * (size_t)r->n; i++) {
		r->pos[i] = (float)xyz[i];
		if (!k)
			r->rest[i] = (float)(xyz[i] - r->disp[i]);
	}
	free(xyz);
	if (rc)
		return rc;
	f.n_dev = nc < VIEW_DEVICES ? nc : VIEW_DEVICES;
	for (unsigned i = 0; i < VIEW_DEVICES; i++) {
		f.dev[i].tri = UINT32_MAX;
		for (int a = 0; i < f.n_dev && a < 3; a++) {
			f.dev[i].tip_m[a] = (float)r->pt[3 * i + a];
			f.dev[i].force_n[a] = (float)r->force[3 * i + a];
		}
		smp.force_n[i] = i < f.n_dev ? (float)sqrt(r->force[3 * i] * r->force[3 * i] +
							   r->force[3 * i + 1] * r->force[3 * i + 1] + r->force[3 * i + 2] * r->force[3 * i + 2]) :
					       0;
	}
	if (view_server_record(s, r->msg, view_frame_write(r->msg, &f, r->pos, r->n, &smp, 1))) {
		snprintf(r->err, r->errlen, "out of memory for frame %zu", k);
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

/* Each DataSet of frames.pvd: its time and file (a name in DIR). */
static const char *next_set(const char *p, double *t, char *file, size_t len)
{
	const char *q, *e;

	p = strstr(p, "<DataSet timestep=\"");
	if (!p || sscanf(p, "<DataSet timestep=\"%lf\"", t) != 1 || !isfinite(*t))
		return NULL;
	q = strstr(p, "file=\"");
	e = q ? strchr(q + 6, '"') : NULL;
	if (!e || (size_t)(e - q - 6) >= len || e == q + 6)
		return NULL;
	memcpy(file, q + 6, (size_t)(e - q - 6));
	file[e - q - 6] = '\0';
	return e;
}

static int hello(struct rdir *r, struct view_server *s, double t0, double t_end, size_t frames)
{
	const char *base = strrchr(r->dir, '/');
	struct view_hello h = { .mode = VIEW_MODE_PLAYBACK, .n_nodes = r->n, .n_tris = r->m, .n_dev = r->nc < VIEW_DEVICES ? r->nc : VIEW_DEVICES, .period_s = (float)t0, .duration_s = (float)t_end, .n_frames = (uint32_t)frames, .name = base && base[1] ? base + 1 : r->dir, .rest_m = r->rest, .tris = r->tris };
	unsigned char *buf = malloc(view_hello_size(r->n, r->m));
	int rc;

	if (!buf)
		return IRDM_ENOMEM;
	h.scale_m = view_colour_scale(r->rest, r->n);
	rc = view_server_set_hello(s, buf, view_hello_write(buf, &h));
	free(buf);
	return rc;
}

int view_render_dir_load(struct view_server *s, const char *dir,
			 struct view_playback_summary *sum, char *err, size_t errlen)
{
	struct rdir r = { .dir = dir, .err = err, .errlen = errlen };
	char file[256];
	const char *p;
	double t = 0, t0 = 0;
	size_t k = 0;
	int rc;

	memset(sum, 0, sizeof(*sum));
	rc = slurp(&r, "frames.pvd", &r.pvd);
	for (p = r.pvd; !rc && (p = next_set(p, &t, file, sizeof(file))); k++) {
		if (strchr(file, '/') || k >= FRAMES_MAX) {
			rc = bad(&r, k >= FRAMES_MAX ? "over 5000 frames" : "a frame outside DIR");
			break;
		}
		rc = slurp(&r, file, &r.vtu);
		if (!rc && !k)
			rc = first(&r);
		if (!rc)
			rc = frame(&r, s, t, k);
		if (!k)
			t0 = t;
	}
	if (!rc && !k) {
		snprintf(r.path, sizeof(r.path), "%s/frames.pvd", dir);
		rc = bad(&r, "no frames");
	}
	if (!rc)
		rc = hello(&r, s, t0, t, k);
	sum->frames = k;
	sum->duration_s = t;
	free(r.pvd);
	free(r.vtu);
	free(r.rest);
	free(r.pos);
	free(r.tris);
	free(r.disp);
	free(r.pt);
	free(r.force);
	free(r.msg);
	return rc;
}
