/* SPDX-License-Identifier: MIT */
/*
 * irdm render's run: irdm replay's (replay.c) with a hook that keeps a
 * frame every so many samples.  Times follow the sample convention
 * (docs/architecture.md): sample t's force acts over [t dt, (t+1) dt) and
 * its displacement u[t], the commanded one at the contact, is the surface
 * at (t+1) dt.  So the frame after sample t is at (t+1) dt, as irdm-fw's
 * frames are (the snapshot after engine tick k is the surface at k dt), and
 * a frame every n samples falls on n dt, 2 n dt, ..., as --frames-every's.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "irdm/posix/outdir.h"
#include "render/render.h"
#include "util/interrupt.h"

struct render {
	const struct irdm_render_opts *o;
	struct irdm_render_summary *sum;
	struct irdm_outdir od; /* the files go to od.tmp, put in DIR's place at the end */
	char path[4400];       /* scratch: the file being opened */
	char forces[4400];     /* the replay's output, DIR.tmp/forces.csv */
	FILE *pvd, *csv;
	bool started;
};

static double frame_time(const struct irdm_replay *r)
{
	return (double)(irdm_replay_row(r) + 1) * irdm_replay_session(r)->img->meta->dt_s;
}

static int io_error(const char *path, int e, char *err, size_t errlen)
{
	snprintf(err, errlen, "%.600s: %s", path, strerror(e));
	return IRDM_EIO;
}

static void csv_header(FILE *f, unsigned nc)
{
	fprintf(f, "frame,t_s,file");
	for (unsigned i = 1; i <= nc; i++)
		fprintf(f, ",c%u_on,c%u_x_m,c%u_y_m,c%u_z_m,c%u_fx_n,c%u_fy_n,c%u_fz_n", i, i, i, i, i,
			i, i);
	fprintf(f, ",max_disp_m\n");
}

/* The sample grid of the frames, known once the inputs are read. */
static int first_tick(struct render *rd, struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_image *img = irdm_replay_session(r)->img;
	double every = rd->o->every_s / img->meta->dt_s;
	size_t rows = irdm_replay_rows(r);

	rd->started = true;
	if (!(every >= 0.5) || every > (double)rows) {
		snprintf(err, errlen, "--every %g: must be between the image's dt (%g s) and the run's length (%g s)",
			 rd->o->every_s, img->meta->dt_s, (double)rows * img->meta->dt_s);
		return IRDM_EINVAL;
	}
	rd->sum->every_rows = (size_t)llround(every);
	if (rows / rd->sum->every_rows > IRDM_RENDER_MAX_FRAMES) {
		snprintf(err, errlen, "--every %g: more than %d frames in this run of %zu samples",
			 rd->o->every_s, IRDM_RENDER_MAX_FRAMES, rows);
		return IRDM_EINVAL;
	}
	irdm_render_surface(img, &rd->sum->surface);
	csv_header(rd->csv, irdm_replay_contacts(r));
	return IRDM_OK;
}

static double max_disp(const struct irdm_image *img, const double *pos)
{
	double m = 0;

	for (uint32_t k = 0; k < img->meta->n_nodes; k++) {
		const float *rest = img->nodes[k].pos_m;
		const double *x = pos + 3 * (size_t)k;
		m = fmax(m, hypot(hypot(x[0] - rest[0], x[1] - rest[1]), x[2] - rest[2]));
	}
	return m;
}

static void csv_row(struct render *rd, struct irdm_replay *r, const char *file, double umax)
{
	const struct irdm_engine *eng = irdm_replay_session(r)->eng;

	fprintf(rd->csv, "%zu,%.9g,%s", rd->sum->frames, frame_time(r), file);
	for (unsigned i = 0; i < irdm_replay_contacts(r); i++) {
		const struct irdm_contact_state *c = irdm_engine_contact(eng, i);
		fprintf(rd->csv, ",%d", c->mode != IRDM_CONTACT_OFF);
		for (int a = 0; a < 3; a++)
			fprintf(rd->csv, ",%.9g", c->site.rest_m[a] + c->disp_m[a]);
		for (int a = 0; a < 3; a++)
			fprintf(rd->csv, ",%.9g", c->force_n[a]);
	}
	fprintf(rd->csv, ",%.9g\n", umax);
}

static int frame(struct render *rd, struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_image *img = irdm_replay_session(r)->img;
	const double *pos = irdm_replay_positions(r);
	char file[32];
	double umax;
	int e;

	if (!pos) {
		snprintf(err, errlen, "internal: no deformation snapshot at t = %g s",
			 frame_time(r));
		return IRDM_EINVAL;
	}
	snprintf(file, sizeof(file), "frame_%05zu.vtu", rd->sum->frames);
	snprintf(rd->path, sizeof(rd->path), "%s/%s", rd->od.tmp, file);
	e = irdm_render_write_vtu(rd->path, r, frame_time(r), pos);
	if (e)
		return io_error(rd->path, e, err, errlen);
	irdm_render_pvd_entry(rd->pvd, frame_time(r), file);
	umax = max_disp(img, pos);
	csv_row(rd, r, file, umax);
	if (umax > rd->sum->max_disp_m) {
		rd->sum->max_disp_m = umax;
		rd->sum->max_disp_t_s = frame_time(r);
	}
	rd->sum->frames++;
	return IRDM_OK;
}

static int on_tick(void *ctx, struct irdm_replay *r, char *err, size_t errlen)
{
	struct render *rd = ctx;
	int ret = rd->started ? IRDM_OK : first_tick(rd, r, err, errlen);

	if (ret || (irdm_replay_row(r) + 1) % rd->sum->every_rows)
		return ret;
	return frame(rd, r, err, errlen);
}

static FILE *open_in(struct render *rd, const char *name)
{
	snprintf(rd->path, sizeof(rd->path), "%s/%s", rd->od.tmp, name);
	return fopen(rd->path, "w");
}

/* Close the index files; 0 or errno. */
static int close_files(struct render *rd)
{
	int e = 0;

	if (rd->pvd && (ferror(rd->pvd) | fclose(rd->pvd)))
		e = errno ? errno : EIO;
	if (rd->csv && (ferror(rd->csv) | fclose(rd->csv)) && !e)
		e = errno ? errno : EIO;
	rd->pvd = rd->csv = NULL;
	return e;
}

static int run_into_tmp(struct render *rd, char *err, size_t errlen)
{
	struct irdm_replay_opts in = rd->o->in;
	int ret;

	rd->pvd = open_in(rd, "frames.pvd");
	if (rd->pvd)
		rd->csv = open_in(rd, "frames.csv");
	if (!rd->pvd || !rd->csv)
		return io_error(rd->path, errno, err, errlen);
	irdm_render_pvd_begin(rd->pvd);
	snprintf(rd->forces, sizeof(rd->forces), "%s/forces.csv", rd->od.tmp);
	in.out = rd->forces;
	in.deform = true;
	in.on_tick = on_tick;
	in.ctx = rd;
	ret = irdm_replay_run(&in, &rd->sum->replay, err, errlen);
	if (ret)
		return ret;
	irdm_render_pvd_end(rd->pvd);
	ret = close_files(rd);
	return ret ? io_error(rd->od.tmp, ret, err, errlen) : IRDM_OK;
}

int irdm_render_run(const struct irdm_render_opts *o, struct irdm_render_summary *sum,
		    char *err, size_t errlen)
{
	struct render rd = { .o = o, .sum = sum };
	int ret, slot;

	memset(sum, 0, sizeof(*sum));
	ret = irdm_outdir_begin(&rd.od, o->out_dir, "irdm render", o->force);
	if (ret)
		goto out_why;
	sum->debris_removed = rd.od.debris_removed;
	slot = irdm_interrupt_add(IRDM_INTERRUPT_DIR, rd.od.tmp, 0);
	ret = run_into_tmp(&rd, err, errlen);
	close_files(&rd);
	if (ret) {
		irdm_outdir_abort(&rd.od);
		irdm_interrupt_del(slot);
		return ret;
	}
	ret = irdm_outdir_commit(&rd.od);
	irdm_interrupt_del(slot);
	if (!ret)
		return IRDM_OK;
out_why:
	snprintf(err, errlen, "%s", rd.od.why);
	return ret;
}
