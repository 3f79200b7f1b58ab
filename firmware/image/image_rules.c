/* SPDX-License-Identifier: MIT */
/*
 * The rules every section check shares: where a section's payload is,
 * whether the section must be there (presence), its element type and exact
 * size from the meta counts (shape), and every value of a response array
 * finite.  Below the checks: they call these, these call none of them.
 */
#include <stdbool.h>
#include <stdint.h>

#include "image_priv.h"

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

const void *img_payload(const struct parse *p, uint32_t kind)
{
	const struct irdm_image_section *s = p->by_kind[kind];

	return s ? p->base + s->offset : NULL;
}

/* Presence rule: the section must be there iff wanted. */
int img_check_presence(struct parse *p, uint32_t kind, bool wanted,
		       const char *why)
{
	bool have = p->by_kind[kind] != NULL;

	if (wanted && !have)
		return img_fail(p, IRDM_EMISSING,
				"required section %s is missing (%s)",
				img_kind_name(kind), why);
	if (!wanted && have)
		return img_fail(p, IRDM_EFORMAT,
				"section %s must not be present (%s)",
				img_kind_name(kind), why);
	return IRDM_OK;
}

/*
 * A present known section has the element type of its kind and exactly the
 * size the meta counts give: the product of factors (checked for overflow)
 * times the element size.
 */
int img_check_shape(struct parse *p, uint32_t kind, const uint64_t *f,
		    unsigned nf, const char *formula)
{
	const struct irdm_image_section *s = p->by_kind[kind];
	uint32_t elem = img_kind_elem(kind);
	uint64_t want;

	if (!s)
		return IRDM_OK;
	if (elem == ELEM_PRECISION)
		elem = p->meta.precision;
	if (s->elem != elem)
		return img_fail(p, IRDM_EFORMAT,
				"section %s has element type %s, expected %s",
				img_kind_name(kind), img_elem_name(s->elem), img_elem_name(elem));
	if (!mul_ok(&want, f, nf) || !mul_ok(&want, (uint64_t[]){ want, irdm_elem_size(elem) }, 2))
		return img_fail(p, IRDM_EFORMAT,
				"section %s: expected size %s x %zu overflows",
				img_kind_name(kind), formula, irdm_elem_size(elem));
	if (s->size != want && elem == IRDM_ELEM_BYTES)
		return img_fail(p, IRDM_EFORMAT,
				"section %s has %llu bytes, expected %llu (%s)",
				img_kind_name(kind), (unsigned long long)s->size,
				(unsigned long long)want, formula);
	if (s->size != want)
		return img_fail(p, IRDM_EFORMAT,
				"section %s has %llu bytes, expected %llu (%s x %zu)",
				img_kind_name(kind), (unsigned long long)s->size,
				(unsigned long long)want, formula,
				irdm_elem_size(elem));
	return IRDM_OK;
}

/* Index of the first non-finite element of an array, or count if none. */
static uint64_t first_non_finite(const void *data, uint32_t elem, uint64_t count)
{
	uint64_t i;

	for (i = 0; i < count; i++)
		if (!f64_finite(irdm_elem_get(data, elem, (size_t)i)))
			return i;
	return i;
}

/* Scan a response array (elements of the meta precision) for NaN/inf. */
int img_check_finite(struct parse *p, uint32_t kind, uint64_t count)
{
	const void *data = img_payload(p, kind);
	uint64_t bad = first_non_finite(data, p->meta.precision, count);

	if (bad == count)
		return IRDM_OK;
	if (kind == IRDM_SEC_FIR) {
		uint64_t t = p->meta.fir_length;
		uint64_t blk = bad / 9;

		return img_fail(p, IRDM_EFORMAT,
				"FIR element %llu (column %llu, row %llu, sample %llu, entry %llu,%llu) is not finite",
				(unsigned long long)bad,
				(unsigned long long)(blk / t / p->meta.n_nodes),
				(unsigned long long)(blk / t % p->meta.n_nodes),
				(unsigned long long)(blk % t),
				(unsigned long long)(bad / 3 % 3),
				(unsigned long long)(bad % 3));
	}
	return img_fail(p, IRDM_EFORMAT, "%s element %llu is not finite",
			img_kind_name(kind), (unsigned long long)bad);
}
