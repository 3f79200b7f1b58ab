/* SPDX-License-Identifier: MIT */
/*
 * Semantic validation: every known section checked against the meta data,
 * in a fixed order (check_contents), with the two rules every section
 * check shares: whether the section must be there (presence) and its
 * element type and exact size from the meta counts (shape).
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
	if (!mul_ok(&want, f, nf) || !mul_ok(&want, (uint64_t[]){ want,
			irdm_elem_size(elem) }, 2))
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

int img_check_contents(struct parse *p)
{
	int (*const step[])(struct parse *) = {
		img_check_meta, img_check_provenance,
		img_check_nodes, img_check_columns,
		img_check_surface, img_check_stability,
		img_check_rigid,
	};
	int ret;

	for (size_t i = 0; i < sizeof(step) / sizeof(step[0]); i++) {
		ret = step[i](p);
		if (ret)
			return ret;
	}
	if (p->meta.representation == IRDM_REPR_FIR)
		ret = img_check_fir(p);
	else
		ret = img_check_modal(p);
	if (ret)
		return ret;
	return img_check_contact_bvh(p);
}
