/* SPDX-License-Identifier: MIT */
/*
 * VTK XML for ParaView: each frame an UnstructuredGrid (.vtu, ASCII) of the
 * image's nodes at their deformed positions and the displayed surface's
 * triangles, with the displacement per point and the contacts as field
 * data; the frames in a Collection (.pvd) with their times.
 */
#include <errno.h>
#include <stdio.h>

#include "render/render.h"

static void field_data(FILE *f, struct irdm_replay *r, double t_s)
{
	const struct irdm_engine *eng = irdm_replay_session(r)->eng;
	unsigned nc = irdm_replay_contacts(r);

	fprintf(f, "    <FieldData>\n"
		   "      <DataArray type=\"Float64\" Name=\"time_s\" NumberOfTuples=\"1\" format=\"ascii\">%.9g</DataArray>\n",
		t_s);
	fprintf(f, "      <DataArray type=\"Int32\" Name=\"contact\" NumberOfTuples=\"%u\" format=\"ascii\">",
		nc);
	for (unsigned i = 0; i < nc; i++)
		fprintf(f, " %d", irdm_engine_contact(eng, i)->mode != IRDM_CONTACT_OFF);
	fprintf(f, "</DataArray>\n      <DataArray type=\"Float64\" Name=\"contact_point_m\" "
		   "NumberOfComponents=\"3\" NumberOfTuples=\"%u\" format=\"ascii\">",
		nc);
	for (unsigned i = 0; i < nc; i++) {
		const struct irdm_contact_state *c = irdm_engine_contact(eng, i);
		for (int a = 0; a < 3; a++)
			fprintf(f, " %.9g", c->site.rest_m[a] + c->disp_m[a]);
	}
	fprintf(f, "</DataArray>\n      <DataArray type=\"Float64\" Name=\"contact_force_n\" "
		   "NumberOfComponents=\"3\" NumberOfTuples=\"%u\" format=\"ascii\">",
		nc);
	for (unsigned i = 0; i < nc; i++)
		for (int a = 0; a < 3; a++)
			fprintf(f, " %.9g", irdm_engine_contact(eng, i)->force_n[a]);
	fprintf(f, "</DataArray>\n    </FieldData>\n");
}

static void point_data(FILE *f, const struct irdm_image *img, const double *pos)
{
	uint32_t n = img->meta->n_nodes;

	fprintf(f, "      <PointData Vectors=\"displacement_m\">\n"
		   "        <DataArray type=\"Float64\" Name=\"displacement_m\" NumberOfComponents=\"3\" format=\"ascii\">\n");
	for (uint32_t k = 0; k < n; k++) {
		const float *rest = img->nodes[k].pos_m;
		const double *x = pos + 3 * (size_t)k;
		fprintf(f, "%.9g %.9g %.9g\n", x[0] - rest[0], x[1] - rest[1], x[2] - rest[2]);
	}
	fprintf(f, "        </DataArray>\n"
		   "        <DataArray type=\"UInt32\" Name=\"mesh_node\" format=\"ascii\">\n");
	for (uint32_t k = 0; k < n; k++)
		fprintf(f, "%u\n", img->nodes[k].mesh_node);
	fprintf(f, "        </DataArray>\n      </PointData>\n");
}

static void points(FILE *f, const struct irdm_image *img, const double *pos)
{
	fprintf(f, "      <Points>\n"
		   "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
	for (uint32_t k = 0; k < img->meta->n_nodes; k++)
		fprintf(f, "%.9g %.9g %.9g\n", pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]);
	fprintf(f, "        </DataArray>\n      </Points>\n");
}

/* The displayed surface: SURFACE's triangles (VTK_TRIANGLE = 5). */
static void cells(FILE *f, const struct irdm_image *img)
{
	uint32_t n = img->meta->n_tris;

	fprintf(f, "      <Cells>\n"
		   "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
	for (uint32_t t = 0; t < n; t++)
		fprintf(f, "%u %u %u\n", img->tris[3 * t], img->tris[3 * t + 1], img->tris[3 * t + 2]);
	fprintf(f, "        </DataArray>\n"
		   "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
	for (uint32_t t = 0; t < n; t++)
		fprintf(f, "%llu\n", 3ull * (t + 1));
	fprintf(f, "        </DataArray>\n"
		   "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
	for (uint32_t t = 0; t < n; t++)
		fputs("5\n", f);
	fprintf(f, "        </DataArray>\n      </Cells>\n");
}

int irdm_render_write_vtu(const char *path, struct irdm_replay *r, double t_s, const double *pos_m)
{
	const struct irdm_image *img = irdm_replay_session(r)->img;
	FILE *f = fopen(path, "w");
	int bad;

	if (!f)
		return errno;
	fprintf(f, "<?xml version=\"1.0\"?>\n"
		   "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
		   "  <UnstructuredGrid>\n");
	field_data(f, r, t_s);
	fprintf(f, "    <Piece NumberOfPoints=\"%u\" NumberOfCells=\"%u\">\n", img->meta->n_nodes,
		img->meta->n_tris);
	point_data(f, img, pos_m);
	points(f, img, pos_m);
	cells(f, img);
	fprintf(f, "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
	bad = ferror(f);
	if (fclose(f) || bad)
		return errno ? errno : EIO;
	return 0;
}

void irdm_render_pvd_begin(FILE *f)
{
	fprintf(f, "<?xml version=\"1.0\"?>\n"
		   "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
		   "  <Collection>\n");
}

void irdm_render_pvd_entry(FILE *f, double t_s, const char *file)
{
	fprintf(f, "    <DataSet timestep=\"%.9g\" group=\"\" part=\"0\" file=\"%s\"/>\n", t_s, file);
}

void irdm_render_pvd_end(FILE *f)
{
	fprintf(f, "  </Collection>\n</VTKFile>\n");
}
