/* SPDX-License-Identifier: MIT */
/*
 * Option tables: one constant table of keys (name, type, range, unit, help,
 * default, where the value goes) drives the parsing of "key = value" files,
 * of "--key value" arguments, the defaults (irdm_opt_set_defaults()), and
 * the help and documentation printed from it (irdm_opt_range_text() gives
 * the range in words).  The scene of the offline tool, the controller's
 * board file and the HAL back-ends' options use the same machinery.
 *
 * No allocation, no I/O: values are stored into a caller's struct (offsetof)
 * or handed to a parse callback; messages go to a caller's buffer.
 */
#ifndef IRDM_OPTIONS_H
#define IRDM_OPTIONS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum irdm_opt_type {
	IRDM_OPT_DOUBLE,   /* finite double */
	IRDM_OPT_UNSIGNED, /* decimal digits only; stored in 1, 2, 4 or 8 bytes */
	IRDM_OPT_INT,      /* optional sign, decimal digits; 1, 2, 4 or 8 bytes */
	IRDM_OPT_BOOL,     /* yes/true/on/1 or no/false/off/0, into a bool */
	IRDM_OPT_ENUM,     /* one of .names, its value into an int-sized field */
	IRDM_OPT_STRING,   /* copied into char[size]; size 0: the pointer is stored */
	IRDM_OPT_FLAG,     /* arguments only: "--key" with no value sets a bool */
	IRDM_OPT_CUSTOM,   /* .parse does it all (composite syntax) */
};

/* Range flags: which of .min and .max apply, inclusive or not. */
#define IRDM_OPT_GE 0x1u /* value >= min */
#define IRDM_OPT_GT 0x2u /* value >  min */
#define IRDM_OPT_LE 0x4u /* value <= max */
#define IRDM_OPT_LT 0x8u /* value <  max */

struct irdm_opt_name {
	const char *name;
	int value;
};

struct irdm_opt;

/*
 * A custom parser: set obj from value, or return IRDM_EFORMAT and, if it
 * can say more than "expected <metavar>", a reason in why.
 */
typedef int (*irdm_opt_parse_fn)(const struct irdm_opt *o, void *obj, const char *value,
				 char *why, size_t whylen);

struct irdm_opt {
	const char *name; /* "dt": the file key, and "--dt" */
	char short_name;  /* 'o' for "-o", or 0 */
	enum irdm_opt_type type;
	const char *metavar; /* the value's syntax for help: "SECONDS", "yes | no" */
	const char *unit;    /* "s", "Pa" or NULL */
	const char *help;    /* one line, without the default */
	/*
	 * The value a key not given takes, written as in a file and parsed by
	 * the entry itself: help and docs print it as "(default X)" ("" prints
	 * as "none").  NULL: the table gives no default (a required key, or one
	 * set otherwise).
	 */
	const char *def;
	size_t offset;  /* where the value goes in the caller's struct */
	size_t size;    /* of that field (IRDM_OPT_FIELD) */
	unsigned range; /* IRDM_OPT_GE | IRDM_OPT_LT ... */
	double min, max;
	const struct irdm_opt_name *names; /* ENUM: ends with a NULL name */
	irdm_opt_parse_fn parse;           /* CUSTOM */
};

/* .offset and .size of a member, e.g. IRDM_OPT_FIELD(struct irdm_scene, dt_s). */
#define IRDM_OPT_FIELD(type, member) \
	.offset = offsetof(type, member), .size = sizeof(((type *)0)->member)

/*
 * .def from a macro that expands to the value: the C code and the table
 * share one definition, e.g. IRDM_OPT_DEFAULT(IRDM_DEVICE_DEFAULT_L1_M);
 * a list macro (0,0.135,-0.135) keeps its commas.
 */
#define IRDM_OPT_DEFAULT(...) .def = IRDM_OPT_TEXT_(__VA_ARGS__)
#define IRDM_OPT_TEXT_(...) #__VA_ARGS__

/*
 * A STRING entry that stores the pointer in a `const char *` member: the
 * caller keeps the text alive (argv does).
 */
#define IRDM_OPT_TEXT_REF(type, member) .offset = offsetof(type, member), .size = 0

struct irdm_opt_table {
	const char *what; /* "scene key": "unknown scene key 'x'" */
	const char *see;  /* "irdm precompute --help", appended to unknown-key messages, or NULL */
	const struct irdm_opt *opts;
	size_t n_opts;
};

/* A table and the struct its offsets point into. */
struct irdm_opt_set {
	const struct irdm_opt_table *table;
	void *obj;
};

/* The entry called name, or NULL. */
const struct irdm_opt *irdm_opt_find(const struct irdm_opt_table *t, const char *name);

/*
 * Parse value for entry o into obj.  why gets the reason on failure
 * ("must be < 0.5", "not a number", "expected lumped | consistent").
 * Return: IRDM_OK; IRDM_EFORMAT if the value is malformed or out of range;
 * IRDM_EINVAL if the entry is unusable (a FLAG, a size the type cannot store).
 */
int irdm_opt_parse_value(const struct irdm_opt *o, void *obj, const char *value,
			 char *why, size_t whylen);

/*
 * Set key to value.  Messages: "WHERE: key = value: reason" or
 * "WHERE: unknown <what> 'key' (see <see>)".
 * Return: IRDM_OK; IRDM_EINVAL if key is not in the table; IRDM_EFORMAT if
 * the value is invalid.
 */
int irdm_opt_set(const struct irdm_opt_table *t, void *obj, const char *where, const char *key,
		 const char *value, char *err, size_t errlen);

/*
 * Every entry's .def parsed into obj, in table order (entries without one
 * are left as they are).  Messages: "default of key: reason".
 * Return: IRDM_OK; what irdm_opt_parse_value() returns for the first
 * default it refuses (a broken table).
 */
int irdm_opt_set_defaults(const struct irdm_opt_table *t, void *obj, char *err, size_t errlen);

/*
 * "key=value" words, separated by any character of seps (" ,\t": a HAL
 * back-end's options), each set through t.  Messages: those of
 * irdm_opt_set() ("WHERE: key = value: reason", "WHERE: unknown <what>
 * 'key' (see <see>)"), and "WHERE: 'word': expected key=value".
 * Return: IRDM_OK; IRDM_EINVAL for an unknown key, a word without '=' or
 * one longer than 255 characters; IRDM_EFORMAT for an invalid value.
 */
int irdm_opt_parse_words(const struct irdm_opt_table *t, void *obj, const char *where,
			 const char *text, const char *seps, char *err, size_t errlen);

/* s without its leading white space; trailing white space is cut in place. */
char *irdm_opt_trim(char *s);

/*
 * A "key = value" text being read line by line.  Set the fields, then call
 * irdm_opt_parse_line() for each line with line_no counting from 1.
 * reject_duplicates: a key set twice is an error (the first 64 entries of
 * the table are tracked).
 */
struct irdm_opt_file {
	const struct irdm_opt_table *table;
	void *obj;
	const char *name; /* for messages: "board.cfg:12: ..." */
	unsigned line_no;
	bool reject_duplicates;
	uint64_t seen; /* bit i: entry i was set; start at 0 */
	unsigned seen_line[64];
};

/*
 * One line: '#' starts a comment, blank lines are skipped, otherwise
 * "key = value" with spaces around either trimmed.  line is modified.
 * Return: IRDM_OK; IRDM_EFORMAT if the line has no '=', the value is
 * invalid or (reject_duplicates) the key was already set; IRDM_EINVAL if
 * the key is unknown.
 */
int irdm_opt_parse_line(struct irdm_opt_file *f, char *line, char *err, size_t errlen);

/*
 * Called with each argument that does not start with '-' (or is "-");
 * returns IRDM_OK or an error with a message in err.
 */
typedef int (*irdm_opt_positional_fn)(void *ctx, const char *arg, char *err, size_t errlen);

/*
 * Command-line arguments argv[0..argc): "--name value", "-c value" (an
 * entry's short_name), "--name" alone for a FLAG.  The sets are searched in
 * order; an unknown option is named with the last set's table ("unknown
 * scene key 'x'").  Arguments not starting with '-' go to positional, or
 * are an error if it is NULL.  Messages: "--name value: reason",
 * "--name needs a value", "unexpected argument 'x'".
 * Return: IRDM_OK; IRDM_EINVAL for an unknown option, a missing value or
 * an unexpected argument; IRDM_EFORMAT for an invalid value; what
 * positional returns.
 */
int irdm_opt_parse_args(const struct irdm_opt_set *sets, size_t n_sets, int argc,
			char *const *argv, irdm_opt_positional_fn positional, void *ctx,
			char *err, size_t errlen);

/*
 * The range as text, with name standing for the value: "-1 < poisson < 0.5",
 * "dt > 0 s"; "" when the entry has no range.
 */
void irdm_opt_range_text(const struct irdm_opt *o, const char *name, char *buf, size_t len);

/*
 * Check a table: names unique and non-empty, enum names unique, sizes fit
 * the types, min <= max.  Return: IRDM_OK; IRDM_EINVAL with the reason.
 */
int irdm_opt_table_check(const struct irdm_opt_table *t, char *err, size_t errlen);

#endif /* IRDM_OPTIONS_H */
