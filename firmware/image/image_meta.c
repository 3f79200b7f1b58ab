/* SPDX-License-Identifier: MIT */
/*
 * META and PROVENANCE: the values every other section is checked against,
 * and the text the firmware prints about where the image came from.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "image_priv.h"

#define META_FLAGS_KNOWN (IRDM_META_FLOATING | IRDM_META_STATIC_CORR | \
			  IRDM_META_CONSISTENT_MASS | IRDM_META_TIME_DOMAIN | \
			  IRDM_META_FIR_TAIL_WINDOW | IRDM_META_EXACT_HEAD | \
			  IRDM_META_ERROR_MEASURED | IRDM_META_COLUMN_SCALE | \
			  IRDM_META_HEAD_PAIRS)

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
			return img_fail(p, IRDM_EFORMAT,
					"meta %s is not finite", d[i].name);
	/* a microsecond at least: a 1 MHz force loop is beyond any device */
	if (!(m->dt_s >= 1e-6 && m->dt_s <= 1))
		return img_fail(p, IRDM_EFORMAT,
				"meta dt_s is %g s, must be in [1e-06, 1]", m->dt_s);
	if (!(m->young_pa > 0))
		return img_fail(p, IRDM_EFORMAT,
				"meta young_pa is %g, must be > 0", m->young_pa);
	if (!(m->poisson > -1 && m->poisson < 0.5))
		return img_fail(p, IRDM_EFORMAT,
				"meta poisson is %g, must be in (-1, 0.5)", m->poisson);
	if (!(m->density_kg_m3 > 0))
		return img_fail(p, IRDM_EFORMAT,
				"meta density_kg_m3 is %g, must be > 0",
				m->density_kg_m3);
	return IRDM_OK;
}

static int check_meta_counts(struct parse *p)
{
	const struct irdm_meta *m = &p->meta;

	if (m->n_nodes < 1 || m->n_cols < 1 || m->n_cols > m->n_nodes)
		return img_fail(p, IRDM_EFORMAT,
				"meta n_nodes %u, n_cols %u: need 1 <= n_cols <= n_nodes",
				m->n_nodes, m->n_cols);
	if (m->representation == IRDM_REPR_FIR &&
	    (m->fir_length < 1 || m->n_modes != 0))
		return img_fail(p, IRDM_EFORMAT,
				"FIR image has fir_length %u, n_modes %u: need T >= 1 and no modes",
				m->fir_length, m->n_modes);
	if (m->representation == IRDM_REPR_MODAL &&
	    (m->n_modes < 1 || m->fir_length != 0))
		return img_fail(p, IRDM_EFORMAT,
				"modal image has n_modes %u, fir_length %u: need modes >= 1 and T = 0",
				m->n_modes, m->fir_length);
	if (!(m->flags & IRDM_META_FIR_TAIL_WINDOW) != !m->fir_exact ||
	    (m->fir_exact && (m->representation != IRDM_REPR_FIR || m->fir_exact >= m->fir_length)))
		return img_fail(p, IRDM_EFORMAT,
				"meta fir_exact %u with fir_length %u, FIR_TAIL_WINDOW %s: need an FIR with 1 <= fir_exact < fir_length exactly when the flag is set",
				m->fir_exact, m->fir_length,
				m->flags & IRDM_META_FIR_TAIL_WINDOW ? "set" : "clear");
	if (m->representation == IRDM_REPR_FIR &&
	    (m->flags & IRDM_META_STATIC_CORR))
		return img_fail(p, IRDM_EFORMAT,
				"FIR image has the STATIC_CORR flag (modal only)");
	if (!(m->flags & IRDM_META_EXACT_HEAD) != !m->head_samples ||
	    m->head_samples > IRDM_HEAD_SAMPLES_MAX ||
	    (m->head_samples && !(m->flags & IRDM_META_STATIC_CORR)))
		return img_fail(p, IRDM_EFORMAT,
				"meta head_samples %u, EXACT_HEAD %s, STATIC_CORR %s: need 1 <= head_samples <= %u on a modal image with STATIC_CORR exactly when the flag is set",
				m->head_samples, m->flags & IRDM_META_EXACT_HEAD ? "set" : "clear",
				m->flags & IRDM_META_STATIC_CORR ? "set" : "clear", IRDM_HEAD_SAMPLES_MAX);
	return IRDM_OK;
}

int img_check_meta(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_META];
	const struct irdm_meta *m = &p->meta;
	int ret;

	ret = img_check_presence(p, IRDM_SEC_META, true, "always");
	if (ret)
		return ret;
	ret = img_check_presence(p, IRDM_SEC_PROVENANCE, true, "always");
	if (ret)
		return ret;
	if (s->size != sizeof(struct irdm_meta) || s->elem != IRDM_ELEM_BYTES)
		return img_fail(p, IRDM_EFORMAT,
				"section META has %llu bytes of %s, expected %zu of BYTES",
				(unsigned long long)s->size, img_elem_name(s->elem),
				sizeof(struct irdm_meta));
	memcpy(&p->meta, p->base + s->offset, sizeof(p->meta));
	if (m->representation != IRDM_REPR_FIR &&
	    m->representation != IRDM_REPR_MODAL)
		return img_fail(p, IRDM_EFORMAT,
				"meta representation is %u, expected 1 (FIR) or 2 (MODAL)",
				m->representation);
	if (m->precision != IRDM_ELEM_F16 && m->precision != IRDM_ELEM_F32 &&
	    m->precision != IRDM_ELEM_F64)
		return img_fail(p, IRDM_EFORMAT,
				"meta precision is %u, expected 1 (F16), 2 (F32) or 3 (F64)",
				m->precision);
	p->es = irdm_elem_size(m->precision);
	if (p->strict && (m->flags & ~META_FLAGS_KNOWN))
		return img_fail(p, IRDM_EFORMAT, "meta has unknown flags (0x%08x)", m->flags);
	/* a 2.2 image has zero where 2.3 put the measured error */
	if (p->strict && !(m->flags & IRDM_META_ERROR_MEASURED) && m->measured_error != 0)
		return img_fail(p, IRDM_EFORMAT,
				"meta measured_error is %g without the ERROR_MEASURED flag",
				(double)m->measured_error);
	if ((m->flags & IRDM_META_ERROR_MEASURED) &&
	    !(f64_finite((double)m->measured_error) && m->measured_error >= 0))
		return img_fail(p, IRDM_EFORMAT, "meta measured_error is %g, must be finite and >= 0",
				(double)m->measured_error);
	if (!memchr(m->tool_version, 0, sizeof(m->tool_version)) ||
	    !memchr(m->mesh_name, 0, sizeof(m->mesh_name)))
		return img_fail(p, IRDM_EFORMAT,
				"meta tool_version or mesh_name is not NUL-terminated");
	ret = check_meta_numbers(p);
	if (ret)
		return ret;
	return check_meta_counts(p);
}

/* Does a line "key=..." start at text[i]? */
static bool key_at(const char *text, size_t len, size_t i, const char *key, size_t klen)
{
	return i + klen < len && (!i || text[i - 1] == '\n') && !memcmp(text + i, key, klen) &&
	       text[i + klen] == '=';
}

/* The value of "key=" at a line start in text (len bytes), copied into
 * val (NUL-terminated); false when the key is not there. */
static bool prov_value(const char *text, size_t len, const char *key, char *val, size_t vlen)
{
	size_t klen = strlen(key);

	for (size_t i = 0; i + klen < len; i++) {
		size_t n = 0;

		if (!key_at(text, len, i, key, klen))
			continue;
		i += klen + 1;
		while (i + n < len && text[i + n] != '\n' && n + 1 < vlen)
			n++;
		memcpy(val, text + i, n);
		val[n] = 0;
		return true;
	}
	return false;
}

/* field holds val, or val cut to the field's size (the text keeps it whole). */
static bool same_text(const char *val, const char *field, size_t size)
{
	size_t n = strnlen(field, size);

	return !strncmp(val, field, n) && (val[n] == 0 || n == size - 1);
}

static bool same_double(const char *s, double v, double rel)
{
	char *end;
	double x = strtod(s, &end);

	return end != s && !*end && fabs(x - v) <= rel * fabs(v);
}

/*
 * PROVENANCE repeats meta values as text for people; a copy that
 * disagrees means one of the two was changed after the image was written
 * (docs/image-format.md lists the redundant fields).  A key that is not
 * there is not a disagreement: the text is free-form beyond these.
 */
static int check_provenance_copies(struct parse *p, const char *text, size_t len)
{
	const struct irdm_meta *m = &p->meta;
	const struct {
		const char *key;
		double v, rel; /* the text's precision: %.17g exact, %.9g */
	} d[] = {
		{ "rayleigh_a_per_s", m->rayleigh_a_per_s, 0 },
		{ "rayleigh_b_s", m->rayleigh_b_s, 0 },
		{ "first_elastic_hz", m->first_elastic_hz, 1e-8 },
		{ "mesh_nodes", m->mesh_nodes, 0 },
		{ "mesh_tets", m->mesh_tets, 0 },
	};
	char val[128];

	for (size_t i = 0; i < sizeof(d) / sizeof(d[0]); i++)
		if (prov_value(text, len, d[i].key, val, sizeof(val)) &&
		    !same_double(val, d[i].v, d[i].rel))
			return img_fail(p, IRDM_EFORMAT,
					"PROVENANCE %s=%s disagrees with meta's %.17g",
					d[i].key, val, d[i].v);
	if (prov_value(text, len, "mesh_hash", val, sizeof(val)) &&
	    strtoull(val, NULL, 16) != m->mesh_hash)
		return img_fail(p, IRDM_EFORMAT,
				"PROVENANCE mesh_hash=%s disagrees with meta's %016llx", val,
				(unsigned long long)m->mesh_hash);
	if (prov_value(text, len, "tool", val, sizeof(val)) &&
	    !same_text(val, m->tool_version, sizeof(m->tool_version)))
		return img_fail(p, IRDM_EFORMAT,
				"PROVENANCE tool=%s disagrees with meta's tool_version '%s'", val,
				m->tool_version);
	if (prov_value(text, len, "mesh_name", val, sizeof(val)) &&
	    !same_text(val, m->mesh_name, sizeof(m->mesh_name)))
		return img_fail(p, IRDM_EFORMAT,
				"PROVENANCE mesh_name=%s disagrees with meta's mesh_name '%s'", val,
				m->mesh_name);
	return IRDM_OK;
}

/* The one figure PROVENANCE holds that meta does not: people and
 * irdm-fw read it, so it is a number or the image is wrong. */
static int read_two_contacts(struct parse *p, const char *text, size_t len)
{
	const char *key = IRDM_PROV_TWO_CONTACTS_ERROR;
	size_t klen = strlen(key), n = 0;
	char val[64], *end;
	double x;

	p->img.two_contacts_error = -1;
	for (size_t i = 0; i + klen < len; i++)
		n += key_at(text, len, i, key, klen);
	if (n > 1)
		return img_fail(p, IRDM_EFORMAT, "PROVENANCE has %s %zu times", key, n);
	if (!prov_value(text, len, key, val, sizeof(val)))
		return IRDM_OK;
	x = strtod(val, &end);
	if (end == val || *end || !f64_finite(x) || x < 0)
		return img_fail(p, IRDM_EFORMAT,
				"PROVENANCE " IRDM_PROV_TWO_CONTACTS_ERROR "=%s is not a finite number >= 0",
				val);
	p->img.two_contacts_error = x;
	return IRDM_OK;
}

int img_check_provenance(struct parse *p)
{
	const struct irdm_image_section *s = p->by_kind[IRDM_SEC_PROVENANCE];
	const char *text = img_payload(p, IRDM_SEC_PROVENANCE);
	int ret;

	if (s->elem != IRDM_ELEM_BYTES)
		return img_fail(p, IRDM_EFORMAT,
				"section PROVENANCE has element type %s, expected BYTES",
				img_elem_name(s->elem));
	/* Text the firmware prints: an embedded NUL would hide the rest. */
	if (memchr(text, 0, (size_t)s->size))
		return img_fail(p, IRDM_EFORMAT,
				"PROVENANCE contains a NUL byte at offset %td",
				(const char *)memchr(text, 0, (size_t)s->size) - text);
	p->img.provenance = text;
	p->img.provenance_len = (size_t)s->size;
	ret = check_provenance_copies(p, text, (size_t)s->size);
	return ret ? ret : read_two_contacts(p, text, (size_t)s->size);
}
