/* SPDX-License-Identifier: MIT */
/* Option tables: parse values by type, "key = value" lines and arguments. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/options.h"

const struct irdm_opt *irdm_opt_find(const struct irdm_opt_table *t, const char *name)
{
	for (size_t i = 0; i < t->n_opts; i++)
		if (!strcmp(t->opts[i].name, name))
			return &t->opts[i];
	return NULL;
}

static const struct irdm_opt *find_short(const struct irdm_opt_table *t, char c)
{
	for (size_t i = 0; i < t->n_opts; i++)
		if (c && t->opts[i].short_name == c)
			return &t->opts[i];
	return NULL;
}

/* "must be < 0.5 Pa", or "" if v is in range. */
static int check_range(const struct irdm_opt *o, double v, char *why, size_t len)
{
	const char *unit = o->unit ? o->unit : "";
	const char *sep = o->unit ? " " : "";

	if ((o->range & IRDM_OPT_GE) && !(v >= o->min))
		snprintf(why, len, "must be >= %.15g%s%s", o->min, sep, unit);
	else if ((o->range & IRDM_OPT_GT) && !(v > o->min))
		snprintf(why, len, "must be > %.15g%s%s", o->min, sep, unit);
	else if ((o->range & IRDM_OPT_LE) && !(v <= o->max))
		snprintf(why, len, "must be <= %.15g%s%s", o->max, sep, unit);
	else if ((o->range & IRDM_OPT_LT) && !(v < o->max))
		snprintf(why, len, "must be < %.15g%s%s", o->max, sep, unit);
	else
		return IRDM_OK;
	return IRDM_EFORMAT;
}

/* The rest of a number: nothing, or say what is left over. */
static int check_end(const char *end, char *why, size_t len)
{
	if (!*end)
		return IRDM_OK;
	snprintf(why, len, "unexpected '%s' after the number", end);
	return IRDM_EFORMAT;
}

/* The whole token, finite; trailing white space is allowed (strtod skips leading). */
static int parse_double(const struct irdm_opt *o, void *field, const char *s, char *why,
			size_t len)
{
	char *end;
	double v;

	if (o->size != sizeof(double))
		return IRDM_EINVAL;
	errno = 0;
	v = strtod(s, &end);
	if (end == s) {
		snprintf(why, len, "not a number");
		return IRDM_EFORMAT;
	}
	while (*end && isspace((unsigned char)*end))
		end++;
	if (check_end(end, why, len))
		return IRDM_EFORMAT;
	if (errno == ERANGE || !isfinite(v)) {
		snprintf(why, len, "not a finite number");
		return IRDM_EFORMAT;
	}
	if (check_range(o, v, why, len))
		return IRDM_EFORMAT;
	memcpy(field, &v, sizeof(v));
	return IRDM_OK;
}

/* The largest value a field of size bytes holds (unsigned or, half that, signed). */
static int size_max(size_t size, unsigned long long *max)
{
	switch (size) {
	case 1: *max = UINT8_MAX; break;
	case 2: *max = UINT16_MAX; break;
	case 4: *max = UINT32_MAX; break;
	case 8: *max = UINT64_MAX; break;
	default: return IRDM_EINVAL;
	}
	return IRDM_OK;
}

static void store_bits(void *field, size_t size, unsigned long long v)
{
	uint8_t u8 = (uint8_t)v;
	uint16_t u16 = (uint16_t)v;
	uint32_t u32 = (uint32_t)v;
	uint64_t u64 = v;

	memcpy(field, size == 1 ? (void *)&u8 : size == 2 ? (void *)&u16 :
					size == 4         ? (void *)&u32 :
							    (void *)&u64,
	       size);
}

/* Digits only: no sign, no space, no "0x". */
static int parse_unsigned(const struct irdm_opt *o, void *field, const char *s, char *why,
			  size_t len)
{
	unsigned long long max, v;
	char *end;

	if (size_max(o->size, &max))
		return IRDM_EINVAL;
	if (!isdigit((unsigned char)*s)) {
		snprintf(why, len, "not a whole number >= 0");
		return IRDM_EFORMAT;
	}
	errno = 0;
	v = strtoull(s, &end, 10);
	if (check_end(end, why, len))
		return IRDM_EFORMAT;
	if (errno || v > max) {
		snprintf(why, len, "must be <= %llu", max);
		return IRDM_EFORMAT;
	}
	if (check_range(o, (double)v, why, len))
		return IRDM_EFORMAT;
	store_bits(field, o->size, v);
	return IRDM_OK;
}

/* An optional sign, then digits. */
static int parse_int(const struct irdm_opt *o, void *field, const char *s, char *why, size_t len)
{
	unsigned long long umax;
	long long max, v;
	const char *d = (*s == '-' || *s == '+') ? s + 1 : s;
	char *end;

	if (size_max(o->size, &umax))
		return IRDM_EINVAL;
	max = (long long)(umax >> 1);
	if (!isdigit((unsigned char)*d)) {
		snprintf(why, len, "not a whole number");
		return IRDM_EFORMAT;
	}
	errno = 0;
	v = strtoll(s, &end, 10);
	if (check_end(end, why, len))
		return IRDM_EFORMAT;
	if (errno || v > max || v < -max - 1) {
		snprintf(why, len, "must be between %lld and %lld", -max - 1, max);
		return IRDM_EFORMAT;
	}
	if (check_range(o, (double)v, why, len))
		return IRDM_EFORMAT;
	store_bits(field, o->size, (unsigned long long)v);
	return IRDM_OK;
}

static int parse_bool(const struct irdm_opt *o, void *field, const char *s, char *why,
		      size_t len)
{
	static const char *const yes[] = { "yes", "true", "1", "on" };
	static const char *const no[] = { "no", "false", "0", "off" };

	if (o->size != sizeof(bool))
		return IRDM_EINVAL;
	for (size_t i = 0; i < 4; i++) {
		if (!strcmp(s, yes[i]) || !strcmp(s, no[i])) {
			*(bool *)field = !strcmp(s, yes[i]);
			return IRDM_OK;
		}
	}
	snprintf(why, len, "expected yes | no");
	return IRDM_EFORMAT;
}

/* "expected a | b | c" */
static void list_names(const struct irdm_opt_name *n, char *why, size_t len)
{
	size_t at = (size_t)snprintf(why, len, "expected");

	for (; n->name && at < len; n++)
		at += (size_t)snprintf(why + at, len - at, "%s %s", at > 8 ? " |" : "", n->name);
}

static int parse_enum(const struct irdm_opt *o, void *field, const char *s, char *why,
		      size_t len)
{
	int v;

	if (o->size != sizeof(int) || !o->names)
		return IRDM_EINVAL;
	for (const struct irdm_opt_name *n = o->names; n->name; n++) {
		if (!strcmp(s, n->name)) {
			v = n->value;
			memcpy(field, &v, sizeof(v));
			return IRDM_OK;
		}
	}
	list_names(o->names, why, len);
	return IRDM_EFORMAT;
}

static int parse_string(const struct irdm_opt *o, void *field, const char *s, char *why,
			size_t len)
{
	size_t n = strlen(s);

	if (!o->size) {
		memcpy(field, &s, sizeof(s));
		return IRDM_OK;
	}
	if (n >= o->size) {
		snprintf(why, len, "longer than %zu characters", o->size - 1);
		return IRDM_EFORMAT;
	}
	/* a value is one line of text: a newline in it would forge lines of
	 * the texts it is copied into (an image's PROVENANCE) */
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f) {
			snprintf(why, len, "contains the control character 0x%02x at character %zu",
				 (unsigned)(unsigned char)s[i], i + 1);
			return IRDM_EFORMAT;
		}
	memcpy(field, s, n + 1);
	return IRDM_OK;
}

int irdm_opt_parse_value(const struct irdm_opt *o, void *obj, const char *value,
			 char *why, size_t whylen)
{
	void *field = (char *)obj + o->offset;
	int ret = IRDM_EINVAL;

	if (whylen)
		why[0] = 0;
	switch (o->type) {
	case IRDM_OPT_DOUBLE: ret = parse_double(o, field, value, why, whylen); break;
	case IRDM_OPT_UNSIGNED: ret = parse_unsigned(o, field, value, why, whylen); break;
	case IRDM_OPT_INT: ret = parse_int(o, field, value, why, whylen); break;
	case IRDM_OPT_BOOL: ret = parse_bool(o, field, value, why, whylen); break;
	case IRDM_OPT_ENUM: ret = parse_enum(o, field, value, why, whylen); break;
	case IRDM_OPT_STRING: ret = parse_string(o, field, value, why, whylen); break;
	case IRDM_OPT_CUSTOM:
		ret = o->parse ? o->parse(o, obj, value, why, whylen) : IRDM_EINVAL;
		if (ret && whylen && !why[0])
			snprintf(why, whylen, "expected %s", o->metavar ? o->metavar : "a value");
		break;
	case IRDM_OPT_FLAG:
		break;
	}
	if (ret == IRDM_EINVAL && whylen && !why[0])
		snprintf(why, whylen, "option table entry '%s' cannot store its type", o->name);
	return ret;
}

static int unknown_key(const struct irdm_opt_table *t, const char *where, const char *key,
		       char *err, size_t errlen)
{
	snprintf(err, errlen, "%s: unknown %s '%s'%s%s%s", where, t->what, key,
		 t->see ? " (see " : "", t->see ? t->see : "", t->see ? ")" : "");
	return IRDM_EINVAL;
}

/* value as the message shows it: control characters escaped, so the
 * message stays one line (cut to buf's size). */
static const char *shown(const char *value, char *buf, size_t size)
{
	size_t n = 0;

	for (const char *c = value; *c && n + 5 < size; c++) {
		unsigned char u = (unsigned char)*c;

		if (u >= 0x20 && u != 0x7f)
			buf[n++] = *c;
		else if (u == '\n' || u == '\t')
			n += (size_t)snprintf(buf + n, size - n, "\\%c", u == '\n' ? 'n' : 't');
		else
			n += (size_t)snprintf(buf + n, size - n, "\\x%02x", u);
	}
	buf[n] = 0;
	return buf;
}

/* The entry's value, or the reason why not: "WHERE: key = value: why". */
static int set_entry(const struct irdm_opt *o, void *obj, const char *where, const char *value,
		     char *err, size_t errlen)
{
	char why[256], val[256];
	int ret = irdm_opt_parse_value(o, obj, value, why, sizeof(why));

	if (ret)
		snprintf(err, errlen, "%s: %s = %s: %s", where, o->name, shown(value, val, sizeof(val)),
			 why);
	return ret;
}

int irdm_opt_set(const struct irdm_opt_table *t, void *obj, const char *where, const char *key,
		 const char *value, char *err, size_t errlen)
{
	const struct irdm_opt *o = irdm_opt_find(t, key);

	if (!o || o->type == IRDM_OPT_FLAG)
		return unknown_key(t, where, key, err, errlen);
	return set_entry(o, obj, where, value, err, errlen);
}

int irdm_opt_set_defaults(const struct irdm_opt_table *t, void *obj, char *err, size_t errlen)
{
	char why[256];
	int ret;

	for (size_t i = 0; i < t->n_opts; i++) {
		const struct irdm_opt *o = &t->opts[i];
		if (!o->def)
			continue;
		ret = irdm_opt_parse_value(o, obj, o->def, why, sizeof(why));
		if (ret) {
			snprintf(err, errlen, "default of %s: %s", o->name, why);
			return ret;
		}
	}
	return IRDM_OK;
}

/* One "key=value" word of n characters at w. */
static int set_word(const struct irdm_opt_table *t, void *obj, const char *where, const char *w,
		    size_t n, char *err, size_t errlen)
{
	char word[256], *eq;

	if (n >= sizeof(word)) {
		snprintf(err, errlen, "%s: '%.40s...': longer than %zu characters", where, w,
			 sizeof(word) - 1);
		return IRDM_EINVAL;
	}
	memcpy(word, w, n);
	word[n] = 0;
	eq = strchr(word, '=');
	if (!eq) {
		snprintf(err, errlen, "%s: '%s': expected key=value", where, word);
		return IRDM_EINVAL;
	}
	*eq = 0;
	return irdm_opt_set(t, obj, where, word, eq + 1, err, errlen);
}

int irdm_opt_parse_words(const struct irdm_opt_table *t, void *obj, const char *where,
			 const char *text, const char *seps, char *err, size_t errlen)
{
	int ret = IRDM_OK;

	while (text && *text && !ret) {
		size_t n;

		text += strspn(text, seps);
		n = strcspn(text, seps);
		if (n)
			ret = set_word(t, obj, where, text, n, err, errlen);
		text += n;
	}
	return ret;
}

char *irdm_opt_trim(char *s)
{
	char *e;

	while (isspace((unsigned char)*s))
		s++;
	e = s + strlen(s);
	while (e > s && isspace((unsigned char)e[-1]))
		*--e = 0;
	return s;
}

/* A key set twice, when the file forbids it; remembers where it was set. */
static int check_duplicate(struct irdm_opt_file *f, const char *where, const char *key,
			   char *err, size_t errlen)
{
	const struct irdm_opt *o = irdm_opt_find(f->table, key);
	size_t i = o ? (size_t)(o - f->table->opts) : 64;

	if (!f->reject_duplicates || i >= 64)
		return IRDM_OK;
	if (f->seen & (UINT64_C(1) << i)) {
		snprintf(err, errlen, "%s: %s is already set on line %u", where, key,
			 f->seen_line[i]);
		return IRDM_EFORMAT;
	}
	f->seen |= UINT64_C(1) << i;
	f->seen_line[i] = f->line_no;
	return IRDM_OK;
}

int irdm_opt_parse_line(struct irdm_opt_file *f, char *line, char *err, size_t errlen)
{
	char where[320], *hash = strchr(line, '#'), *s, *eq, *key;
	int ret;

	snprintf(where, sizeof(where), "%s:%u", f->name, f->line_no);
	if (hash)
		*hash = 0;
	s = irdm_opt_trim(line);
	if (!*s)
		return IRDM_OK;
	eq = strchr(s, '=');
	if (!eq) {
		snprintf(err, errlen, "%s: expected 'key = value'", where);
		return IRDM_EFORMAT;
	}
	*eq = 0;
	key = irdm_opt_trim(s);
	ret = check_duplicate(f, where, key, err, errlen);
	if (!ret)
		ret = irdm_opt_set(f->table, f->obj, where, key, irdm_opt_trim(eq + 1), err,
				   errlen);
	return ret;
}

/* The entry an argument names ("--dt", "-o"), and the set it belongs to. */
static const struct irdm_opt *find_arg(const struct irdm_opt_set *sets, size_t n_sets,
				       const char *arg, void **obj)
{
	const struct irdm_opt *o = NULL;

	for (size_t k = 0; k < n_sets && !o; k++) {
		if (arg[1] == '-')
			o = irdm_opt_find(sets[k].table, arg + 2);
		else if (arg[1] && !arg[2])
			o = find_short(sets[k].table, arg[1]);
		*obj = sets[k].obj;
	}
	return o;
}

/* One option at argv[*i]; *i moves past its value. */
static int parse_arg(const struct irdm_opt_set *sets, size_t n_sets, int argc,
		     char *const *argv, int *i, char *err, size_t errlen)
{
	const char *a = argv[*i];
	void *obj = NULL;
	const struct irdm_opt *o = find_arg(sets, n_sets, a, &obj);

	if (!o && a[1] != '-') {
		snprintf(err, errlen, "unexpected argument '%s'", a);
		return IRDM_EINVAL;
	}
	if (!o)
		return unknown_key(sets[n_sets - 1].table, a, a + 2, err, errlen);
	if (o->type == IRDM_OPT_FLAG) {
		if (o->size != sizeof(bool)) {
			snprintf(err, errlen, "%s: option table entry is not a bool", a);
			return IRDM_EINVAL;
		}
		*(bool *)((char *)obj + o->offset) = true;
		return IRDM_OK;
	}
	if (*i + 1 >= argc) {
		snprintf(err, errlen, "%s needs a value", a);
		return IRDM_EINVAL;
	}
	const char *v = argv[++*i];
	char why[256], val[256];
	int ret = irdm_opt_parse_value(o, obj, v, why, sizeof(why));
	if (ret)
		snprintf(err, errlen, "%s %s: %s", a, shown(v, val, sizeof(val)), why);
	return ret;
}

int irdm_opt_parse_args(const struct irdm_opt_set *sets, size_t n_sets, int argc,
			char *const *argv, irdm_opt_positional_fn positional, void *ctx,
			char *err, size_t errlen)
{
	int ret = IRDM_OK;

	for (int i = 0; i < argc && !ret; i++) {
		const char *a = argv[i];
		if (a[0] == '-' && a[1] && n_sets)
			ret = parse_arg(sets, n_sets, argc, argv, &i, err, errlen);
		else if (positional)
			ret = positional(ctx, a, err, errlen);
		else {
			snprintf(err, errlen, "unexpected argument '%s'", a);
			ret = IRDM_EINVAL;
		}
	}
	return ret;
}

void irdm_opt_range_text(const struct irdm_opt *o, const char *name, char *buf, size_t len)
{
	const char *lo = (o->range & IRDM_OPT_GE) ? " <=" : (o->range & IRDM_OPT_GT) ? " <" :
										       NULL;
	const char *hi = (o->range & IRDM_OPT_LE) ? " <=" : (o->range & IRDM_OPT_LT) ? " <" :
										       NULL;
	const char *unit = o->unit ? o->unit : "";
	const char *sep = o->unit ? " " : "";
	size_t at = 0;

	if (len)
		buf[0] = 0;
	if (!lo && !hi)
		return;
	if (lo && hi)
		at = (size_t)snprintf(buf, len, "%.15g%s ", o->min, lo);
	if (at < len)
		at += (size_t)snprintf(buf + at, len - at, "%s", name);
	if (lo && !hi && at < len)
		at += (size_t)snprintf(buf + at, len - at, " %s %.15g", lo[2] == '=' ? ">=" : ">",
				       o->min);
	if (hi && at < len)
		at += (size_t)snprintf(buf + at, len - at, "%s %.15g", hi, o->max);
	if (at < len)
		snprintf(buf + at, len - at, "%s%s", sep, unit);
}

static int check_entry(const struct irdm_opt *o, char *err, size_t errlen)
{
	static const size_t any = 0;
	size_t want = o->type == IRDM_OPT_DOUBLE                           ? sizeof(double) :
		      o->type == IRDM_OPT_BOOL || o->type == IRDM_OPT_FLAG ? sizeof(bool) :
		      o->type == IRDM_OPT_ENUM                             ? sizeof(int) :
									     any;
	unsigned long long max;

	if (!o->name || !o->name[0] || !o->help)
		snprintf(err, errlen, "an entry has no name or no help");
	else if (want != any && o->size != want)
		snprintf(err, errlen, "'%s': field size %zu, its type needs %zu", o->name, o->size, want);
	else if ((o->type == IRDM_OPT_UNSIGNED || o->type == IRDM_OPT_INT) && size_max(o->size, &max))
		snprintf(err, errlen, "'%s': integer field of %zu bytes", o->name, o->size);
	else if ((o->type == IRDM_OPT_ENUM && !o->names) || (o->type == IRDM_OPT_CUSTOM && !o->parse))
		snprintf(err, errlen, "'%s': no names or no parse callback", o->name);
	else if ((o->range & (IRDM_OPT_GE | IRDM_OPT_GT)) && (o->range & (IRDM_OPT_LE | IRDM_OPT_LT)) &&
		 o->min > o->max)
		snprintf(err, errlen, "'%s': min %g > max %g", o->name, o->min, o->max);
	else
		return IRDM_OK;
	return IRDM_EINVAL;
}

static int check_names(const struct irdm_opt *o, char *err, size_t errlen)
{
	for (const struct irdm_opt_name *a = o->names; a && a->name; a++)
		for (const struct irdm_opt_name *b = a + 1; b->name; b++)
			if (!strcmp(a->name, b->name)) {
				snprintf(err, errlen, "'%s': name '%s' listed twice", o->name, a->name);
				return IRDM_EINVAL;
			}
	return IRDM_OK;
}

int irdm_opt_table_check(const struct irdm_opt_table *t, char *err, size_t errlen)
{
	for (size_t i = 0; i < t->n_opts; i++) {
		const struct irdm_opt *o = &t->opts[i];
		if (check_entry(o, err, errlen) || check_names(o, err, errlen))
			return IRDM_EINVAL;
		for (size_t j = i + 1; j < t->n_opts; j++)
			if (!strcmp(o->name, t->opts[j].name) ||
			    (o->short_name && o->short_name == t->opts[j].short_name)) {
				snprintf(err, errlen, "'%s' is in the table twice", o->name);
				return IRDM_EINVAL;
			}
	}
	return IRDM_OK;
}
