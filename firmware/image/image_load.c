/* SPDX-License-Identifier: MIT */
/*
 * Flash image loader.  An image comes from a file that may be truncated,
 * corrupted or hostile, so nothing in it is trusted until checked: the
 * header and section table are copied out and validated (magic, version,
 * sizes, checksums, offsets, alignment, overlap, zero padding), then every
 * known section is checked against the meta data (counts, sizes, index
 * ranges, finiteness) before a single view is handed out.  No byte outside
 * [base, base + size) is ever read.  See docs/image-format.md.
 *
 * The checks run in a fixed order and the first failure wins, so an error
 * names the most basic thing that is wrong.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/image.h"

/* Views are plain struct pointers into the file: only a little-endian host
 * can use them in place. */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && \
	__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "IRDM images are little-endian and used in place"
#endif

#define KIND_MAX IRDM_SEC_CONTACT_BVH
#define TABLE_ENTRY sizeof(struct irdm_image_section)
#define HEADER_SIZE sizeof(struct irdm_image_header)
#define HEADER_CRC_LEN offsetof(struct irdm_image_header, header_crc32c)
#define META_FLAGS_KNOWN (IRDM_META_FLOATING | IRDM_META_STATIC_CORR | \
			  IRDM_META_CONSISTENT_MASS | IRDM_META_TIME_DOMAIN)

/* Element type each known kind must declare; PRECISION means meta's. */
#define ELEM_PRECISION 0xfffffffeu
#define ELEM_ANY 0xffffffffu

static const struct {
	const char *name;
	uint32_t elem;
} kinds[KIND_MAX + 1] = {
	[IRDM_SEC_META] = { "META", IRDM_ELEM_BYTES },
	[IRDM_SEC_PROVENANCE] = { "PROVENANCE", IRDM_ELEM_BYTES },
	[IRDM_SEC_NODES] = { "NODES", IRDM_ELEM_BYTES },
	[IRDM_SEC_COLUMNS] = { "COLUMNS", IRDM_ELEM_U32 },
	[IRDM_SEC_SURFACE] = { "SURFACE", IRDM_ELEM_U32 },
	[IRDM_SEC_FIR] = { "FIR", ELEM_PRECISION },
	[IRDM_SEC_MODES] = { "MODES", IRDM_ELEM_BYTES },
	[IRDM_SEC_MODE_SHAPES] = { "MODE_SHAPES", ELEM_PRECISION },
	[IRDM_SEC_STATIC_CORR] = { "STATIC_CORR", ELEM_PRECISION },
	[IRDM_SEC_RIGID] = { "RIGID", IRDM_ELEM_BYTES },
	[IRDM_SEC_STABILITY] = { "STABILITY", IRDM_ELEM_BYTES },
	[IRDM_SEC_CONTACT_BVH] = { "CONTACT_BVH", ELEM_ANY },
};

static const char *const elem_names[] = {
	[IRDM_ELEM_BYTES] = "BYTES",
	[IRDM_ELEM_F16] = "F16",
	[IRDM_ELEM_F32] = "F32",
	[IRDM_ELEM_F64] = "F64",
	[IRDM_ELEM_U32] = "U32",
};

/* A byte range of the file that something owns: header, table or payload. */
struct region {
	uint64_t off;
	uint64_t end;
	int sec;                        /* section index, or REGION_* */
};

#define REGION_HEADER (-1)
#define REGION_TABLE (-2)

/* State of one parse. */
struct parse {
	const uint8_t *base;
	uint64_t size;
	struct irdm_image_header hdr;   /* copies: the mapping may change */
	struct irdm_image_section tab[IRDM_IMAGE_MAX_SECTIONS];
	unsigned n;
	bool strict;                    /* our minor: reserved must be 0 */
	const struct irdm_image_section *by_kind[KIND_MAX + 1];
	struct irdm_meta meta;
	size_t es;                      /* bytes per element of precision */
	struct irdm_image img;
	char *err;
	size_t errlen;
};

static int vreport(char *buf, size_t len, int code, const char *fmt,
		   va_list ap)
{
	if (buf && len)
		vsnprintf(buf, len, fmt, ap);
	return code;
}

/* Write a one-line reason into buf (if any) and return code. */
static int report(char *buf, size_t len, int code, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	code = vreport(buf, len, code, fmt, ap);
	va_end(ap);
	return code;
}

static int fail(struct parse *p, int code, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	code = vreport(p->err, p->errlen, code, fmt, ap);
	va_end(ap);
	return code;
}

static const char *kind_name(uint32_t kind)
{
	if (kind <= KIND_MAX && kinds[kind].name)
		return kinds[kind].name;
	return "unknown kind";
}

static const char *elem_name(uint32_t elem)
{
	if (elem < sizeof(elem_names) / sizeof(elem_names[0]))
		return elem_names[elem];
	return "unknown";
}

/*
 * Checksum comparison.  The fuzz build of the semantic checks defines
 * IRDM_FUZZ_SKIP_CRC: a fuzzer almost never produces a matching CRC-32C, so
 * without this it would never get past the checksums to the code that
 * validates counts, sizes and indices.  Never define it anywhere else.
 */
static bool crc_matches(const void *data, uint64_t len, uint32_t stored,
			uint32_t *computed)
{
#ifdef IRDM_FUZZ_SKIP_CRC
	(void)data;
	(void)len;
	*computed = stored;
	return true;
#else
	*computed = irdm_crc32c(data, (size_t)len);
	return *computed == stored;
#endif
}

static bool mul_ok(uint64_t *r, const uint64_t *f, unsigned n)
{
	uint64_t acc = 1;

	for (unsigned i = 0; i < n; i++) {
		if (f[i] && acc > UINT64_MAX / f[i])
			return false;
		acc *= f[i];
	}
	*r = acc;
	return true;
}

static bool all_zero(const void *data, size_t len)
{
	const uint8_t *b = data;

	for (size_t i = 0; i < len; i++)
		if (b[i])
			return false;
	return true;
}

static bool f64_finite(double d)
{
	uint64_t x;

	memcpy(&x, &d, sizeof(x));
	return (x & 0x7ff0000000000000u) != 0x7ff0000000000000u;
}

static bool f32_finite(float f)
{
	uint32_t x;

	memcpy(&x, &f, sizeof(x));
	return (x & 0x7f800000u) != 0x7f800000u;
}

/* Index of the first non-finite element of an array, or count if none. */
static uint64_t first_non_finite(const void *data, uint32_t elem, uint64_t count)
{
	const uint8_t *b = data;
	uint64_t i;

	for (i = 0; i < count; i++) {
		uint16_t h;
		uint32_t x;
		uint64_t d;

		switch (elem) {
		case IRDM_ELEM_F16:
			memcpy(&h, b + i * 2, sizeof(h));
			if ((h & 0x7c00u) == 0x7c00u)
				return i;
			break;
		case IRDM_ELEM_F32:
			memcpy(&x, b + i * 4, sizeof(x));
			if ((x & 0x7f800000u) == 0x7f800000u)
				return i;
			break;
		default:
			memcpy(&d, b + i * 8, sizeof(d));
			if ((d & 0x7ff0000000000000u) == 0x7ff0000000000000u)
				return i;
			break;
		}
	}
	return i;
}

/* ---------------------------------------------------------------- header */

static int check_header(struct parse *p)
{
	const struct irdm_image_header *h = &p->hdr;
	uint32_t crc;

	if (p->size < HEADER_SIZE)
		return fail(p, IRDM_IMAGE_ETRUNC,
			    "image is truncated: file has %llu bytes, the header alone needs %zu",
			    (unsigned long long)p->size, HEADER_SIZE);
	memcpy(&p->hdr, p->base, HEADER_SIZE);
	if (memcmp(h->magic, IRDM_IMAGE_MAGIC, sizeof(h->magic)))
		return fail(p, IRDM_IMAGE_EMAGIC,
			    "not an IRDM image: magic bytes are %02x %02x %02x %02x %02x %02x %02x %02x, expected \"IRDMIMG\\0\"",
			    h->magic[0], h->magic[1], h->magic[2], h->magic[3],
			    h->magic[4], h->magic[5], h->magic[6], h->magic[7]);
	if (h->version_major != IRDM_IMAGE_VERSION_MAJOR)
		return fail(p, IRDM_IMAGE_EVERSION,
			    "image format version %u.%u is not supported: this loader reads %u.x",
			    h->version_major, h->version_minor,
			    IRDM_IMAGE_VERSION_MAJOR);
	if (h->header_size != HEADER_SIZE)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "header_size is %u, version 1 headers are %zu bytes",
			    h->header_size, HEADER_SIZE);
	/* Checksum the copies: what is checked is exactly what was summed. */
	if (!crc_matches(&p->hdr, HEADER_CRC_LEN, h->header_crc32c, &crc))
		return fail(p, IRDM_IMAGE_ECRC,
			    "header checksum mismatch: stored 0x%08x, computed 0x%08x",
			    h->header_crc32c, crc);
	if (h->file_size > p->size)
		return fail(p, IRDM_IMAGE_ETRUNC,
			    "image is truncated: header says %llu bytes, file has %llu",
			    (unsigned long long)h->file_size,
			    (unsigned long long)p->size);
	if (h->file_size < p->size)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "image has %llu trailing bytes: header says %llu bytes, file has %llu",
			    (unsigned long long)(p->size - h->file_size),
			    (unsigned long long)h->file_size,
			    (unsigned long long)p->size);
	/* A newer minor version may give meaning to reserved fields. */
	p->strict = h->version_minor <= IRDM_IMAGE_VERSION_MINOR;
	if (p->strict && (h->flags || !all_zero(h->reserved, sizeof(h->reserved))))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "header flags (0x%08x) or reserved bytes are not zero in a version %u.%u image",
			    h->flags, h->version_major, h->version_minor);
	return IRDM_IMAGE_OK;
}

static int check_table(struct parse *p)
{
	const struct irdm_image_header *h = &p->hdr;
	uint64_t off = h->section_table_offset;
	uint64_t len;
	uint32_t crc;

	if (h->section_count < 1 || h->section_count > IRDM_IMAGE_MAX_SECTIONS)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section_count is %u, must be 1..%u",
			    h->section_count, IRDM_IMAGE_MAX_SECTIONS);
	p->n = h->section_count;
	len = (uint64_t)p->n * TABLE_ENTRY;
	if (off % IRDM_IMAGE_ALIGN || off < HEADER_SIZE)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "section table offset %llu is not a multiple of %u past the header",
			    (unsigned long long)off, IRDM_IMAGE_ALIGN);
	if (off > p->size || len > p->size - off)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "section table [%llu, %llu) lies outside the %llu-byte file",
			    (unsigned long long)off,
			    (unsigned long long)(off + len),
			    (unsigned long long)p->size);
	memcpy(p->tab, p->base + off, (size_t)len);
	if (!crc_matches(p->tab, len, h->table_crc32c, &crc))
		return fail(p, IRDM_IMAGE_ECRC,
			    "section table checksum mismatch: stored 0x%08x, computed 0x%08x",
			    h->table_crc32c, crc);
	return IRDM_IMAGE_OK;
}

/* -------------------------------------------------------------- sections */

static int check_entry(struct parse *p, unsigned i)
{
	const struct irdm_image_section *s = &p->tab[i];
	size_t es = irdm_elem_size(s->elem);

	if (p->strict && s->reserved)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section #%u (%s): reserved field is 0x%08x, not 0",
			    i, kind_name(s->kind), s->reserved);
	if (!es)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section #%u (%s): unknown element type %u",
			    i, kind_name(s->kind), s->elem);
	if (s->offset % IRDM_IMAGE_ALIGN)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "section #%u (%s): offset %llu is not a multiple of %u",
			    i, kind_name(s->kind),
			    (unsigned long long)s->offset, IRDM_IMAGE_ALIGN);
	if (s->offset > p->size || s->size > p->size - s->offset)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "section #%u (%s): payload at %llu, %llu bytes, runs past the end of the %llu-byte file",
			    i, kind_name(s->kind),
			    (unsigned long long)s->offset,
			    (unsigned long long)s->size,
			    (unsigned long long)p->size);
	if (s->size % es)
		return fail(p, IRDM_IMAGE_ERANGE,
			    "section #%u (%s): size %llu is not a multiple of its %s element size %zu",
			    i, kind_name(s->kind), (unsigned long long)s->size,
			    elem_name(s->elem), es);
	return IRDM_IMAGE_OK;
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
			 kind_name(p->tab[r->sec].kind),
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
				  (uint64_t)p->n * TABLE_ENTRY, REGION_TABLE };
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
	uint64_t covered = 0;           /* end of the furthest region so far */
	unsigned last = 0;              /* region that reaches it */
	char a[96], b[96];

	for (unsigned i = 0; i < n; i++) {
		if (r[i].off < covered) {
			describe(p, &r[last], a, sizeof(a));
			describe(p, &r[i], b, sizeof(b));
			return fail(p, IRDM_IMAGE_ERANGE, "%s and %s overlap", a, b);
		}
		for (uint64_t o = covered; o < r[i].off; o++)
			if (p->base[o])
				return fail(p, IRDM_IMAGE_EINVAL,
					    "padding byte at offset %llu is 0x%02x, not 0",
					    (unsigned long long)o, p->base[o]);
		if (r[i].end > covered) {
			covered = r[i].end;
			last = i;
		}
	}
	for (uint64_t o = covered; o < p->size; o++)
		if (p->base[o])
			return fail(p, IRDM_IMAGE_EINVAL,
				    "padding byte at offset %llu is 0x%02x, not 0",
				    (unsigned long long)o, p->base[o]);
	return IRDM_IMAGE_OK;
}

static int check_sections(struct parse *p)
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

		if (!crc_matches(p->base + s->offset, s->size, s->crc32c, &crc))
			return fail(p, IRDM_IMAGE_ECRC,
				    "section #%u (%s) checksum mismatch: stored 0x%08x, computed 0x%08x",
				    i, kind_name(s->kind), s->crc32c, crc);
	}
	for (unsigned i = 0; i < p->n; i++)
		for (unsigned j = 0; j < i; j++)
			if (p->tab[i].kind == p->tab[j].kind)
				return fail(p, IRDM_IMAGE_EMISSING,
					    "section kind %u (%s) appears twice: #%u and #%u",
					    p->tab[i].kind,
					    kind_name(p->tab[i].kind), j, i);
	for (unsigned i = 0; i < p->n; i++)
		if (p->tab[i].kind <= KIND_MAX)
			p->by_kind[p->tab[i].kind] = &p->tab[i];
	return IRDM_IMAGE_OK;
}

/* ------------------------------------------------------------- semantics */

static const void *payload(const struct parse *p, uint32_t kind)
{
	const struct irdm_image_section *s = p->by_kind[kind];

	return s ? p->base + s->offset : NULL;
}

/* Presence rule: the section must be there iff wanted. */
static int check_presence(struct parse *p, uint32_t kind, bool wanted,
			  const char *why)
{
	bool have = p->by_kind[kind] != NULL;

	if (wanted && !have)
		return fail(p, IRDM_IMAGE_EMISSING,
			    "required section %s is missing (%s)",
			    kind_name(kind), why);
	if (!wanted && have)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section %s must not be present (%s)",
			    kind_name(kind), why);
	return IRDM_IMAGE_OK;
}

/*
 * A present known section has the element type of its kind and exactly the
 * size the meta counts give: the product of factors (checked for overflow)
 * times the element size.
 */
static int check_shape(struct parse *p, uint32_t kind, const uint64_t *f,
		       unsigned nf, const char *formula)
{
	const struct irdm_image_section *s = p->by_kind[kind];
	uint32_t elem = kinds[kind].elem;
	uint64_t want;

	if (!s)
		return IRDM_IMAGE_OK;
	if (elem == ELEM_PRECISION)
		elem = p->meta.precision;
	if (s->elem != elem)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section %s has element type %s, expected %s",
			    kind_name(kind), elem_name(s->elem), elem_name(elem));
	if (!mul_ok(&want, f, nf) || !mul_ok(&want, (uint64_t[]){ want,
			irdm_elem_size(elem) }, 2))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section %s: expected size %s x %zu overflows",
			    kind_name(kind), formula, irdm_elem_size(elem));
	if (s->size != want && elem == IRDM_ELEM_BYTES)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section %s has %llu bytes, expected %llu (%s)",
			    kind_name(kind), (unsigned long long)s->size,
			    (unsigned long long)want, formula);
	if (s->size != want)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section %s has %llu bytes, expected %llu (%s x %zu)",
			    kind_name(kind), (unsigned long long)s->size,
			    (unsigned long long)want, formula,
			    irdm_elem_size(elem));
	return IRDM_IMAGE_OK;
}

static int check_meta_numbers(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const struct {
		const char *name;
		double v;
	} d[] = {
		{ "dt_s", m->dt_s },
		{ "young_pa", m->young_pa },
		{ "poisson", m->poisson },
		{ "density_kg_m3", m->density_kg_m3 },
		{ "rayleigh_a_per_s", m->rayleigh_a_per_s },
		{ "rayleigh_b_s", m->rayleigh_b_s },
		{ "damping_ratio[0]", m->damping_ratio[0] },
		{ "damping_ratio[1]", m->damping_ratio[1] },
		{ "damping_freq_hz[0]", m->damping_freq_hz[0] },
		{ "damping_freq_hz[1]", m->damping_freq_hz[1] },
		{ "max_spectral_radius", m->max_spectral_radius },
		{ "first_elastic_hz", m->first_elastic_hz },
	};

	for (size_t i = 0; i < sizeof(d) / sizeof(d[0]); i++)
		if (!f64_finite(d[i].v))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "meta %s is not finite", d[i].name);
	if (!(m->dt_s > 0 && m->dt_s <= 1))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta dt_s is %g s, must be in (0, 1]", m->dt_s);
	if (!(m->young_pa > 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta young_pa is %g, must be > 0", m->young_pa);
	if (!(m->poisson > -1 && m->poisson < 0.5))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta poisson is %g, must be in (-1, 0.5)", m->poisson);
	if (!(m->density_kg_m3 > 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta density_kg_m3 is %g, must be > 0",
			    m->density_kg_m3);
	return IRDM_IMAGE_OK;
}

static int check_meta_counts(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;

	if (m->n_nodes < 1 || m->n_cols < 1 || m->n_cols > m->n_nodes)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta n_nodes %u, n_cols %u: need 1 <= n_cols <= n_nodes",
			    m->n_nodes, m->n_cols);
	if (m->representation == IRDM_REPR_FIR &&
	    (m->fir_length < 1 || m->n_modes != 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "FIR image has fir_length %u, n_modes %u: need T >= 1 and no modes",
			    m->fir_length, m->n_modes);
	if (m->representation == IRDM_REPR_MODAL &&
	    (m->n_modes < 1 || m->fir_length != 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "modal image has n_modes %u, fir_length %u: need modes >= 1 and T = 0",
			    m->n_modes, m->fir_length);
	if (m->representation == IRDM_REPR_FIR &&
	    (m->flags & IRDM_META_STATIC_CORR))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "FIR image has the STATIC_CORR flag (modal only)");
	return IRDM_IMAGE_OK;
}

static int check_meta(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_META];
	const struct irdm_meta *m = &p->meta;
	int ret;

	ret = check_presence(p, IRDM_SEC_META, true, "always");
	if (ret)
		return ret;
	ret = check_presence(p, IRDM_SEC_PROVENANCE, true, "always");
	if (ret)
		return ret;
	if (s->size != sizeof(struct irdm_meta) || s->elem != IRDM_ELEM_BYTES)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section META has %llu bytes of %s, expected %zu of BYTES",
			    (unsigned long long)s->size, elem_name(s->elem),
			    sizeof(struct irdm_meta));
	memcpy(&p->meta, p->base + s->offset, sizeof(p->meta));
	if (m->representation != IRDM_REPR_FIR &&
	    m->representation != IRDM_REPR_MODAL)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta representation is %u, expected 1 (FIR) or 2 (MODAL)",
			    m->representation);
	if (m->precision != IRDM_ELEM_F16 && m->precision != IRDM_ELEM_F32 &&
	    m->precision != IRDM_ELEM_F64)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta precision is %u, expected 1 (F16), 2 (F32) or 3 (F64)",
			    m->precision);
	p->es = irdm_elem_size(m->precision);
	if (p->strict && ((m->flags & ~META_FLAGS_KNOWN) || m->reserved0 ||
			  !all_zero(m->reserved, sizeof(m->reserved))))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta has unknown flags (0x%08x) or non-zero reserved fields",
			    m->flags);
	if (!memchr(m->tool_version, 0, sizeof(m->tool_version)) ||
	    !memchr(m->mesh_name, 0, sizeof(m->mesh_name)))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "meta tool_version or mesh_name is not NUL-terminated");
	ret = check_meta_numbers(p);
	if (ret)
		return ret;
	return check_meta_counts(p);
}

static int check_provenance(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_PROVENANCE];
	const char *text = payload(p, IRDM_SEC_PROVENANCE);

	if (s->elem != IRDM_ELEM_BYTES)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "section PROVENANCE has element type %s, expected BYTES",
			    elem_name(s->elem));
	/* Text the firmware prints: an embedded NUL would hide the rest. */
	if (memchr(text, 0, (size_t)s->size))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "PROVENANCE contains a NUL byte at offset %td",
			    (const char *)memchr(text, 0, (size_t)s->size) - text);
	p->img.provenance = text;
	p->img.provenance_len = (size_t)s->size;
	return IRDM_IMAGE_OK;
}

static int check_nodes(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const struct irdm_node *nodes;
	int ret;

	ret = check_presence(p, IRDM_SEC_NODES, true, "always");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_NODES,
				  (uint64_t[]){ m->n_nodes, sizeof(*nodes) }, 2,
				  "n_nodes x 16");
	if (ret)
		return ret;
	nodes = payload(p, IRDM_SEC_NODES);
	for (uint32_t i = 0; i < m->n_nodes; i++) {
		const struct irdm_node *nd = &nodes[i];

		if (!f32_finite(nd->pos_m[0]) || !f32_finite(nd->pos_m[1]) ||
		    !f32_finite(nd->pos_m[2]))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "node %u has a non-finite position", i);
		/* mesh_nodes 0: responses not from a mesh (e.g. measured). */
		if (m->mesh_nodes && nd->mesh_node >= m->mesh_nodes)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "node %u: mesh_node %u >= mesh_nodes %u",
				    i, nd->mesh_node, m->mesh_nodes);
	}
	p->img.nodes = nodes;
	return IRDM_IMAGE_OK;
}

/* Column indices must name distinct rows; a bitmap finds repeats in O(n).
 * Allocating is fine here: this is initialisation, not the loop. */
static int check_columns(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint32_t *cols;
	uint8_t *seen;
	int ret;

	ret = check_presence(p, IRDM_SEC_COLUMNS, true, "always");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_COLUMNS, (uint64_t[]){ m->n_cols },
				  1, "n_cols");
	if (ret)
		return ret;
	cols = payload(p, IRDM_SEC_COLUMNS);
	seen = calloc((size_t)m->n_nodes / 8 + 1, 1);
	if (!seen)
		return fail(p, IRDM_IMAGE_EIO,
			    "out of memory checking %u columns", m->n_cols);
	for (uint32_t i = 0; i < m->n_cols; i++) {
		uint32_t c = cols[i];

		if (c >= m->n_nodes) {
			ret = fail(p, IRDM_IMAGE_EINVAL,
				   "column %u names node %u, but there are only %u nodes",
				   i, c, m->n_nodes);
			goto free_seen;
		}
		if (seen[c / 8] & (1u << (c % 8))) {
			ret = fail(p, IRDM_IMAGE_EINVAL,
				   "column %u repeats node %u", i, c);
			goto free_seen;
		}
		seen[c / 8] |= (uint8_t)(1u << (c % 8));
	}
	p->img.columns = cols;
free_seen:
	free(seen);
	return ret;
}

static int check_surface(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint32_t *tris;
	int ret;

	ret = check_presence(p, IRDM_SEC_SURFACE, true, "always");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_SURFACE, (uint64_t[]){ m->n_tris, 3 },
				  2, "n_tris x 3");
	if (ret)
		return ret;
	tris = payload(p, IRDM_SEC_SURFACE);
	for (uint64_t i = 0; i < (uint64_t)m->n_tris * 3; i++)
		if (tris[i] >= m->n_nodes)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "triangle %llu names node %u, but there are only %u nodes",
				    (unsigned long long)(i / 3), tris[i], m->n_nodes);
	p->img.tris = tris;
	return IRDM_IMAGE_OK;
}

static int check_stability(struct parse *p)
{
	const struct irdm_stability *st;
	int ret;

	ret = check_presence(p, IRDM_SEC_STABILITY, true, "always");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_STABILITY,
				  (uint64_t[]){ p->meta.n_cols, sizeof(*st) }, 2,
				  "n_cols x 8");
	if (ret)
		return ret;
	st = payload(p, IRDM_SEC_STABILITY);
	for (uint32_t i = 0; i < p->meta.n_cols; i++) {
		float rho = st[i].spectral_radius;

		if (!f32_finite(rho) || rho < 0)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "column %u: spectral radius %g is not a finite value >= 0",
				    i, (double)rho);
		if ((st[i].flags & IRDM_STAB_STABLE) && !(rho < 1))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "column %u is flagged stable with spectral radius %g >= 1",
				    i, (double)rho);
	}
	p->img.stability = st;
	return IRDM_IMAGE_OK;
}

static int check_rigid(struct parse *p)
{
	bool floating = p->meta.flags & IRDM_META_FLOATING;
	const struct irdm_rigid *rg;
	int ret;

	ret = check_presence(p, IRDM_SEC_RIGID, floating,
			     floating ? "meta flags say floating" :
					"meta flags say grounded");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_RIGID,
				  (uint64_t[]){ sizeof(*rg) }, 1, "128");
	if (ret || !floating)
		return ret;
	rg = payload(p, IRDM_SEC_RIGID);
	if (!f64_finite(rg->mass_kg) || !(rg->mass_kg > 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "rigid mass_kg is %g, must be finite and > 0", rg->mass_kg);
	for (unsigned i = 0; i < 3; i++)
		if (!f64_finite(rg->com_m[i]))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "rigid com_m[%u] is not finite", i);
	for (unsigned i = 0; i < 9; i++)
		if (!f64_finite(rg->inertia_kg_m2[i]))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "rigid inertia_kg_m2[%u] is not finite", i);
	if (p->strict && !all_zero(rg->reserved, sizeof(rg->reserved)))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "rigid reserved fields are not zero");
	p->img.rigid = rg;
	return IRDM_IMAGE_OK;
}

/* Scan a response array (elements of the meta precision) for NaN/inf. */
static int check_finite(struct parse *p, uint32_t kind, uint64_t count)
{
	const void *data = payload(p, kind);
	uint64_t bad = first_non_finite(data, p->meta.precision, count);

	if (bad == count)
		return IRDM_IMAGE_OK;
	if (kind == IRDM_SEC_FIR) {
		uint64_t t = p->meta.fir_length;
		uint64_t blk = bad / 9;

		return fail(p, IRDM_IMAGE_EINVAL,
			    "FIR element %llu (column %llu, row %llu, sample %llu, entry %llu,%llu) is not finite",
			    (unsigned long long)bad,
			    (unsigned long long)(blk / t / p->meta.n_nodes),
			    (unsigned long long)(blk / t % p->meta.n_nodes),
			    (unsigned long long)(blk % t),
			    (unsigned long long)(bad / 3 % 3),
			    (unsigned long long)(bad % 3));
	}
	return fail(p, IRDM_IMAGE_EINVAL, "%s element %llu is not finite",
		    kind_name(kind), (unsigned long long)bad);
}

static int check_fir(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	const uint64_t f[] = { m->n_cols, m->n_nodes, m->fir_length, 9 };
	int ret;

	ret = check_presence(p, IRDM_SEC_FIR, true, "FIR image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_MODES, false, "FIR image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_MODE_SHAPES, false, "FIR image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_STATIC_CORR, false, "FIR image");
	if (!ret)
		ret = check_shape(p, IRDM_SEC_FIR, f, 4, "n_cols x n_nodes x T x 9");
	if (!ret)
		ret = check_finite(p, IRDM_SEC_FIR, p->by_kind[IRDM_SEC_FIR]->size / p->es);
	if (ret)
		return ret;
	p->img.fir = payload(p, IRDM_SEC_FIR);
	return IRDM_IMAGE_OK;
}

static int check_modes(struct parse *p)
{
	const struct irdm_mode *modes;
	int ret;

	ret = check_shape(p, IRDM_SEC_MODES,
			  (uint64_t[]){ p->meta.n_modes, sizeof(*modes) }, 2,
			  "n_modes x 64");
	if (ret)
		return ret;
	modes = payload(p, IRDM_SEC_MODES);
	for (uint32_t k = 0; k < p->meta.n_modes; k++) {
		const struct irdm_mode *md = &modes[k];
		bool ok = f64_finite(md->omega_rad_s) && md->omega_rad_s >= 0 &&
			  f64_finite(md->zeta) && md->zeta >= 0;

		for (unsigned i = 0; i < 4; i++)
			ok = ok && f64_finite(md->a[i]);
		ok = ok && f64_finite(md->b[0]) && f64_finite(md->b[1]);
		if (!ok)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "mode %u: omega %g, zeta %g: need finite omega >= 0, zeta >= 0, A and b",
				    k, md->omega_rad_s, md->zeta);
	}
	p->img.modes = modes;
	return IRDM_IMAGE_OK;
}

static int check_modal(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;
	bool corr = m->flags & IRDM_META_STATIC_CORR;
	const uint64_t shapes[] = { m->n_nodes, 3, m->n_modes };
	const uint64_t sc[] = { m->n_cols, m->n_cols, 9 };
	int ret;

	ret = check_presence(p, IRDM_SEC_FIR, false, "modal image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_MODES, true, "modal image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_MODE_SHAPES, true, "modal image");
	if (!ret)
		ret = check_presence(p, IRDM_SEC_STATIC_CORR, corr,
				     corr ? "meta flags say STATIC_CORR" :
					    "meta flags lack STATIC_CORR");
	if (!ret)
		ret = check_modes(p);
	if (!ret)
		ret = check_shape(p, IRDM_SEC_MODE_SHAPES, shapes, 3,
				  "n_nodes x 3 x n_modes");
	if (!ret)
		ret = check_finite(p, IRDM_SEC_MODE_SHAPES,
				   p->by_kind[IRDM_SEC_MODE_SHAPES]->size / p->es);
	if (!ret && corr)
		ret = check_shape(p, IRDM_SEC_STATIC_CORR, sc, 3,
				  "n_cols x n_cols x 9");
	if (!ret && corr)
		ret = check_finite(p, IRDM_SEC_STATIC_CORR,
				   p->by_kind[IRDM_SEC_STATIC_CORR]->size / p->es);
	if (ret)
		return ret;
	p->img.mode_shapes = payload(p, IRDM_SEC_MODE_SHAPES);
	p->img.static_corr = payload(p, IRDM_SEC_STATIC_CORR);
	return IRDM_IMAGE_OK;
}

/* ----------------------------------------------------------- contact BVH */

/* Scratch of the BVH check (init time: allocating is fine here). */
struct bvh_scratch {
	uint8_t *tri_seen;              /* per surface triangle: listed in index[] */
	uint8_t *slot_seen;             /* per index[] entry: covered by a leaf */
	uint8_t *parents;               /* per node: references from a parent */
	uint8_t *level;                 /* per node: depth, root = 1 */
};

static bool bvh_contactable(const uint32_t *col_of_row, const uint32_t *v)
{
	return col_of_row[v[0]] != IRDM_BVH_NONE &&
	       col_of_row[v[1]] != IRDM_BVH_NONE &&
	       col_of_row[v[2]] != IRDM_BVH_NONE;
}

static bool box_inside(const float *lo, const float *hi, const float *ilo,
		       const float *ihi)
{
	for (unsigned a = 0; a < 3; a++)
		if (ilo[a] < lo[a] || ihi[a] > hi[a])
			return false;
	return true;
}

/* Header: counts agree with meta, the canonical contiguous layout. */
static int bvh_check_header(struct parse *p, const struct irdm_image_section *s,
			    const struct irdm_bvh_header *h)
{
	const struct irdm_meta *m = &p->meta;
	uint64_t nodes_off = sizeof(*h);
	uint64_t index_off = nodes_off + (uint64_t)h->n_bvh_nodes * sizeof(struct irdm_bvh_node);
	uint64_t adj_off = index_off + (uint64_t)h->n_contact_tris * 4;
	uint64_t cor_off = adj_off + (uint64_t)m->n_tris * 12;
	uint64_t end = cor_off + (uint64_t)m->n_nodes * 4;

	if (h->n_surface_tris != m->n_tris || h->n_rows != m->n_nodes)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH is for %u triangles and %u rows, meta has %u and %u",
			    h->n_surface_tris, h->n_rows, m->n_tris, m->n_nodes);
	if (p->strict && !all_zero(h->reserved, sizeof(h->reserved)))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH reserved fields are not zero");
	if (h->n_contact_tris > m->n_tris || (h->n_bvh_nodes == 0) != (h->n_contact_tris == 0) ||
	    h->n_bvh_nodes > 2 * (uint64_t)h->n_contact_tris)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH has %u nodes for %u of %u triangles",
			    h->n_bvh_nodes, h->n_contact_tris, m->n_tris);
	if (h->depth > IRDM_BVH_MAX_DEPTH || (h->depth == 0) != (h->n_bvh_nodes == 0) ||
	    h->leaf_max > IRDM_BVH_LEAF_MAX || (h->leaf_max == 0) != (h->n_bvh_nodes == 0))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH depth %u, leaf_max %u: need 1..%u and 1..%u",
			    h->depth, h->leaf_max, IRDM_BVH_MAX_DEPTH, IRDM_BVH_LEAF_MAX);
	if (h->nodes_offset != nodes_off || h->index_offset != index_off ||
	    h->adj_offset != adj_off || h->col_of_row_offset != cor_off || s->size != end)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH layout: offsets %u, %u, %u, %u and size %llu, expected %llu, %llu, %llu, %llu and %llu",
			    h->nodes_offset, h->index_offset, h->adj_offset,
			    h->col_of_row_offset, (unsigned long long)s->size,
			    (unsigned long long)nodes_off, (unsigned long long)index_off,
			    (unsigned long long)adj_off, (unsigned long long)cor_off,
			    (unsigned long long)end);
	return IRDM_IMAGE_OK;
}

/* col_of_row is exactly the inverse of COLUMNS. */
static int bvh_check_cols(struct parse *p, const uint32_t *cor)
{
	uint32_t n = 0;

	for (uint32_t r = 0; r < p->meta.n_nodes; r++) {
		if (cor[r] == IRDM_BVH_NONE)
			continue;
		if (cor[r] >= p->meta.n_cols || p->img.columns[cor[r]] != r)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH col_of_row[%u] is %u, which is not the column of row %u",
				    r, cor[r], r);
		n++;
	}
	if (n != p->meta.n_cols)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH col_of_row names %u columns, the image has %u",
			    n, p->meta.n_cols);
	return IRDM_IMAGE_OK;
}

/* index[] lists every contactable triangle exactly once, nothing else. */
static int bvh_check_index(struct parse *p, const struct irdm_bvh_header *h,
			   const uint32_t *index, const uint32_t *cor,
			   struct bvh_scratch *sc)
{
	uint32_t n = 0;

	for (uint32_t i = 0; i < h->n_contact_tris; i++) {
		uint32_t t = index[i];

		if (t >= p->meta.n_tris)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH index[%u] is triangle %u, but there are only %u",
				    i, t, p->meta.n_tris);
		if (sc->tri_seen[t])
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH index[%u] repeats triangle %u", i, t);
		if (!bvh_contactable(cor, &p->img.tris[3 * (uint64_t)t]))
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH index[%u]: triangle %u has a vertex that is not a column",
				    i, t);
		sc->tri_seen[t] = 1;
	}
	for (uint32_t t = 0; t < p->meta.n_tris; t++)
		n += bvh_contactable(cor, &p->img.tris[3 * (uint64_t)t]);
	if (n != h->n_contact_tris)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH lists %u triangles, the surface has %u contactable ones",
			    h->n_contact_tris, n);
	return IRDM_IMAGE_OK;
}

static int bvh_check_leaf(struct parse *p, const struct irdm_bvh_header *h,
			  const struct irdm_bvh_node *nd, uint32_t i,
			  const uint32_t *index, struct bvh_scratch *sc)
{
	uint64_t first = nd->left_or_first, count = nd->count_or_right;

	if (count < 1 || count > h->leaf_max || first + count > h->n_contact_tris)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH leaf %u has triangles [%llu, %llu) of %u (at most %u per leaf)",
			    i, (unsigned long long)first, (unsigned long long)(first + count),
			    h->n_contact_tris, h->leaf_max);
	for (uint64_t k = first; k < first + count; k++) {
		const uint32_t *v = &p->img.tris[3 * (uint64_t)index[k]];

		if (sc->slot_seen[k])
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH leaf %u: index entry %llu is in another leaf too",
				    i, (unsigned long long)k);
		sc->slot_seen[k] = 1;
		for (unsigned j = 0; j < 3; j++) {
			const float *q = p->img.nodes[v[j]].pos_m;

			if (!box_inside(nd->lo, nd->hi, q, q))
				return fail(p, IRDM_IMAGE_EINVAL,
					    "CONTACT_BVH leaf %u does not contain triangle %u",
					    i, index[k]);
		}
	}
	return IRDM_IMAGE_OK;
}

static int bvh_check_child(struct parse *p, const struct irdm_bvh_header *h,
			   const struct irdm_bvh_node *nodes, uint32_t i,
			   uint32_t c, struct bvh_scratch *sc)
{
	if (c <= i || c >= h->n_bvh_nodes)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH node %u has child %u: must be in (%u, %u)",
			    i, c, i, h->n_bvh_nodes);
	if (sc->parents[c]++)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH node %u has more than one parent", c);
	if (!box_inside(nodes[i].lo, nodes[i].hi, nodes[c].lo, nodes[c].hi))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH node %u does not contain its child %u", i, c);
	sc->level[c] = sc->level[i] + 1;
	return IRDM_IMAGE_OK;
}

/*
 * A tree: children have larger indices than their parent (no cycle), every
 * node but the root has exactly one parent, so every node hangs off node 0.
 * Leaves partition index[]; boxes are finite, ordered and nested.
 */
static int bvh_check_nodes(struct parse *p, const struct irdm_bvh_header *h,
			   const struct irdm_bvh_node *nodes, const uint32_t *index,
			   struct bvh_scratch *sc)
{
	uint32_t depth = 0;
	int ret;

	if (h->n_bvh_nodes)
		sc->level[0] = 1;
	for (uint32_t i = 0; i < h->n_bvh_nodes; i++) {
		const struct irdm_bvh_node *nd = &nodes[i];

		for (unsigned a = 0; a < 3; a++)
			if (!f32_finite(nd->lo[a]) || !f32_finite(nd->hi[a]) ||
			    !(nd->lo[a] <= nd->hi[a]))
				return fail(p, IRDM_IMAGE_EINVAL,
					    "CONTACT_BVH node %u: box axis %u is [%g, %g], need finite lo <= hi",
					    i, a, (double)nd->lo[a], (double)nd->hi[a]);
		if (i && sc->parents[i] != 1)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH node %u is not reachable from the root", i);
		if (sc->level[i] > h->depth)
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH node %u is at level %u, the header says depth %u",
				    i, sc->level[i], h->depth);
		depth = sc->level[i] > depth ? sc->level[i] : depth;
		if (nd->count_or_right & IRDM_BVH_INTERNAL) {
			ret = bvh_check_child(p, h, nodes, i, nd->left_or_first, sc);
			if (!ret)
				ret = bvh_check_child(p, h, nodes, i,
						      nd->count_or_right & ~IRDM_BVH_INTERNAL, sc);
		} else {
			ret = bvh_check_leaf(p, h, nd, i, index, sc);
		}
		if (ret)
			return ret;
	}
	if (depth != h->depth)
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH is %u levels deep, the header says %u", depth, h->depth);
	for (uint32_t k = 0; k < h->n_contact_tris; k++)
		if (!sc->slot_seen[k])
			return fail(p, IRDM_IMAGE_EINVAL,
				    "CONTACT_BVH index entry %u is in no leaf", k);
	return IRDM_IMAGE_OK;
}

/* Neighbours are contactable, share the edge, and name us back across it. */
static int bvh_check_adj(struct parse *p, const uint32_t *adj, const uint32_t *cor)
{
	const uint32_t *tris = p->img.tris;

	for (uint32_t t = 0; t < p->meta.n_tris; t++) {
		const uint32_t *v = &tris[3 * (uint64_t)t];
		bool contactable = bvh_contactable(cor, v);

		for (unsigned e = 0; e < 3; e++) {
			uint32_t u = adj[3 * (uint64_t)t + e], a = v[e], b = v[(e + 1) % 3];
			const uint32_t *w;
			unsigned f;

			if (u == IRDM_BVH_NONE)
				continue;
			if (!contactable || u >= p->meta.n_tris || u == t ||
			    !bvh_contactable(cor, &tris[3 * (uint64_t)u]))
				return fail(p, IRDM_IMAGE_EINVAL,
					    "CONTACT_BVH triangle %u edge %u: neighbour %u is out of range or not contactable",
					    t, e, u);
			w = &tris[3 * (uint64_t)u];
			for (f = 0; f < 3; f++)
				if ((w[f] == a && w[(f + 1) % 3] == b) ||
				    (w[f] == b && w[(f + 1) % 3] == a))
					break;
			if (f == 3 || adj[3 * (uint64_t)u + f] != t)
				return fail(p, IRDM_IMAGE_EINVAL,
					    "CONTACT_BVH triangle %u edge %u: neighbour %u does not share it back",
					    t, e, u);
		}
	}
	return IRDM_IMAGE_OK;
}

/*
 * Optional.  Version 1.0 reserved kind 12 without defining it, so a kind-12
 * section of another element type than BYTES is that reserved form: skipped
 * like an unknown kind, no view.  A BYTES one must be a valid BVH.
 */
static int check_contact_bvh(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_CONTACT_BVH];
	const struct irdm_bvh_header *h;
	struct bvh_scratch sc = { 0 };
	const uint8_t *base;
	int ret;

	if (!s || s->elem != IRDM_ELEM_BYTES)
		return IRDM_IMAGE_OK;
	if (s->size < sizeof(*h))
		return fail(p, IRDM_IMAGE_EINVAL,
			    "CONTACT_BVH has %llu bytes, less than its %zu-byte header",
			    (unsigned long long)s->size, sizeof(*h));
	base = p->base + s->offset;
	h = (const struct irdm_bvh_header *)base;
	ret = bvh_check_header(p, s, h);
	if (ret)
		return ret;
	ret = bvh_check_cols(p, (const uint32_t *)(base + h->col_of_row_offset));
	if (ret)
		return ret;
	sc.tri_seen = calloc((size_t)p->meta.n_tris + 1, 1);
	sc.slot_seen = calloc((size_t)h->n_contact_tris + 1, 1);
	sc.parents = calloc((size_t)h->n_bvh_nodes + 1, 1);
	sc.level = calloc((size_t)h->n_bvh_nodes + 1, 1);
	if (!sc.tri_seen || !sc.slot_seen || !sc.parents || !sc.level) {
		ret = fail(p, IRDM_IMAGE_EIO, "out of memory checking CONTACT_BVH");
		goto out;
	}
	ret = bvh_check_index(p, h, (const uint32_t *)(base + h->index_offset),
			      (const uint32_t *)(base + h->col_of_row_offset), &sc);
	if (!ret)
		ret = bvh_check_nodes(p, h, (const struct irdm_bvh_node *)(base + h->nodes_offset),
				      (const uint32_t *)(base + h->index_offset), &sc);
	if (!ret)
		ret = bvh_check_adj(p, (const uint32_t *)(base + h->adj_offset),
				    (const uint32_t *)(base + h->col_of_row_offset));
	if (!ret) {
		p->img.contact_bvh = h;
		p->img.contact_bvh_size = (size_t)s->size;
	}
out:
	free(sc.tri_seen);
	free(sc.slot_seen);
	free(sc.parents);
	free(sc.level);
	return ret;
}

static int check_contents(struct parse *p)
{
	int (*const step[])(struct parse *) = {
		check_meta, check_provenance, check_nodes, check_columns,
		check_surface, check_stability, check_rigid,
	};
	int ret;

	for (size_t i = 0; i < sizeof(step) / sizeof(step[0]); i++) {
		ret = step[i](p);
		if (ret)
			return ret;
	}
	if (p->meta.representation == IRDM_REPR_FIR)
		ret = check_fir(p);
	else
		ret = check_modal(p);
	if (ret)
		return ret;
	return check_contact_bvh(p);
}

/* ------------------------------------------------------------------- API */

int irdm_image_parse(const void *buf, size_t size, struct irdm_image *img,
		     char *err, size_t errlen)
{
	struct parse p = { .base = buf, .size = size, .err = err,
			   .errlen = errlen };
	int ret;

	memset(img, 0, sizeof(*img));
	if (err && errlen)
		err[0] = '\0';
	if ((!buf && size) || (uintptr_t)buf % 8)
		return fail(&p, IRDM_IMAGE_EINVAL,
			    "image buffer %p is not 8-byte aligned", buf);
	ret = check_header(&p);
	if (!ret)
		ret = check_table(&p);
	if (!ret)
		ret = check_sections(&p);
	if (!ret)
		ret = check_contents(&p);
	if (ret)
		return ret;
	*img = p.img;
	img->base = buf;
	img->size = size;
	img->meta = payload(&p, IRDM_SEC_META);
	return IRDM_IMAGE_OK;
}

static void format_size(char *buf, size_t len, size_t bytes)
{
	const size_t mib = (size_t)1 << 20;

	if (bytes >= mib)
		snprintf(buf, len, "%zu MiB", (bytes + mib - 1) / mib);
	else
		snprintf(buf, len, "%zu KiB", (bytes + 1023) / 1024);
}

/* Read one byte of every page: the loop must never take a page fault.
 * MAP_POPULATE and mlock usually did it already; this makes it certain. */
static void touch_pages(const uint8_t *base, size_t size)
{
	long page = sysconf(_SC_PAGESIZE);
	volatile uint8_t sink = 0;

	if (page <= 0)
		page = 4096;
	for (size_t o = 0; o < size; o += (size_t)page)
		sink ^= base[o];
	sink ^= base[size - 1];
	(void)sink;
}

static int lock_pages(struct irdm_image *raw, char *msg, size_t msglen)
{
	char sz[32];
	int e;

	if (!mlock(raw->base, raw->size)) {
		raw->locked = true;
		return IRDM_IMAGE_OK;
	}
	e = errno;
	format_size(sz, sizeof(sz), raw->size);
	return report(msg, msglen, IRDM_IMAGE_EIO, "cannot lock %s: %s%s", sz,
		      strerror(e), e == EPERM || e == ENOMEM ?
		      " (raise RLIMIT_MEMLOCK or run with CAP_IPC_LOCK)" : "");
}

/* mmap the whole file read-only into raw; the caller closes fd. */
static int map_fd(int fd, unsigned flags, struct irdm_image *raw,
		  char *msg, size_t msglen)
{
	int mflags = MAP_PRIVATE;
	struct stat st;
	void *base;
	int ret;

	if (fstat(fd, &st))
		return report(msg, msglen, IRDM_IMAGE_EIO, "cannot stat: %s",
			      strerror(errno));
	if (!S_ISREG(st.st_mode))
		return report(msg, msglen, IRDM_IMAGE_EIO, "not a regular file");
	if ((uintmax_t)st.st_size < HEADER_SIZE)
		return report(msg, msglen, IRDM_IMAGE_ETRUNC,
			      "image is truncated: file has %jd bytes, the header alone needs %zu",
			      (intmax_t)st.st_size, HEADER_SIZE);
	if ((uintmax_t)st.st_size > SIZE_MAX)
		return report(msg, msglen, IRDM_IMAGE_EIO,
			      "too large to map (%jd bytes)", (intmax_t)st.st_size);
#ifdef MAP_POPULATE
	mflags |= MAP_POPULATE;
#endif
	base = mmap(NULL, (size_t)st.st_size, PROT_READ, mflags, fd, 0);
	if (base == MAP_FAILED)
		return report(msg, msglen, IRDM_IMAGE_EIO, "cannot map: %s",
			      strerror(errno));
	raw->base = base;
	raw->size = (size_t)st.st_size;
	if (flags & IRDM_IMAGE_MAP_LOCK) {
		ret = lock_pages(raw, msg, msglen);
		if (ret)
			goto unmap;
	}
	touch_pages(base, raw->size);
	return IRDM_IMAGE_OK;
unmap:
	munmap(base, raw->size);
	memset(raw, 0, sizeof(*raw));
	return ret;
}

int irdm_image_map(const char *path, unsigned flags, struct irdm_image *img,
		   char *err, size_t errlen)
{
	struct irdm_image raw = { 0 };
	char msg[256] = "";
	int fd, ret;

	memset(img, 0, sizeof(*img));
	if (flags & ~(unsigned)IRDM_IMAGE_MAP_LOCK) {
		ret = report(msg, sizeof(msg), IRDM_IMAGE_EINVAL,
			     "unknown map flags 0x%x", flags);
		goto out_msg;
	}
	fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0) {
		ret = report(msg, sizeof(msg), IRDM_IMAGE_EIO, "cannot open: %s",
			     strerror(errno));
		goto out_msg;
	}
	ret = map_fd(fd, flags, &raw, msg, sizeof(msg));
	close(fd);              /* the mapping keeps the file */
	if (ret)
		goto out_msg;
	ret = irdm_image_parse(raw.base, raw.size, img, msg, sizeof(msg));
	if (ret)
		goto unmap;
	img->mapped = true;
	img->locked = raw.locked;
	return IRDM_IMAGE_OK;
unmap:
	munmap((void *)raw.base, raw.size);     /* also unlocks */
out_msg:
	if (err && errlen)
		snprintf(err, errlen, "%s: %s", path, msg);
	memset(img, 0, sizeof(*img));
	return ret;
}

void irdm_image_unmap(struct irdm_image *img)
{
	if (img->mapped && img->base)
		munmap((void *)img->base, img->size);
	memset(img, 0, sizeof(*img));
}

const char *irdm_image_strerror(int code)
{
	switch (code) {
	case IRDM_IMAGE_OK:
		return "success";
	case IRDM_IMAGE_EIO:
		return "cannot open, map or lock the image";
	case IRDM_IMAGE_ETRUNC:
		return "image is truncated";
	case IRDM_IMAGE_EMAGIC:
		return "not an IRDM image";
	case IRDM_IMAGE_EVERSION:
		return "unsupported image version";
	case IRDM_IMAGE_ECRC:
		return "bad checksum";
	case IRDM_IMAGE_ERANGE:
		return "offset, size or alignment out of range";
	case IRDM_IMAGE_EMISSING:
		return "required section missing or duplicated";
	case IRDM_IMAGE_EINVAL:
		return "invalid value in image";
	default:
		return "unknown image error";
	}
}

const struct irdm_image_section *irdm_image_find(const struct irdm_image *img,
						 uint32_t kind)
{
	const struct irdm_image_section *tab;
	struct irdm_image_header h;

	if (!img->base)
		return NULL;
	memcpy(&h, img->base, sizeof(h));
	tab = (const struct irdm_image_section *)(img->base +
						  h.section_table_offset);
	for (uint32_t i = 0; i < h.section_count; i++)
		if (tab[i].kind == kind)
			return &tab[i];
	return NULL;
}
