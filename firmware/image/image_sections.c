/* SPDX-License-Identifier: MIT */
/*
 * The section table's entries and the file layout they describe: element
 * types, alignment and bounds of every payload, no overlap between header,
 * table and payloads, zero padding, payload checksums and unique kinds.
 * Ends by indexing the sections by kind for the semantic checks.
 */
#include <stdint.h>
#include <stdio.h>

#include "image_priv.h"

/* A byte range of the file that something owns: header, table or payload. */
struct region {
	uint64_t off;
	uint64_t end;
	int sec; /* section index, or REGION_* */
};

#define REGION_HEADER (-1)
#define REGION_TABLE (-2)

static int check_entry(struct parse *p, unsigned i)
{
	const struct irdm_image_section *s = &p->tab[i];
	size_t es = irdm_elem_size(s->elem);

	if (p->strict && s->reserved)
		return img_fail(p, IRDM_EFORMAT,
				"section #%u (%s): reserved field is 0x%08x, not 0",
				i, img_kind_name(s->kind), s->reserved);
	if (!es)
		return img_fail(p, IRDM_EFORMAT,
				"section #%u (%s): unknown element type %u",
				i, img_kind_name(s->kind), s->elem);
	if (s->offset % IRDM_IMAGE_ALIGN)
		return img_fail(p, IRDM_ERANGE,
				"section #%u (%s): offset %llu is not a multiple of %u",
				i, img_kind_name(s->kind),
				(unsigned long long)s->offset, IRDM_IMAGE_ALIGN);
	if (s->offset > p->size || s->size > p->size - s->offset)
		return img_fail(p, IRDM_ERANGE,
				"section #%u (%s): payload at %llu, %llu bytes, runs past the end of the %llu-byte file",
				i, img_kind_name(s->kind),
				(unsigned long long)s->offset,
				(unsigned long long)s->size,
				(unsigned long long)p->size);
	if (s->size % es)
		return img_fail(p, IRDM_ERANGE,
				"section #%u (%s): size %llu is not a multiple of its %s element size %zu",
				i, img_kind_name(s->kind), (unsigned long long)s->size,
				img_elem_name(s->elem), es);
	return IRDM_OK;
}

static void describe(const struct parse *p, const struct region *r,
		     char *buf, size_t len)
{
	const char *what;

	if (r->sec == REGION_HEADER)
		what = "the header";
	else if (r->sec == REGION_TABLE)
		what = "the section table";
	else
		what = NULL;
	if (what)
		snprintf(buf, len, "%s [%llu, %llu)", what,
			 (unsigned long long)r->off, (unsigned long long)r->end);
	else
		snprintf(buf, len, "section #%d (%s) [%llu, %llu)", r->sec,
			 img_kind_name(p->tab[r->sec].kind),
			 (unsigned long long)r->off, (unsigned long long)r->end);
}

static void sort_regions(struct region *r, unsigned n)
{
	for (unsigned i = 1; i < n; i++) {
		struct region key = r[i];
		unsigned j = i;

		while (j > 0 && (r[j - 1].off > key.off ||
				 (r[j - 1].off == key.off && r[j - 1].end > key.end))) {
			r[j] = r[j - 1];
			j--;
		}
		r[j] = key;
	}
}

static unsigned collect_regions(const struct parse *p, struct region *r)
{
	unsigned n = 0;

	r[n++] = (struct region){ 0, HEADER_SIZE, REGION_HEADER };
	r[n++] = (struct region){ p->hdr.section_table_offset,
				  p->hdr.section_table_offset +
					  (uint64_t)p->n * TABLE_ENTRY,
				  REGION_TABLE };
	for (unsigned i = 0; i < p->n; i++)
		r[n++] = (struct region){ p->tab[i].offset,
					  p->tab[i].offset + p->tab[i].size,
					  (int)i };
	sort_regions(r, n);
	return n;
}

/*
 * No two of header, table and payloads may share a byte, and every byte that
 * none of them owns (alignment padding) must be zero.  Padding is covered by
 * no checksum; requiring it to be zero makes every single-byte corruption of
 * the file detectable.
 */
static int check_layout(struct parse *p)
{
	struct region r[IRDM_IMAGE_MAX_SECTIONS + 2];
	unsigned n = collect_regions(p, r);
	uint64_t covered = 0; /* end of the furthest region so far */
	unsigned last = 0;    /* region that reaches it */
	char a[96], b[96];

	for (unsigned i = 0; i < n; i++) {
		if (r[i].off < covered) {
			describe(p, &r[last], a, sizeof(a));
			describe(p, &r[i], b, sizeof(b));
			return img_fail(p, IRDM_ERANGE, "%s and %s overlap", a, b);
		}
		for (uint64_t o = covered; o < r[i].off; o++)
			if (p->base[o])
				return img_fail(p, IRDM_EFORMAT,
						"padding byte at offset %llu is 0x%02x, not 0",
						(unsigned long long)o, p->base[o]);
		if (r[i].end > covered) {
			covered = r[i].end;
			last = i;
		}
	}
	for (uint64_t o = covered; o < p->size; o++)
		if (p->base[o])
			return img_fail(p, IRDM_EFORMAT,
					"padding byte at offset %llu is 0x%02x, not 0",
					(unsigned long long)o, p->base[o]);
	return IRDM_OK;
}

int img_check_sections(struct parse *p)
{
	int ret;

	for (unsigned i = 0; i < p->n; i++) {
		ret = check_entry(p, i);
		if (ret)
			return ret;
	}
	ret = check_layout(p);
	if (ret)
		return ret;
	for (unsigned i = 0; i < p->n; i++) {
		const struct irdm_image_section *s = &p->tab[i];
		uint32_t crc;

		if (!img_crc_matches(p->base + s->offset, s->size, s->crc32c, &crc))
			return img_fail(p, IRDM_ECRC,
					"section #%u (%s) checksum mismatch: stored 0x%08x, computed 0x%08x",
					i, img_kind_name(s->kind), s->crc32c, crc);
	}
	for (unsigned i = 0; i < p->n; i++)
		for (unsigned j = 0; j < i; j++)
			if (p->tab[i].kind == p->tab[j].kind)
				return img_fail(p, IRDM_EMISSING,
						"section kind %u (%s) appears twice: #%u and #%u",
						p->tab[i].kind,
						img_kind_name(p->tab[i].kind), j, i);
	for (unsigned i = 0; i < p->n; i++)
		if (p->tab[i].kind <= KIND_MAX)
			p->by_kind[p->tab[i].kind] = &p->tab[i];
	return IRDM_OK;
}
