/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image_response.h"
#include "irdm/board.h"
#include "irdm/contact.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/deform_worker.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "modal/lapack.h" /* openblas_set_num_threads */
#include "replay/replay.h"
#include "replay/replay_priv.h"

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

/* ---- the run ---- */

struct irdm_replay {
	const struct irdm_replay_opts *o;
	struct irdm_session *s;       /* image, engine, deformation channel */
	const struct irdm_image *img; /* the session's */
	struct irdm_engine *eng;      /* the session's */
	struct trajectory tr;
	struct trajectory sites;    /* --sites or --log: per-sample sites, else none */
	struct trajectory logged;   /* --log: the controller's forces, else none */
	struct trajectory softened; /* --log: the contacts that began softly */
	unsigned n_contacts;
	enum irdm_contact_mode mode;
	double *pos;    /* every image node's position */
	size_t pos_row; /* the sample pos holds, SIZE_MAX: none */
	struct irdm_contact_site site[IRDM_MAX_CONTACTS];
	struct irdm_contact_mesh cm; /* for the sites' normals; hdr NULL: none */
	uint32_t *rows, *mesh;       /* --nodes: image rows and their mesh nodes */
	size_t n_nodes, row;
	struct irdm_replay_summary *sum;
	FILE *out;
	char tmp[4096];
};

const struct irdm_session *irdm_replay_session(const struct irdm_replay *r)
{
	return r->s;
}

size_t irdm_replay_row(const struct irdm_replay *r)
{
	return r->row;
}

size_t irdm_replay_rows(const struct irdm_replay *r)
{
	return r->tr.n_rows;
}

unsigned irdm_replay_contacts(const struct irdm_replay *r)
{
	return r->n_contacts;
}

const double *irdm_replay_positions(struct irdm_replay *r)
{
	uint64_t tick;

	if (!r->s->worker)
		return NULL;
	/* the engine publishes every tick: a new snapshot is always there
	 * unless this sample's was taken already */
	if (r->pos_row != r->row && irdm_deform_update(r->s->worker, r->pos, &tick))
		r->pos_row = r->row;
	return r->pos_row == r->row ? r->pos : NULL;
}

/* ---- sites and output nodes ---- */

static int make_sites(struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_replay_opts *o = r->o;

	for (unsigned i = 0; i < o->n_contacts; i++) {
		const struct irdm_replay_contact *c = &o->contact[i];
		int rc;
		if (c->is_node) {
			int64_t row = irdm_image_node_of(r->img, c->mesh_node);
			rc = row < 0 ? IRDM_ECONTACT : irdm_engine_site_node(r->eng, (uint32_t)row, &r->site[i]);
			if (rc) {
				snprintf(err, errlen, "--contact %u: mesh node %u is not a touchable node of %s",
					 c->mesh_node, c->mesh_node, o->image);
				return IRDM_EINVAL;
			}
		} else {
			uint32_t tri;
			double bary[3];
			if (irdm_replay_locate(r->img, c->point_m, &tri, bary) ||
			    irdm_engine_site_point(r->eng, tri, bary, &r->site[i])) {
				snprintf(err, errlen, "--contact %g,%g,%g: no touchable surface in %s",
					 c->point_m[0], c->point_m[1], c->point_m[2], o->image);
				return IRDM_EINVAL;
			}
		}
	}
	return 0;
}

/* --nodes N,...: any nodes of the image, or "all" of them. */
static int parse_nodes(struct irdm_replay *r, const char *list, char *err, size_t errlen)
{
	uint32_t n_img = r->img->meta->n_nodes;
	size_t cap = 1;
	const char *p = list;

	for (const char *q = list; *q; q++)
		cap += *q == ',';
	if (!strcmp(list, "all"))
		cap = n_img;
	r->rows = malloc(cap * sizeof(uint32_t));
	r->mesh = malloc(cap * sizeof(uint32_t));
	if (!r->rows || !r->mesh) {
		snprintf(err, errlen, "--nodes: out of memory for %zu nodes", cap);
		return IRDM_ENOMEM;
	}
	if (!strcmp(list, "all")) {
		for (uint32_t k = 0; k < n_img; k++) {
			r->rows[k] = k;
			r->mesh[k] = r->img->nodes[k].mesh_node;
		}
		r->n_nodes = n_img;
		return 0;
	}
	while (p && *p) {
		char *end;
		errno = 0;
		unsigned long v = strtoul(p, &end, 10);
		int64_t row = (end == p || errno || v > UINT32_MAX) ? -1 : irdm_image_node_of(r->img, (uint32_t)v);
		if (row < 0 || (*end && *end != ',')) {
			snprintf(err, errlen, "--nodes: '%.20s' is not a node of the image", p);
			return IRDM_EINVAL;
		}
		r->rows[r->n_nodes] = (uint32_t)row;
		r->mesh[r->n_nodes++] = (uint32_t)v;
		p = *end ? end + 1 : end;
	}
	return 0;
}

/* The engine as the board's controller configures it (fw_config.c). */
static int board_config(struct irdm_replay *r, struct irdm_engine_config *cfg, char *board_name,
			char *err, size_t errlen)
{
	struct irdm_board b;
	int ret = irdm_board_load(&b, r->o->board, err, errlen);

	if (ret)
		return ret;
	irdm_board_engine_config(&b, cfg);
	if (cfg->max_contacts < b.devices)
		cfg->max_contacts = b.devices;
	/* the controller's limit only catches a runaway; a replay renders
	 * whatever the log holds */
	cfg->max_force_n = 0;
	r->n_contacts = b.devices;
	r->mode = IRDM_CONTACT_PUSH;
	snprintf(board_name, IRDM_LOG_NAME_LEN, "%s", b.name);
	return IRDM_OK;
}

static int start_log(struct irdm_replay *r, const char *board_name, char *err, size_t errlen)
{
	struct replay_log lg;
	int ret = read_log(r->o->log, r->img->meta->dt_s, r->img->meta->n_tris, &lg, err, errlen);

	if (ret)
		return ret;
	if (lg.n_devices != r->n_contacts || strcmp(lg.board, board_name)) {
		snprintf(err, errlen, "%s: recorded on board '%s' (%u devices), not on %s ('%s', %u)",
			 r->o->log, lg.board, lg.n_devices, r->o->board, board_name, r->n_contacts);
		replay_log_free(&lg);
		return IRDM_EINVAL;
	}
	r->tr = lg.tr;
	r->sites = lg.sites;
	r->logged = lg.forces;
	r->softened = lg.softened;
	return IRDM_OK;
}

static int start_inputs(struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_replay_opts *o = r->o;
	int ret = o->sites ? IRDM_OK : make_sites(r, err, errlen);

	if (!ret)
		ret = read_trajectory(o->trajectory, r->n_contacts, r->img->meta->dt_s, &r->tr, err,
				      errlen);
	if (ret || !o->sites)
		return ret;
	ret = read_sites(o->sites, r->n_contacts, r->img->meta->dt_s, r->img->meta->n_tris,
			 &r->sites, err, errlen);
	if (!ret && r->sites.n_rows != r->tr.n_rows) {
		snprintf(err, errlen, "%s: %zu rows, but %s has %zu", o->sites, r->sites.n_rows,
			 o->trajectory, r->tr.n_rows);
		ret = IRDM_EFORMAT;
	}
	return ret;
}

static int start(struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_replay_opts *o = r->o;
	bool deform = o->nodes || o->deform;
	struct irdm_session_config sc = { .deform = deform };
	char board_name[IRDM_LOG_NAME_LEN] = "";
	int ret;

	irdm_engine_config_default(&sc.engine);
	if (o->log) {
		ret = board_config(r, &sc.engine, board_name, err, errlen);
		if (ret)
			return ret;
	} else {
		sc.engine.passivity_control = o->passivity;
		sc.engine.max_contacts = r->n_contacts;
		sc.engine.solve = o->solve;
		sc.engine.coupling_k_n_per_m = o->coupling_k;
		sc.engine.coupling_b_ns_per_m = o->coupling_b;
	}
	sc.engine.publish_every = deform ? 1 : 0;
	ret = irdm_session_open(&r->s, o->image, &sc, err, errlen);
	if (ret)
		return ret;
	r->img = r->s->img;
	r->eng = r->s->eng;
	if (irdm_contact_mesh_init(&r->cm, r->img))
		memset(&r->cm, 0, sizeof(r->cm)); /* no BVH: sites keep the rest normal */
	ret = o->log ? start_log(r, board_name, err, errlen) : start_inputs(r, err, errlen);
	if (ret || !deform)
		return ret;
	r->pos = malloc(3 * (size_t)r->img->meta->n_nodes * sizeof(double));
	if (!r->pos) {
		snprintf(err, errlen, "%s: out of memory for the deformed surface", o->image);
		return IRDM_ENOMEM;
	}
	/* the product irdm-fw's worker computes, summed in the same order:
	 * its frames and these agree bit for bit */
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);
	ret = irdm_session_deform_open(r->s, err, errlen);
	if (!ret && o->nodes)
		ret = parse_nodes(r, o->nodes, err, errlen);
	return ret;
}

static void header(struct irdm_replay *r)
{
	fprintf(r->out, "t");
	for (unsigned i = 0; i < r->n_contacts; i++)
		fprintf(r->out, ",c%u_fx,c%u_fy,c%u_fz", i + 1, i + 1, i + 1);
	for (size_t k = 0; k < r->n_nodes; k++)
		fprintf(r->out, ",n%u_ux,n%u_uy,n%u_uz", r->mesh[k], r->mesh[k], r->mesh[k]);
	fputc('\n', r->out);
}

static void engine_disp(const void *ctx, uint32_t row, double u[3])
{
	irdm_engine_node_disp(ctx, row, u);
}

/*
 * The normal irdm-fw gives the engine with a site: its triangle's on the
 * surface as the engine has it now (the proxy's, irdm_contact_tri_normal()),
 * not at rest; the push release judges the force against it.
 */
static void deformed_normal(struct irdm_replay *r, uint32_t tri, struct irdm_contact_site *site)
{
	const struct irdm_contact_disp disp = { .fn = engine_disp, .ctx = r->eng };
	double n[3];

	if (r->cm.hdr && irdm_contact_tri_normal(&r->cm, &disp, tri, n))
		memcpy(site->normal, n, sizeof(n));
}

/* This sample's commands; a contact whose sample has no site is an error. */
static int commands(struct irdm_replay *r, const double *v, struct irdm_contact_cmd *cmd,
		    char *err, size_t errlen)
{
	memset(cmd, 0, IRDM_MAX_CONTACTS * sizeof(*cmd));
	for (unsigned i = 0; i < r->n_contacts; i++) {
		const double *u = &v[1 + 3 * i];
		if (isnan(u[0]) || isnan(u[1]) || isnan(u[2]))
			continue; /* released this sample */
		if (r->sites.v) {
			/* the site of this sample, handed over every sample as the
			 * controller does (a slide keeps the contact's past) */
			const double *st = &r->sites.v[r->row * r->sites.n_cols + 1 + 4 * i];
			if (st[0] < 0 || irdm_engine_site_point(r->eng, (uint32_t)st[0], st + 1,
								&r->site[i])) {
				snprintf(err, errlen, "%s: row %zu: contact %u has a displacement but "
						      "no site",
					 r->o->log ? r->o->log : r->o->sites, r->row + 1, i + 1);
				return IRDM_EINVAL;
			}
			deformed_normal(r, (uint32_t)st[0], &r->site[i]);
			irdm_engine_contact_begin(r->eng, i, &r->site[i], r->mode);
			if (r->softened.v &&
			    r->softened.v[r->row * r->softened.n_cols + 1 + i] != 0 &&
			    irdm_engine_contact_soften(r->eng, i)) {
				snprintf(err, errlen, "%s: row %zu: contact %u began softly but is not "
						      "new",
					 r->o->log, r->row + 1, i + 1);
				return IRDM_EINVAL;
			}
		} else if (irdm_engine_contact(r->eng, i)->mode == IRDM_CONTACT_OFF) {
			irdm_engine_contact_begin(r->eng, i, &r->site[i], r->mode);
		}
		cmd[i].mode = r->mode;
		memcpy(cmd[i].target_m, u, sizeof(cmd[i].target_m));
	}
	return 0;
}

/* --log: how far the forces are from the ones the controller logged. */
static void compare_logged(struct irdm_replay *r)
{
	const double *lf = &r->logged.v[r->row * r->logged.n_cols + 1];

	for (unsigned i = 0; i < r->n_contacts; i++) {
		const double *f = irdm_engine_contact(r->eng, i)->force_n;
		double d = 0, n = 0;
		for (int a = 0; a < 3; a++) {
			d += (f[a] - lf[3 * i + a]) * (f[a] - lf[3 * i + a]);
			n += lf[3 * i + a] * lf[3 * i + a];
		}
		r->sum->log_max_diff_n = fmax(r->sum->log_max_diff_n, sqrt(d));
		r->sum->log_peak_n = fmax(r->sum->log_peak_n, sqrt(n));
	}
}

static int write_row(struct irdm_replay *r, const double *v, char *err, size_t errlen)
{
	const double *pos = r->n_nodes ? irdm_replay_positions(r) : NULL;

	if (r->n_nodes && !pos) {
		snprintf(err, errlen, "internal: no deformation snapshot at t = %g s", v[0]);
		return IRDM_EINVAL;
	}
	fprintf(r->out, "%.9g", v[0]);
	for (unsigned i = 0; i < r->n_contacts; i++) {
		const double *f = irdm_engine_contact(r->eng, i)->force_n;
		fprintf(r->out, ",%.17g,%.17g,%.17g", f[0], f[1], f[2]);
	}
	for (size_t k = 0; k < r->n_nodes; k++) {
		const float *rest = r->img->nodes[r->rows[k]].pos_m;
		const double *x = &pos[3 * (size_t)r->rows[k]];
		fprintf(r->out, ",%.12g,%.12g,%.12g", x[0] - rest[0], x[1] - rest[1], x[2] - rest[2]);
	}
	fputc('\n', r->out);
	return 0;
}

static int step(struct irdm_replay *r, size_t row, char *err, size_t errlen)
{
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	const double *v = &r->tr.v[row * r->tr.n_cols];
	int ret;

	r->row = row;
	ret = commands(r, v, cmd, err, errlen);
	if (ret)
		return ret;
	if (irdm_engine_tick(r->eng, cmd)) {
		const char *why = irdm_engine_fault_reason(r->eng);
		snprintf(err, errlen, "engine fault at t = %g s: %s", v[0],
			 why ? why : "(no reason given)");
		return IRDM_EFAULT;
	}
	if (r->logged.v)
		compare_logged(r);
	ret = write_row(r, v, err, errlen);
	if (!ret && r->o->on_tick)
		ret = r->o->on_tick(r->o->ctx, r, err, errlen);
	return ret;
}

static int run_rows(struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_replay_opts *o = r->o;
	int ret = start(r, err, errlen);

	if (ret)
		return ret;
	snprintf(r->tmp, sizeof(r->tmp), "%s.tmp", o->out);
	r->out = fopen(r->tmp, "w");
	if (!r->out) {
		snprintf(err, errlen, "%s: cannot create: %s", r->tmp, strerror(errno));
		return IRDM_EIO;
	}
	header(r);
	for (size_t row = 0; !ret && row < r->tr.n_rows; row++)
		ret = step(r, row, err, errlen);
	r->sum->rows = r->tr.n_rows;
	if (ret)
		return ret;
	ret = fclose(r->out);
	r->out = NULL;
	if (ret) {
		snprintf(err, errlen, "%s: write failed: %s", r->tmp, strerror(errno));
		return IRDM_EIO;
	}
	if (rename(r->tmp, o->out)) {
		snprintf(err, errlen, "%s: cannot rename into place: %s", o->out, strerror(errno));
		return IRDM_EIO;
	}
	r->tmp[0] = '\0'; /* in place: nothing to remove */
	return IRDM_OK;
}

int irdm_replay_run(const struct irdm_replay_opts *o, struct irdm_replay_summary *sum, char *err,
		    size_t errlen)
{
	struct irdm_replay_summary none;
	struct irdm_replay *r = calloc(1, sizeof(*r));
	int ret;

	if (!r) {
		snprintf(err, errlen, "out of memory");
		return IRDM_ENOMEM;
	}
	r->o = o;
	r->sum = sum ? sum : &none;
	memset(r->sum, 0, sizeof(*r->sum));
	r->pos_row = SIZE_MAX;
	r->mode = o->mode;
	r->n_contacts = o->n_contacts;
	ret = o->sites ? sites_contacts(o->sites, &r->n_contacts, err, errlen) : IRDM_OK;
	if (!ret)
		ret = run_rows(r, err, errlen);
	if (r->out)
		fclose(r->out);
	if (ret && r->tmp[0])
		remove(r->tmp);
	irdm_trajectory_free(&r->tr);
	irdm_trajectory_free(&r->sites);
	irdm_trajectory_free(&r->logged);
	irdm_trajectory_free(&r->softened);
	free(r->pos);
	free(r->rows);
	free(r->mesh);
	irdm_session_close(r->s);
	free(r);
	return ret;
}
