/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image_response.h"
#include "irdm/contact.h"
#include "irdm/deform_worker.h"
#include "irdm/session.h"
#include "replay/replay.h"
#include "replay/replay_priv.h"

#define MAX_NODES_OUT 256

void irdm_replay_opts_default(struct irdm_replay_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->mode = IRDM_CONTACT_GRAB;
	o->solve = IRDM_SOLVE_COUPLED;
}

int irdm_replay_locate(const struct irdm_image *img, const double p[3], uint32_t *tri,
		       double bary[3])
{
	struct irdm_contact_mesh cm;
	struct irdm_contact_hit hit;

	/* the nearest point of the rest surface (no displacement); 1 km covers
	 * any object (the query wants a finite radius) */
	if (irdm_contact_mesh_init(&cm, img) ||
	    irdm_contact_closest(&cm, NULL, 0.0, p, 1e3, &hit) != 1)
		return -1;
	*tri = hit.tri;
	memcpy(bary, hit.bary, sizeof(hit.bary));
	return 0;
}

/* ---- sites and output nodes ---- */

static int make_sites(const struct irdm_replay_opts *o, const struct irdm_image *img,
		      const struct irdm_engine *eng, struct irdm_contact_site *site,
		      char *err, size_t errlen)
{
	for (unsigned i = 0; i < o->n_contacts; i++) {
		const struct irdm_replay_contact *c = &o->contact[i];
		int rc;
		if (c->is_node) {
			int64_t row = irdm_image_node_of(img, c->mesh_node);
			rc = row < 0 ? IRDM_ECONTACT : irdm_engine_site_node(eng, (uint32_t)row, &site[i]);
			if (rc) {
				snprintf(err, errlen, "--contact %u: mesh node %u is not a touchable node of %s",
					 c->mesh_node, c->mesh_node, o->image);
				return IRDM_EINVAL;
			}
		} else {
			uint32_t tri;
			double bary[3];
			if (irdm_replay_locate(img, c->point_m, &tri, bary) ||
			    irdm_engine_site_point(eng, tri, bary, &site[i])) {
				snprintf(err, errlen, "--contact %g,%g,%g: no touchable surface in %s",
					 c->point_m[0], c->point_m[1], c->point_m[2], o->image);
				return IRDM_EINVAL;
			}
		}
	}
	return 0;
}

static int parse_nodes(const char *list, const struct irdm_image *img, uint32_t *rows,
		       uint32_t *mesh, size_t *n, char *err, size_t errlen)
{
	const char *p = list;

	*n = 0;
	while (p && *p) {
		char *end;
		errno = 0;
		unsigned long v = strtoul(p, &end, 10);
		int64_t row = (end == p || errno || v > UINT32_MAX) ? -1 : irdm_image_node_of(img, (uint32_t)v);
		if (row < 0 || *n == MAX_NODES_OUT || (*end && *end != ',')) {
			snprintf(err, errlen, "--nodes: '%.20s' is not a node of the image (at most %d)",
				 p, MAX_NODES_OUT);
			return IRDM_EINVAL;
		}
		rows[*n] = (uint32_t)row;
		mesh[(*n)++] = (uint32_t)v;
		p = *end ? end + 1 : end;
	}
	return 0;
}

/* ---- the run ---- */

struct run {
	struct irdm_session *s;         /* image, engine, deformation of the --nodes */
	const struct irdm_image *img;   /* the session's */
	struct irdm_engine *eng;        /* the session's */
	struct trajectory tr;
	struct trajectory sites;        /* --sites: per-sample sites, else none */
	double *pos;                    /* every image node's position */
	struct irdm_contact_site site[IRDM_MAX_CONTACTS];
	uint32_t rows[MAX_NODES_OUT], mesh[MAX_NODES_OUT];
	size_t n_nodes;
	FILE *out;
	char tmp[4096];
};

/* The deformation worker gives any node's position (world, for floating). */
static int start_deform(struct run *r, char *err, size_t errlen)
{
	r->pos = malloc(3 * (size_t)r->img->meta->n_nodes * sizeof(double));
	if (!r->pos) {
		snprintf(err, errlen, "--nodes: out of memory");
		return IRDM_ENOMEM;
	}
	return irdm_session_deform_open(r->s, err, errlen);
}

static int start(const struct irdm_replay_opts *o, struct run *r, char *err, size_t errlen)
{
	struct irdm_session_config sc = { .deform = o->nodes != NULL };
	int ret;

	irdm_engine_config_default(&sc.engine);
	sc.engine.passivity_control = o->passivity;
	sc.engine.max_contacts = o->n_contacts;
	sc.engine.solve = o->solve;
	sc.engine.coupling_k_n_per_m = o->coupling_k;
	sc.engine.coupling_b_ns_per_m = o->coupling_b;
	sc.engine.publish_every = o->nodes ? 1 : 0;
	ret = irdm_session_open(&r->s, o->image, &sc, err, errlen);
	if (ret)
		return ret;
	r->img = r->s->img;
	r->eng = r->s->eng;
	ret = o->sites ? IRDM_OK : make_sites(o, r->img, r->eng, r->site, err, errlen);
	if (ret)
		return ret;
	if (o->nodes) {
		ret = start_deform(r, err, errlen);
		if (!ret)
			ret = parse_nodes(o->nodes, r->img, r->rows, r->mesh, &r->n_nodes, err, errlen);
		if (ret)
			return ret;
	}
	ret = read_trajectory(o->trajectory, o->n_contacts, r->img->meta->dt_s, &r->tr, err,
			      errlen);
	if (ret || !o->sites)
		return ret;
	ret = read_sites(o->sites, o->n_contacts, r->img->meta->dt_s, r->img->meta->n_tris,
			 &r->sites, err, errlen);
	if (!ret && r->sites.n_rows != r->tr.n_rows) {
		snprintf(err, errlen, "%s: %zu rows, but %s has %zu", o->sites, r->sites.n_rows,
			 o->trajectory, r->tr.n_rows);
		ret = IRDM_EFORMAT;
	}
	return ret;
}

static void header(const struct irdm_replay_opts *o, struct run *r)
{
	fprintf(r->out, "t");
	for (unsigned i = 0; i < o->n_contacts; i++)
		fprintf(r->out, ",c%u_fx,c%u_fy,c%u_fz", i + 1, i + 1, i + 1);
	for (size_t k = 0; k < r->n_nodes; k++)
		fprintf(r->out, ",n%u_ux,n%u_uy,n%u_uz", r->mesh[k], r->mesh[k], r->mesh[k]);
	fputc('\n', r->out);
}

static int step(const struct irdm_replay_opts *o, struct run *r, size_t row, char *err,
		size_t errlen)
{
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	const double *v = &r->tr.v[row * r->tr.n_cols];

	memset(cmd, 0, sizeof(cmd));
	for (unsigned i = 0; i < o->n_contacts; i++) {
		const double *u = &v[1 + 3 * i];
		if (isnan(u[0]) || isnan(u[1]) || isnan(u[2]))
			continue;   /* released this sample */
		if (r->sites.v) {
			/* the site of this sample, handed over every sample as the
			 * controller does (a slide keeps the contact's past) */
			const double *st = &r->sites.v[row * r->sites.n_cols + 1 + 4 * i];
			if (st[0] < 0 || irdm_engine_site_point(r->eng, (uint32_t)st[0], st + 1,
								&r->site[i])) {
				snprintf(err, errlen, "%s: row %zu: contact %u has a displacement but "
					 "no site", o->sites, row + 1, i + 1);
				return IRDM_EINVAL;
			}
			irdm_engine_contact_begin(r->eng, i, &r->site[i], o->mode);
		} else if (irdm_engine_contact(r->eng, i)->mode == IRDM_CONTACT_OFF) {
			irdm_engine_contact_begin(r->eng, i, &r->site[i], o->mode);
		}
		cmd[i].mode = o->mode;
		memcpy(cmd[i].target_m, u, sizeof(cmd[i].target_m));
	}
	if (irdm_engine_tick(r->eng, cmd)) {
		snprintf(err, errlen, "engine fault at t = %g s (non-finite or excessive force)", v[0]);
		return IRDM_EFAULT;
	}
	fprintf(r->out, "%.9g", v[0]);
	for (unsigned i = 0; i < o->n_contacts; i++) {
		const double *f = irdm_engine_contact(r->eng, i)->force_n;
		fprintf(r->out, ",%.17g,%.17g,%.17g", f[0], f[1], f[2]);
	}
	uint64_t tick;
	if (r->n_nodes && !irdm_deform_update(r->s->worker, r->pos, &tick)) {
		snprintf(err, errlen, "internal: no deformation snapshot at t = %g s", v[0]);
		return IRDM_EINVAL;
	}
	for (size_t k = 0; k < r->n_nodes; k++) {
		const float *rest = r->img->nodes[r->rows[k]].pos_m;
		const double *x = &r->pos[3 * (size_t)r->rows[k]];
		fprintf(r->out, ",%.12g,%.12g,%.12g", x[0] - rest[0], x[1] - rest[1], x[2] - rest[2]);
	}
	fputc('\n', r->out);
	return 0;
}

int irdm_replay_run(const struct irdm_replay_opts *opts, char *err, size_t errlen)
{
	struct run *r = calloc(1, sizeof(*r));
	struct irdm_replay_opts with_sites = *opts;
	const struct irdm_replay_opts *o = &with_sites;
	int ret;

	if (opts->sites) {
		ret = sites_contacts(opts->sites, &with_sites.n_contacts, err, errlen);
		if (ret) {
			free(r);
			return ret;
		}
	}
	if (!r) {
		snprintf(err, errlen, "out of memory");
		return IRDM_ENOMEM;
	}
	ret = start(o, r, err, errlen);
	if (ret)
		goto out_free;
	snprintf(r->tmp, sizeof(r->tmp), "%s.tmp", o->out);
	r->out = fopen(r->tmp, "w");
	if (!r->out) {
		snprintf(err, errlen, "%s: cannot create: %s", r->tmp, strerror(errno));
		ret = IRDM_EIO;
		goto out_free;
	}
	header(o, r);
	for (size_t row = 0; !ret && row < r->tr.n_rows; row++)
		ret = step(o, r, row, err, errlen);
	if (ret)
		goto out_remove;
	/* from here on every failure is the file system's */
	ret = IRDM_EIO;
	if (fclose(r->out)) {
		r->out = NULL;
		snprintf(err, errlen, "%s: write failed: %s", r->tmp, strerror(errno));
		goto out_remove;
	}
	r->out = NULL;
	if (rename(r->tmp, o->out)) {
		snprintf(err, errlen, "%s: cannot rename into place: %s", o->out, strerror(errno));
		goto out_remove;
	}
	ret = IRDM_OK;
	goto out_free;
out_remove:
	if (r->out)
		fclose(r->out);
	remove(r->tmp);
out_free:
	irdm_trajectory_free(&r->tr);
	irdm_trajectory_free(&r->sites);
	free(r->pos);
	irdm_session_close(r->s);
	free(r);
	return ret;
}
