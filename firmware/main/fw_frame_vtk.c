/* SPDX-License-Identifier: MIT */
/*
 * The kept frames of the deformed surface as legacy VTK: --frame-at's one
 * file, and --frames-every's series, a directory of frame_NNNNN.vtk with a
 * frames.vtk.series index (ParaView's JSON file-series format: each file
 * and its time), so ParaView opens the series with its times.  Each is
 * written beside its destination and renamed into place: a reader never
 * sees half a frame or half a series (irdm/outdir.h).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/outdir.h"

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
static int write_file(const struct fw *fw, const struct fw_frame_slot *sl, const char *path)
{
	FILE *f = fopen(path, "w");
	int bad;

	if (!f)
		return errno;
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

/* Written to FILE.tmp and renamed: a reader never sees half a frame. */
int fw_frame_write(struct fw *fw)
{
	const char *path = fw->args.frame_out;
	char tmp[4096];
	int e;

	if (!path)
		return IRDM_OK;
	if (!fw->frame.slot[fw->frame.single_slot].held)
		return no_frame(fw, path);
	if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= sizeof(tmp)) {
		snprintf(fw->err, sizeof(fw->err), "%s: path too long", path);
		return IRDM_EINVAL;
	}
	e = write_file(fw, &fw->frame.slot[fw->frame.single_slot], tmp);
	if (!e && rename(tmp, path))
		e = errno;
	if (e) {
		remove(tmp);
		return io_error(fw, path, e);
	}
	return IRDM_OK;
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

		if (k == fr->single_slot)
			continue;
		snprintf(path, sizeof(path), "%s/frame_%05u.vtk", dir, ++n);
		e = write_file(fw, sl, path);
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

/* The series into DIR.tmp, then swapped in for DIR (irdm/outdir.h). */
int fw_frame_write_series(struct fw *fw)
{
	const struct fw_frame *fr = &fw->frame;
	const char *dir = fw->args.frames_out;
	char tmp[4096];
	int e;

	if (!dir)
		return IRDM_OK;
	for (unsigned k = 0; k < fr->n_slots; k++)
		if (k != fr->single_slot && !fr->slot[k].held)
			return no_frame(fw, dir);
	e = irdm_outdir_begin(dir, tmp, sizeof(tmp));
	if (e == ENAMETOOLONG) {
		snprintf(fw->err, sizeof(fw->err), "%s: path too long", dir);
		return IRDM_EINVAL;
	}
	if (e)
		return io_error(fw, tmp, e);
	e = write_series_into(fw, tmp);
	if (e)
		irdm_outdir_remove(tmp);
	else
		e = irdm_outdir_commit(dir, tmp);
	return e ? io_error(fw, dir, e) : IRDM_OK;
}
