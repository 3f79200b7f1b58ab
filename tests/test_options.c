/* SPDX-License-Identifier: MIT */
/*
 * The option-table machinery (irdm/options.h): every type takes its valid
 * values and refuses the invalid ones with a message that says why; lines,
 * arguments, unknown keys and duplicates; the help and Markdown generated
 * from a table; and the project's real tables pass the table check.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/error.h"
#include "irdm/options.h"
#include "irdm/posix/options_doc.h"
#include "scene/scene.h"

struct cfg {
	double gain;
	double ratio;
	unsigned count;
	uint8_t small;
	int offset;
	int16_t trim;
	bool enabled;
	bool verbose;
	int mode;
	char label[8];
	const char *path;
	unsigned pair[2];
};

enum { MODE_OFF = 0,
       MODE_SLOW = 3,
       MODE_FAST = 7 };

static const struct irdm_opt_name mode_names[] = {
	{ "off", MODE_OFF },
	{ "slow", MODE_SLOW },
	{ "fast", MODE_FAST },
	{ NULL, 0 },
};

/* "A,B" with A < B */
static int parse_pair(const struct irdm_opt *o, void *obj, const char *v, char *why, size_t len)
{
	struct cfg *c = obj;
	unsigned a, b;
	int n = 0;

	(void)o;
	if (sscanf(v, "%u,%u%n", &a, &b, &n) != 2 || v[n])
		return IRDM_EFORMAT; /* the default reason: "expected A,B" */
	if (a >= b) {
		snprintf(why, len, "A must be < B");
		return IRDM_EFORMAT;
	}
	c->pair[0] = a;
	c->pair[1] = b;
	return IRDM_OK;
}

#define CF(member) IRDM_OPT_FIELD(struct cfg, member)

static const struct irdm_opt cfg_opts[] = {
	{ .name = "gain", .type = IRDM_OPT_DOUBLE, CF(gain), .unit = "N/m", .help = "gain", .range = IRDM_OPT_GT | IRDM_OPT_LE, .min = 0, .max = 100 },
	{ .name = "ratio", .type = IRDM_OPT_DOUBLE, CF(ratio), .help = "ratio", .range = IRDM_OPT_GE | IRDM_OPT_LT, .min = -1, .max = 0.5 },
	{ .name = "count", .type = IRDM_OPT_UNSIGNED, CF(count), .help = "count", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = 1, .max = 1000 },
	{ .name = "small", .type = IRDM_OPT_UNSIGNED, CF(small), .help = "one byte" },
	{ .name = "offset", .type = IRDM_OPT_INT, CF(offset), .unit = "us", .help = "offset", .range = IRDM_OPT_GE | IRDM_OPT_LE, .min = -500, .max = 500 },
	{ .name = "trim", .type = IRDM_OPT_INT, CF(trim), .help = "two bytes" },
	{ .name = "enabled", .type = IRDM_OPT_BOOL, CF(enabled), .help = "on or off" },
	{ .name = "verbose", .short_name = 'v', .type = IRDM_OPT_FLAG, CF(verbose), .help = "talk" },
	{ .name = "mode", .type = IRDM_OPT_ENUM, CF(mode), .names = mode_names, .help = "mode" },
	{ .name = "label", .type = IRDM_OPT_STRING, CF(label), .help = "label" },
	{ .name = "path", .short_name = 'p', .type = IRDM_OPT_STRING, IRDM_OPT_TEXT_REF(struct cfg, path), .metavar = "FILE", .help = "a file" },
	{ .name = "pair", .type = IRDM_OPT_CUSTOM, .parse = parse_pair, .metavar = "A,B", .help = "two numbers" },
};

static const struct irdm_opt_table cfg_table = {
	.what = "board key",
	.see = "the manual",
	.opts = cfg_opts,
	.n_opts = sizeof(cfg_opts) / sizeof(cfg_opts[0]),
};

static struct cfg c;
static char err[512];

/* Set key = value in c; the return code, with the message in err. */
static int set(const char *key, const char *value)
{
	err[0] = 0;
	return irdm_opt_set(&cfg_table, &c, "b.cfg:4", key, value, err, sizeof(err));
}

static void expect_ok(const char *key, const char *value)
{
	if (set(key, value))
		fail_msg("%s = %s refused: %s", key, value, err);
}

/* Refused with IRDM_EFORMAT, and the message is exactly `want`. */
static void expect_bad(const char *key, const char *value, const char *want)
{
	int rc = set(key, value);

	if (rc != IRDM_EFORMAT || strcmp(err, want))
		fail_msg("%s = %s: got %d '%s', want '%s'", key, value, rc, err, want);
}

static int reset(void **state)
{
	(void)state;
	memset(&c, 0, sizeof(c));
	return 0;
}

static void test_double(void **state)
{
	(void)state;
	expect_ok("gain", "100");
	assert_true(c.gain == 100);
	expect_ok("gain", "2.5e-3 "); /* trailing space, as strtod's leading */
	assert_true(c.gain == 2.5e-3);
	expect_bad("gain", "0", "b.cfg:4: gain = 0: must be > 0 N/m");
	expect_bad("gain", "100.5", "b.cfg:4: gain = 100.5: must be <= 100 N/m");
	expect_bad("gain", "", "b.cfg:4: gain = : not a number");
	expect_bad("gain", "fast", "b.cfg:4: gain = fast: not a number");
	expect_bad("gain", "1.5x", "b.cfg:4: gain = 1.5x: unexpected 'x' after the number");
	expect_bad("gain", "nan", "b.cfg:4: gain = nan: not a finite number");
	expect_bad("gain", "inf", "b.cfg:4: gain = inf: not a finite number");
	expect_bad("gain", "1e999", "b.cfg:4: gain = 1e999: not a finite number");
	assert_true(c.gain == 2.5e-3); /* a refused value leaves the field */
	expect_ok("ratio", "-1");
	expect_ok("ratio", "0.4999");
	expect_bad("ratio", "0.5", "b.cfg:4: ratio = 0.5: must be < 0.5");
	expect_bad("ratio", "-1.0001", "b.cfg:4: ratio = -1.0001: must be >= -1");
}

static void test_unsigned(void **state)
{
	(void)state;
	expect_ok("count", "1");
	expect_ok("count", "1000");
	assert_int_equal(c.count, 1000);
	expect_ok("count", "007");
	assert_int_equal(c.count, 7);
	expect_bad("count", "0", "b.cfg:4: count = 0: must be >= 1");
	expect_bad("count", "1001", "b.cfg:4: count = 1001: must be <= 1000");
	expect_bad("count", "-3", "b.cfg:4: count = -3: not a whole number >= 0");
	expect_bad("count", "+3", "b.cfg:4: count = +3: not a whole number >= 0");
	expect_bad("count", " 3", "b.cfg:4: count =  3: not a whole number >= 0");
	expect_bad("count", "3.0", "b.cfg:4: count = 3.0: unexpected '.0' after the number");
	expect_bad("count", "12 ", "b.cfg:4: count = 12 : unexpected ' ' after the number");
	expect_bad("count", "99999999999999999999", "b.cfg:4: count = 99999999999999999999: must be <= 4294967295");
	/* the field's size bounds it too */
	expect_ok("small", "255");
	assert_int_equal(c.small, 255);
	expect_bad("small", "256", "b.cfg:4: small = 256: must be <= 255");
	assert_int_equal(c.count, 7);
}

static void test_int(void **state)
{
	(void)state;
	expect_ok("offset", "-500");
	assert_int_equal(c.offset, -500);
	expect_ok("offset", "+12");
	assert_int_equal(c.offset, 12);
	expect_bad("offset", "-501", "b.cfg:4: offset = -501: must be >= -500 us");
	expect_bad("offset", "501", "b.cfg:4: offset = 501: must be <= 500 us");
	expect_bad("offset", "-", "b.cfg:4: offset = -: not a whole number");
	expect_bad("offset", "x1", "b.cfg:4: offset = x1: not a whole number");
	expect_bad("offset", "1e3", "b.cfg:4: offset = 1e3: unexpected 'e3' after the number");
	expect_ok("trim", "-32768");
	assert_int_equal(c.trim, -32768);
	expect_bad("trim", "32768", "b.cfg:4: trim = 32768: must be between -32768 and 32767");
}

static void test_bool_enum_string(void **state)
{
	static const char *const yes[] = { "yes", "true", "on", "1" }, *const no[] = { "no", "false", "off", "0" };

	(void)state;
	for (int i = 0; i < 4; i++) {
		expect_ok("enabled", yes[i]);
		assert_true(c.enabled);
		expect_ok("enabled", no[i]);
		assert_false(c.enabled);
	}
	expect_bad("enabled", "Yes", "b.cfg:4: enabled = Yes: expected yes | no");
	expect_bad("enabled", "2", "b.cfg:4: enabled = 2: expected yes | no");
	expect_ok("mode", "fast");
	assert_int_equal(c.mode, MODE_FAST);
	expect_bad("mode", "medium", "b.cfg:4: mode = medium: expected off | slow | fast");
	expect_bad("mode", "", "b.cfg:4: mode = : expected off | slow | fast");
	assert_int_equal(c.mode, MODE_FAST);
	expect_ok("label", "1234567");
	assert_string_equal(c.label, "1234567");
	expect_bad("label", "12345678", "b.cfg:4: label = 12345678: longer than 7 characters");
	/* one line: a newline would forge lines of the texts a value goes into */
	expect_bad("label", "a\nb=1",
		   "b.cfg:4: label = a\\nb=1: contains the control character 0x0a at character 2");
	expect_bad("label", "a\tb", "b.cfg:4: label = a\\tb: contains the control character 0x09 at character 2");
	assert_string_equal(c.label, "1234567");
	expect_ok("path", "/tmp/x");
	assert_string_equal(c.path, "/tmp/x");
}

static void test_custom(void **state)
{
	(void)state;
	expect_ok("pair", "3,9");
	assert_int_equal(c.pair[1], 9);
	expect_bad("pair", "9,3", "b.cfg:4: pair = 9,3: A must be < B");
	expect_bad("pair", "3", "b.cfg:4: pair = 3: expected A,B");
}

static void test_unknown_key(void **state)
{
	(void)state;
	assert_int_equal(set("gian", "1"), IRDM_EINVAL);
	assert_string_equal(err, "b.cfg:4: unknown board key 'gian' (see the manual)");
	/* a flag is for the command line only */
	assert_int_equal(set("verbose", "yes"), IRDM_EINVAL);
}

/* Lines: comments, blanks, spaces, line numbers in messages, duplicates. */
static void test_lines(void **state)
{
	struct irdm_opt_file f = { .table = &cfg_table, .obj = &c, .name = "b.cfg", .reject_duplicates = true };
	char lines[][64] = { "# a board", "", "  gain=  4.5   # N/m", "mode = slow",
			     "gain = 5", "count 3", "colour = red", "ratio = 0.7" };

	(void)state;
	for (int i = 0; i < 4; i++) {
		f.line_no = (unsigned)i + 1;
		assert_int_equal(irdm_opt_parse_line(&f, lines[i], err, sizeof(err)), IRDM_OK);
	}
	assert_true(c.gain == 4.5);
	assert_int_equal(c.mode, MODE_SLOW);
	f.line_no = 5;
	assert_int_equal(irdm_opt_parse_line(&f, lines[4], err, sizeof(err)), IRDM_EFORMAT);
	assert_string_equal(err, "b.cfg:5: gain is already set on line 3");
	assert_true(c.gain == 4.5);
	f.line_no = 6;
	assert_int_equal(irdm_opt_parse_line(&f, lines[5], err, sizeof(err)), IRDM_EFORMAT);
	assert_string_equal(err, "b.cfg:6: expected 'key = value'");
	f.line_no = 7;
	assert_int_equal(irdm_opt_parse_line(&f, lines[6], err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "b.cfg:7: unknown board key 'colour' (see the manual)");
	f.line_no = 12;
	assert_int_equal(irdm_opt_parse_line(&f, lines[7], err, sizeof(err)), IRDM_EFORMAT);
	assert_string_equal(err, "b.cfg:12: ratio = 0.7: must be < 0.5");
	/* without reject_duplicates the last line wins (scene files) */
	char again[] = "mode = off";
	f.reject_duplicates = false;
	assert_int_equal(irdm_opt_parse_line(&f, again, err, sizeof(err)), IRDM_OK);
	assert_int_equal(c.mode, MODE_OFF);
}

static int positional(void *ctx, const char *arg, char *e, size_t len)
{
	const char **first = ctx;

	if (*first) {
		snprintf(e, len, "one file only, not '%s'", arg);
		return IRDM_EINVAL;
	}
	*first = arg;
	return IRDM_OK;
}

static int parse(const char *first, ...)
{
	char *argv[16];
	int argc = 0;
	va_list ap;
	const struct irdm_opt_set set1 = { &cfg_table, &c };
	const char *file = NULL;

	va_start(ap, first);
	for (const char *a = first; a && argc < 16; a = va_arg(ap, const char *))
		argv[argc++] = (char *)a;
	va_end(ap);
	err[0] = 0;
	return irdm_opt_parse_args(&set1, 1, argc, argv, positional, &file, err, sizeof(err));
}

static void test_args(void **state)
{
	(void)state;
	assert_int_equal(parse("--gain", "3", "-v", "in.dat", "-p", "out", "--mode", "slow", NULL), IRDM_OK);
	assert_true(c.gain == 3 && c.verbose && c.mode == MODE_SLOW);
	assert_string_equal(c.path, "out");
	assert_int_equal(parse("--gain", "0", NULL), IRDM_EFORMAT);
	assert_string_equal(err, "--gain 0: must be > 0 N/m");
	/* the message stays one line whatever the value holds */
	assert_int_equal(parse("--label", "a\nb\x01", NULL), IRDM_EFORMAT);
	assert_string_equal(err, "--label a\\nb\\x01: contains the control character 0x0a at character 2");
	assert_int_equal(parse("--count", NULL), IRDM_EINVAL);
	assert_string_equal(err, "--count needs a value");
	assert_int_equal(parse("--colour", "red", NULL), IRDM_EINVAL);
	assert_string_equal(err, "--colour: unknown board key 'colour' (see the manual)");
	assert_int_equal(parse("-x", NULL), IRDM_EINVAL);
	assert_string_equal(err, "unexpected argument '-x'");
	assert_int_equal(parse("a", "b", NULL), IRDM_EINVAL);
	assert_string_equal(err, "one file only, not 'b'");
	/* without a positional callback a bare word is an error */
	char *argv[] = { "word" };
	const struct irdm_opt_set set1 = { &cfg_table, &c };
	assert_int_equal(irdm_opt_parse_args(&set1, 1, 1, argv, NULL, NULL, err, sizeof(err)),
			 IRDM_EINVAL);
	assert_string_equal(err, "unexpected argument 'word'");
}

static void test_range_text(void **state)
{
	char buf[64];

	(void)state;
	irdm_opt_range_text(&cfg_opts[0], "gain", buf, sizeof(buf));
	assert_string_equal(buf, "0 < gain <= 100 N/m");
	irdm_opt_range_text(&cfg_opts[1], "ratio", buf, sizeof(buf));
	assert_string_equal(buf, "-1 <= ratio < 0.5");
	irdm_opt_range_text(&cfg_opts[3], "small", buf, sizeof(buf));
	assert_string_equal(buf, "");
}

/* The table check catches what would silently write the wrong bytes. */
static void test_table_check(void **state)
{
	struct irdm_opt bad[2] = { cfg_opts[0], cfg_opts[2] };
	struct irdm_opt_table t = { .what = "key", .opts = bad, .n_opts = 2 };
	static const struct irdm_opt_name twice[] = { { "a", 1 }, { "b", 2 }, { "a", 3 }, { NULL, 0 } };

	(void)state;
	assert_int_equal(irdm_opt_table_check(&cfg_table, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_opt_table_check(&irdm_scene_options, err, sizeof(err)), IRDM_OK);
	bad[1].name = "gain";
	assert_int_equal(irdm_opt_table_check(&t, err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "'gain' is in the table twice");
	bad[1] = cfg_opts[8];
	bad[1].names = twice;
	assert_int_equal(irdm_opt_table_check(&t, err, sizeof(err)), IRDM_EINVAL);
	assert_string_equal(err, "'mode': name 'a' listed twice");
	bad[1] = cfg_opts[0];
	bad[1].name = "g2";
	bad[1].size = sizeof(float);
	assert_int_equal(irdm_opt_table_check(&t, err, sizeof(err)), IRDM_EINVAL);
	bad[1].size = sizeof(double);
	bad[1].min = 200;
	assert_int_equal(irdm_opt_table_check(&t, err, sizeof(err)), IRDM_EINVAL);
}

/* Help and Markdown carry each entry's syntax, help and range. */
static void test_docs(void **state)
{
	char text[8192];
	FILE *f = fmemopen(text, sizeof(text), "w");

	(void)state;
	assert_non_null(f);
	irdm_opt_print_help(f, &cfg_table, IRDM_OPT_STYLE_ARG);
	irdm_opt_print_help(f, &cfg_table, IRDM_OPT_STYLE_KEY);
	irdm_opt_print_markdown(f, &cfg_table);
	fclose(f);
	assert_non_null(strstr(text, "  --gain NUMBER             gain; 0 < gain <= 100 N/m\n"));
	assert_non_null(strstr(text, "  -p, --path FILE           a file\n"));
	assert_non_null(strstr(text, "  -v, --verbose             talk\n"));
	assert_non_null(strstr(text, "  mode = off | slow | fast  mode\n"));
	assert_non_null(strstr(text, "| `mode` | `off \\| slow \\| fast` |  | mode |\n"));
	assert_non_null(strstr(text, "| `ratio` | `NUMBER` | -1 <= ratio < 0.5 | ratio |\n"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(test_double, reset),
		cmocka_unit_test_setup(test_unsigned, reset),
		cmocka_unit_test_setup(test_int, reset),
		cmocka_unit_test_setup(test_bool_enum_string, reset),
		cmocka_unit_test_setup(test_custom, reset),
		cmocka_unit_test_setup(test_unknown_key, reset),
		cmocka_unit_test_setup(test_lines, reset),
		cmocka_unit_test_setup(test_args, reset),
		cmocka_unit_test(test_range_text),
		cmocka_unit_test(test_table_check),
		cmocka_unit_test(test_docs),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
