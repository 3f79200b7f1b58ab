/* SPDX-License-Identifier: MIT */
/*
 * One source for a board key's default: the .def of its entry in the board
 * key table.  The test links with --wrap=irdm_board_options (Makefile), so
 * every caller in the firmware library gets the table this file hands out:
 * a copy with the defaults of watchdog_us (a number) and gear_ratio (a
 * list, an arm key) changed.  The key help (irdm-fw --help-board), the
 * Markdown of docs/boards.md, irdm_board_default() and the parse of a board
 * that leaves both keys out must all show the new values; with the real
 * table, the shipped ones.  A default taken from anywhere else than the
 * entry fails here.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "irdm/board.h"
#include "irdm/error.h"
#include "irdm/posix/options_doc.h"

const struct irdm_opt_table *__real_irdm_board_options(void);
const struct irdm_opt_table *__wrap_irdm_board_options(void);

static struct irdm_opt changed_opts[64];
static struct irdm_opt_table changed;
static bool use_changed;

const struct irdm_opt_table *__wrap_irdm_board_options(void)
{
	return use_changed ? &changed : __real_irdm_board_options();
}

/* The real table with two defaults replaced. */
static void change_defaults(const char *watchdog, const char *gear)
{
	const struct irdm_opt_table *t = __real_irdm_board_options();

	assert_true(t->n_opts <= 64);
	memcpy(changed_opts, t->opts, t->n_opts * sizeof(t->opts[0]));
	changed = *t;
	changed.opts = changed_opts;
	for (size_t i = 0; i < t->n_opts; i++) {
		if (!strcmp(changed_opts[i].name, "watchdog_us"))
			changed_opts[i].def = watchdog;
		if (!strcmp(changed_opts[i].name, "gear_ratio"))
			changed_opts[i].def = gear;
	}
	use_changed = true;
}

/* What print writes, white space runs (line wraps) as one space. */
static char *printed(void (*print)(FILE *, const struct irdm_opt_table *))
{
	char *buf = NULL, *r, *w;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);

	assert_non_null(f);
	print(f, irdm_board_options());
	fclose(f);
	for (r = w = buf; *r; r++)
		if (!(*r == ' ' || *r == '\n') || (w > buf && w[-1] != ' '))
			*w++ = *r == '\n' ? ' ' : *r;
	*w = 0;
	return buf;
}

static void print_keys(FILE *f, const struct irdm_opt_table *t)
{
	irdm_opt_print_help(f, t, IRDM_OPT_STYLE_KEY);
}

static void print_doc(FILE *f, const struct irdm_opt_table *t)
{
	irdm_opt_print_markdown(f, t);
}

static void expect_in(char *text, const char *want, const char *what)
{
	if (!strstr(text, want))
		fail_msg("%s does not show '%s':\n%s", what, want, text);
	free(text);
}

/* Every view of the defaults shows watchdog and gear (as text and numbers). */
static void expect_defaults(const char *watchdog, const char *gear, unsigned watchdog_us,
			    const double gear_ratio[3])
{
	static const char minimal[] = "name = t\nhal = sim\n"
				      "workspace_min_m = -0.035,-0.035,-0.040\n"
				      "workspace_max_m = 0.035,0.045,0.030\n";
	struct irdm_board b;
	char want[256], err[256];

	snprintf(want, sizeof(want), "watchdog_us = N one tick longer than this faults; "
				     "> period_us (default %s); 1 <= watchdog_us <= 1000000 us",
		 watchdog);
	expect_in(printed(print_keys), want, "the key help");
	snprintf(want, sizeof(want), "gear_ratio = J1,J2,J3 motor turns per joint turn "
				     "(the capstan) (default %s);",
		 gear);
	expect_in(printed(print_keys), want, "the key help");
	snprintf(want, sizeof(want), "| `watchdog_us` | `N` | 1 <= watchdog_us <= 1000000 us | "
				     "one tick longer than this faults; > period_us (default %s) |",
		 watchdog);
	expect_in(printed(print_doc), want, "the Markdown");
	snprintf(want, sizeof(want), "| motor turns per joint turn (the capstan) (default %s) |",
		 gear);
	expect_in(printed(print_doc), want, "the Markdown");

	irdm_board_default(&b);
	assert_int_equal(b.watchdog_us, watchdog_us);
	assert_memory_equal(b.device.gear_ratio, gear_ratio, 3 * sizeof(double));

	memset(&b, 0, sizeof(b));
	if (irdm_board_parse(&b, "t.board", minimal, err, sizeof(err)))
		fail_msg("minimal board refused: %s", err);
	assert_int_equal(b.watchdog_us, watchdog_us);
	assert_memory_equal(b.device.gear_ratio, gear_ratio, 3 * sizeof(double));
}

static void test_shipped_defaults(void **state)
{
	(void)state;
	use_changed = false;
	expect_defaults("5000", "11.6, 11.6, 11.6", 5000, (const double[3]){ 11.6, 11.6, 11.6 });
}

static void test_changed_defaults(void **state)
{
	(void)state;
	change_defaults("4321", "10.5,11,12.25");
	expect_defaults("4321", "10.5,11,12.25", 4321, (const double[3]){ 10.5, 11, 12.25 });
	use_changed = false;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_shipped_defaults),
		cmocka_unit_test(test_changed_defaults),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
