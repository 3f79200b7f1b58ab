/* SPDX-License-Identifier: MIT */
#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image_writer.h"
#include "irdm/image.h"
#include "irdm/posix/textfile.h"
#include "precompute/td_part.h"

#define PART_MAGIC "IRDMPART"

struct part_header {
	char magic[8];
	uint64_t version;
	uint64_t scene_hash, n_inputs, begin, end, T, n_out;
	uint32_t data_crc32c;
	uint32_t header_crc32c;
};

/* A part is written to "<path>.tmp" and renamed into place, so a reader
 * never sees half a part. */
int irdm_td_part_write(const char *path, const struct irdm_td_part *p, char *err, size_t errlen)
{
	struct part_header h = { .version = 1, .scene_hash = p->scene_hash, .n_inputs = p->n_inputs, .begin = p->begin, .end = p->end, .T = p->T, .n_out = p->n_out };
	size_t n = (size_t)((p->end - p->begin) * p->T * p->n_out);
	char tmp[4096];
	FILE *f;

	memcpy(h.magic, PART_MAGIC, 8);
	h.data_crc32c = irdm_crc32c(p->data, n * sizeof(double));
	h.header_crc32c = irdm_crc32c(&h, offsetof(struct part_header, header_crc32c));
	if (snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= (int)sizeof(tmp)) {
		snprintf(err, errlen, "%s: path too long", path);
		return IRDM_EINVAL;
	}
	f = fopen(tmp, "wb");
	if (!f) {
		snprintf(err, errlen, "%s: cannot create: %s", tmp, strerror(errno));
		return IRDM_EIO;
	}
	if (fwrite(&h, sizeof(h), 1, f) != 1 || fwrite(p->data, sizeof(double), n, f) != n ||
	    fflush(f) || fclose(f)) {
		snprintf(err, errlen, "%s: write failed: %s", tmp, strerror(errno));
		remove(tmp);
		return IRDM_EIO;
	}
	if (rename(tmp, path)) {
		snprintf(err, errlen, "%s: cannot rename into place: %s", path, strerror(errno));
		remove(tmp);
		return IRDM_EIO;
	}
	return IRDM_OK;
}

int irdm_td_part_read(const char *path, struct irdm_td_part *p, char *err, size_t errlen)
{
	struct part_header h;
	FILE *f;
	int ret = IRDM_EFORMAT;

	memset(p, 0, sizeof(*p));
	if (irdm_file_fopen(path, IRDM_DATA_MAX_BYTES, &f, err, errlen))
		return IRDM_EIO;
	if (fread(&h, sizeof(h), 1, f) != 1 || memcmp(h.magic, PART_MAGIC, 8) || h.version != 1 ||
	    h.header_crc32c != irdm_crc32c(&h, offsetof(struct part_header, header_crc32c))) {
		snprintf(err, errlen, "%s: not a time-domain part file (bad magic, version or header checksum)", path);
		goto out_close;
	}
	if (h.begin >= h.end || h.end > h.n_inputs || h.T == 0 || h.T > 1000000 ||
	    h.n_out == 0 || h.n_out > 30000000 || (h.end - h.begin) > (1u << 24) ||
	    (h.end - h.begin) * h.T > ((uint64_t)1 << 40) / h.n_out) {
		snprintf(err, errlen, "%s: part header has impossible sizes", path);
		goto out_close;
	}
	size_t n = (size_t)((h.end - h.begin) * h.T * h.n_out);
	p->data = malloc(n * sizeof(double));
	if (!p->data) {
		snprintf(err, errlen, "%s: out of memory for %zu values", path, n);
		ret = IRDM_ENOMEM;
		goto out_close;
	}
	if (fread(p->data, sizeof(double), n, f) != n || fgetc(f) != EOF ||
	    irdm_crc32c(p->data, n * sizeof(double)) != h.data_crc32c) {
		snprintf(err, errlen, "%s: part data is truncated, too long or corrupted", path);
		free(p->data);
		p->data = NULL;
		goto out_close;
	}
	p->scene_hash = h.scene_hash;
	p->n_inputs = h.n_inputs;
	p->begin = h.begin;
	p->end = h.end;
	p->T = h.T;
	p->n_out = h.n_out;
	ret = IRDM_OK;
out_close:
	fclose(f);
	return ret;
}
