/* SPDX-License-Identifier: MIT */
/*
 * The kept frames of the deformed surface as legacy VTK: --frame-at's one
 * file, and --frames-every's series, a directory of frame_NNNNN.vtk with a
 * frames.vtk.series index (ParaView's JSON file-series format: each file
 * and its time), so ParaView opens the series with its times.  Each is
 * written beside its destination under a fresh name and renamed into
 * place: a reader never sees half a frame or half a series, and nothing
 * the tool did not write is replaced (irdm/posix/outdir.h).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/posix/outdir.h"
#include "irdm/posix/outfile.h"

#include "fw.h"

/* Three doubles a line, %.17g: the file holds every bit the run had. */
static void put_vec(FILE *f, const double *v)
{
	fprintf(f, "%.17g %.17g %.17g\n", v[0], v[1], v[2]);
}

static bool tri_shown(const uint32_t *t, uint32_t rows)
{
	return t[0] < rows && t[1] < rows && t[2] < rows;
}

static void write_polys(FILE *f, const struct irdm_image *img, uint32_t rows)
{
	uint32_t n = 0;

	for (uint32_t t = 0; t < img->meta->n_tris; t++)
		n += tri_shown(img->tris + 3 * (size_t)t, rows);
	fprintf(f, "POLYGONS %u %u\n", n, 4 * n);
	for (uint32_t t = 0; t < img->meta->n_tris; t++) {
		const uint32_t *v = img->tris + 3 * (size_t)t;
		if (tri_shown(v, rows))
			fprintf(f, "3 %u %u %u\n", v[0], v[1], v[2]);
	}
}

/*
 * Legacy VTK: the displayed nodes' world positions and the surface; the
 * contact as dataset field data; per point the displacement and the rest
 * position (what plot-surface.py colours by).
 */
static void write_vtk(FILE *f, const struct fw *fw, const struct fw_frame_slot *sl)
{
	const struct fw_frame *fr = &fw->frame;
	const struct irdm_image *img = fw->s->img;
	double dt_s = fw->board.period_us * 1e-6;

	fprintf(f, "# vtk DataFile Version 3.0\n");
	fprintf(f, "irdm-fw frame: tick %llu (t %.6f s), contact at tick %llu\n",
		(unsigned long long)sl->held_tick, (double)sl->held_tick * dt_s,
		(unsigned long long)(sl->contact_seen ? sl->target_tick : 0));
	fprintf(f, "ASCII\nDATASET POLYDATA\nFIELD FieldData 4\n");
	fprintf(f, "time_s 1 1 double\n%.17g\n", (double)sl->held_tick * dt_s);
	fprintf(f, "contact 1 1 int\n%d\n", sl->contact_on ? 1 : 0);
	fprintf(f, "contact_point_m 3 1 double\n");
	put_vec(f, sl->contact_m);
	fprintf(f, "contact_force_n 3 1 double\n");
	put_vec(f, sl->force_obj_n);
	fprintf(f, "POINTS %u double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++)
		put_vec(f, sl->pos_m + 3 * (size_t)r);
	write_polys(f, img, fr->rows);
	fprintf(f, "POINT_DATA %u\nVECTORS displacement_m double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++) {
		const float *rest = img->nodes[r].pos_m;
		const double *p = sl->pos_m + 3 * (size_t)r;
		double u[3] = { p[0] - rest[0], p[1] - rest[1], p[2] - rest[2] };
		put_vec(f, u);
	}
	fprintf(f, "FIELD FieldData 1\nrest_m 3 %u double\n", fr->rows);
	for (uint32_t r = 0; r < fr->rows; r++) {
		const float *rest = img->nodes[r].pos_m;
		put_vec(f, (const double[3]){ rest[0], rest[1], rest[2] });
	}
}

/* One frame to path (no rename).  Return: 0, or errno. */
/* Write and close f: 0, or errno. */
static int write_file(const struct fw *fw, const struct fw_frame_slot *sl, FILE *f)
{
	int bad;

	write_vtk(f, fw, sl);
	bad = ferror(f);
	if (fclose(f) || bad)
		return errno ? errno : EIO;
	return 0;
}

static int no_frame(struct fw *fw, const char *path)
{
	snprintf(fw->err, sizeof(fw->err),
		 "%s: no deformation frame was computed (the run stopped at tick %llu)", path,
		 (unsigned long long)fw->ticks);
	return IRDM_EIO;
}

static int io_error(struct fw *fw, const char *path, int e)
{
	snprintf(fw->err, sizeof(fw->err), "%.400s: %s", path, strerror(e));
	return IRDM_EIO;
}

/* Written whole beside FILE and renamed (irdm/posix/outfile.h): a reader never
 * sees half a frame, and nothing but a file is replaced. */
int fw_frame_write(struct fw *fw)
{
	const char *path = fw->args.frame_out;
	struct irdm_outfile o;
	int rc;

	if (!path)
		return IRDM_OK;
	if (!fw->frame.slot[fw->frame.single_slot].held)
		return no_frame(fw, path);
	rc = irdm_outfile_open(&o, path, fw->err, sizeof(fw->err));
	if (rc)
		return rc;
	write_vtk(o.f, fw, &fw->frame.slot[fw->frame.single_slot]);
	return irdm_outfile_commit(&o, fw->err, sizeof(fw->err));
}

/* The frames and the index into dir.  Return: 0, or errno. */
static int write_series_into(const struct fw *fw, const char *dir)
{
	const struct fw_frame *fr = &fw->frame;
	char path[4200];
	unsigned n = 0;
	FILE *idx;
	int e = 0;

	snprintf(path, sizeof(path), "%s/frames.vtk.series", dir);
	idx = fopen(path, "w");
	if (!idx)
		return errno;
	fprintf(idx, "{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n");
	for (unsigned k = 0; k < fr->n_slots && !e; k++) {
		const struct fw_frame_slot *sl = &fr->slot[k];
		FILE *f;

		if (k == fr->single_slot)
			continue;
		snprintf(path, sizeof(path), "%s/frame_%05u.vtk", dir, ++n);
		f = fopen(path, "w");
		e = f ? write_file(fw, sl, f) : errno;
		fprintf(idx, "%s    { \"name\" : \"frame_%05u.vtk\", \"time\" : %.17g }", n > 1 ? ",\n" : "",
			n, (double)sl->held_tick * fw->board.period_us / 1e6);
	}
	fprintf(idx, "\n  ]\n}\n");
	if (ferror(idx) && !e)
		e = EIO;
	if (fclose(idx) && !e)
		e = errno;
	return e;
}

/*
 * The series' directory is claimed before the run (irdm/posix/outdir.h): a DIR
 * this tool did not write is refused then, not after the run.
 */
int fw_frame_claim_series(struct fw *fw)
{
	int rc;

	if (!fw->args.frames_out)
		return IRDM_OK;
	rc = irdm_outdir_begin(&fw->frames_dir, fw->args.frames_out, "irdm-fw", fw->args.force);
	if (rc)
		snprintf(fw->err, sizeof(fw->err), "%.500s", fw->frames_dir.why);
	else if (fw->frames_dir.debris_removed && !fw->args.quiet)
		fprintf(stderr, "irdm-fw: note: %s: removed %u director%s left by interrupted runs\n",
			fw->frames_dir.dir, fw->frames_dir.debris_removed,
			fw->frames_dir.debris_removed == 1 ? "y" : "ies");
	return rc;
}

/* The series into the claimed directory, then put in DIR's place. */
int fw_frame_write_series(struct fw *fw)
{
	const struct fw_frame *fr = &fw->frame;
	const char *dir = fw->args.frames_out;
	int e;

	if (!dir)
		return IRDM_OK;
	for (unsigned k = 0; k < fr->n_slots; k++)
		if (k != fr->single_slot && !fr->slot[k].held)
			return no_frame(fw, dir);
	e = write_series_into(fw, fw->frames_dir.tmp);
	if (e)
		return io_error(fw, fw->frames_dir.tmp, e);
	e = irdm_outdir_commit(&fw->frames_dir);
	if (e)
		snprintf(fw->err, sizeof(fw->err), "%.500s", fw->frames_dir.why);
	return e;
}
