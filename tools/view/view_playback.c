/* SPDX-License-Identifier: MIT */
/*
 * A recorded run as the view's recording (view_playback.h).  Times follow
 * the sample convention (docs/architecture.md): the surface after sample
 * (tick) k is the one at (k + 1) dt, and a frame there carries record k's
 * state and devices and the chart's samples since the previous frame.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "irdm/board.h"
#include "irdm/error.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "replay/replay.h"
#include "view/view_msg.h"
#include "view/view_playback.h"

#define RECORDS_MAX (3600u * 1000u) /* an hour at 1 kHz */

struct playback {
	const struct view_playback_opts *o;
	struct view_playback_summary *sum;
	struct view_server *srv;
	struct irdm_board board;
	struct irdm_tick_record *rec;
	size_t n_rec, every, next_sample;
	double dt;
	float *pos;
	struct view_sample *smp;
	unsigned char *msg;
	bool started;
};

static int read_log(struct playback *pb, char *err, size_t errlen)
{
	struct irdm_log_reader *r;
	const struct irdm_log_header *h;
	int rc = irdm_log_open(&r, pb->o->log, err, errlen);

	if (rc)
		return rc;
	h = irdm_log_header(r);
	if (h->record_count > RECORDS_MAX) {
		snprintf(err, errlen, "%s: %llu records: over the %u a playback holds", pb->o->log,
			 (unsigned long long)h->record_count, RECORDS_MAX);
		rc = IRDM_EINVAL;
		goto close;
	}
	pb->rec = malloc((h->record_count ? h->record_count : 1) * sizeof(*pb->rec));
	if (!pb->rec) {
		snprintf(err, errlen, "out of memory for %llu records",
			 (unsigned long long)h->record_count);
		rc = IRDM_ENOMEM;
		goto close;
	}
	while ((rc = irdm_log_next(r, &pb->rec[pb->n_rec], err, errlen)) == 1)
		pb->n_rec++;
close:
	irdm_log_close(r);
	return rc < 0 ? rc : rc ? rc :
				  IRDM_OK;
}

static int hello(struct playback *pb, const struct irdm_image *img, char *err, size_t errlen)
{
	struct view_hello h = { .mode = VIEW_MODE_PLAYBACK, .n_dev = pb->board.devices, .period_s = (float)pb->dt, .duration_s = (float)(pb->n_rec * pb->dt), .n_frames = (uint32_t)(pb->n_rec / pb->every), .name = pb->board.name };
	unsigned char *buf;
	size_t len = view_hello_image(&buf, img, &h);
	int rc = len ? view_server_set_hello(pb->srv, buf, len) : IRDM_ENOMEM;

	if (rc)
		snprintf(err, errlen, "out of memory for the mesh of %u nodes", img->meta->n_nodes);
	free(buf);
	return rc;
}

static int start(struct playback *pb, struct irdm_replay *r, char *err, size_t errlen)
{
	const struct irdm_image *img = irdm_replay_session(r)->img;
	double every = pb->o->every_s / img->meta->dt_s;

	pb->started = true;
	pb->dt = img->meta->dt_s;
	if (!(every >= 0.5) || every > (double)pb->n_rec) {
		snprintf(err, errlen, "--every %g: must be between the image's dt (%g s) and the "
				      "run's length (%g s)",
			 pb->o->every_s, pb->dt, pb->n_rec * pb->dt);
		return IRDM_EINVAL;
	}
	pb->every = (size_t)llround(every);
	pb->pos = malloc(12 * (size_t)(img->meta->n_nodes ? img->meta->n_nodes : 1));
	pb->smp = malloc(pb->every * sizeof(*pb->smp));
	pb->msg = malloc(view_frame_size(img->meta->n_nodes, (uint32_t)pb->every));
	if (!pb->pos || !pb->smp || !pb->msg) {
		snprintf(err, errlen, "out of memory for a frame");
		return IRDM_ENOMEM;
	}
	return hello(pb, img, err, errlen);
}

static int frame(struct playback *pb, struct irdm_replay *r, size_t row, char *err,
		 size_t errlen)
{
	const struct irdm_image *img = irdm_replay_session(r)->img;
	const double *pos = irdm_replay_positions(r);
	const struct irdm_tick_record *rec = &pb->rec[row];
	struct view_frame f;
	uint32_t n = 0;

	if (!pos) {
		snprintf(err, errlen, "internal: no deformed surface at t = %g s", (row + 1) * pb->dt);
		return IRDM_EINVAL;
	}
	for (size_t i = 0; i < 3 * (size_t)img->meta->n_nodes; i++)
		pb->pos[i] = (float)pos[i];
	for (; pb->next_sample <= row; pb->next_sample++)
		view_sample_from_record(&pb->smp[n++], &pb->rec[pb->next_sample], pb->dt);
	memset(&f, 0, sizeof(f));
	view_frame_from_record(&f, rec);
	for (unsigned i = 0; i < f.n_dev; i++) {
		double tip[3];

		irdm_board_device_to_object(&pb->board, rec->dev[i].tip_pos_m, tip);
		for (int k = 0; k < 3; k++)
			f.dev[i].tip_m[k] = (float)tip[k];
	}
	f.tick = f.newest_tick = (double)(row + 1);
	f.t_s = (double)(row + 1) * pb->dt;
	pb->sum->frames++;
	if (view_server_record(pb->srv, pb->msg, view_frame_write(pb->msg, &f, pb->pos, img->meta->n_nodes, pb->smp, n))) {
		snprintf(err, errlen, "out of memory for frame %zu", pb->sum->frames);
		return IRDM_ENOMEM;
	}
	return IRDM_OK;
}

static int on_tick(void *ctx, struct irdm_replay *r, char *err, size_t errlen)
{
	struct playback *pb = ctx;
	size_t row = irdm_replay_row(r);
	int rc = pb->started ? IRDM_OK : start(pb, r, err, errlen);

	if (rc || (row + 1) % pb->every || row >= pb->n_rec)
		return rc;
	return frame(pb, r, row, err, errlen);
}

/* The replay writes its forces CSV: into a directory of our own, removed. */
static int replay(struct playback *pb, char *err, size_t errlen)
{
	char tmp[] = "/tmp/irdm-view-XXXXXX", out[64];
	struct irdm_replay_opts in;
	struct irdm_replay_summary rs;
	int rc;

	if (!mkdtemp(tmp)) {
		snprintf(err, errlen, "%s: %s", tmp, strerror(errno));
		return IRDM_EIO;
	}
	snprintf(out, sizeof(out), "%s/forces.csv", tmp);
	irdm_replay_opts_default(&in);
	in.image = pb->o->image;
	in.log = pb->o->log;
	in.board = pb->o->board;
	in.out = out;
	in.deform = true;
	in.on_tick = on_tick;
	in.ctx = pb;
	rc = irdm_replay_run(&in, &rs, err, errlen);
	unlink(out);
	rmdir(tmp);
	pb->sum->log_max_diff_n = rs.log_max_diff_n;
	pb->sum->log_peak_n = rs.log_peak_n;
	return rc;
}

int view_playback_load(struct view_server *s, const struct view_playback_opts *o,
		       struct view_playback_summary *sum, char *err, size_t errlen)
{
	struct playback pb = { .o = o, .sum = sum, .srv = s };
	int rc;

	memset(sum, 0, sizeof(*sum));
	rc = irdm_board_load(&pb.board, o->board, err, errlen);
	if (!rc)
		rc = read_log(&pb, err, errlen);
	if (!rc)
		rc = replay(&pb, err, errlen);
	sum->records = pb.n_rec;
	sum->duration_s = pb.n_rec * pb.dt;
	free(pb.rec);
	free(pb.pos);
	free(pb.smp);
	free(pb.msg);
	return rc;
}
