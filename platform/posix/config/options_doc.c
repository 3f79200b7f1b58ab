/* SPDX-License-Identifier: MIT */
/* --help lines and Markdown from an option table. */
#include <stdlib.h>
#include <string.h>

#include "irdm/posix/options_doc.h"

#define HELP_COLUMN 28
#define LINE_WIDTH 79

/* The value's syntax: the entry's metavar, or one made from its type. */
static void metavar(const struct irdm_opt *o, char *buf, size_t len)
{
	static const char *const by_type[] = {
		[IRDM_OPT_DOUBLE] = "NUMBER",
		[IRDM_OPT_UNSIGNED] = "N",
		[IRDM_OPT_INT] = "N",
		[IRDM_OPT_BOOL] = "yes | no",
		[IRDM_OPT_STRING] = "TEXT",
		[IRDM_OPT_FLAG] = "",
		[IRDM_OPT_CUSTOM] = "VALUE",
	};
	size_t at = 0;

	buf[0] = 0;
	if (o->metavar) {
		snprintf(buf, len, "%s", o->metavar);
		return;
	}
	if (o->type != IRDM_OPT_ENUM) {
		snprintf(buf, len, "%s", by_type[o->type]);
		return;
	}
	for (const struct irdm_opt_name *n = o->names; n->name && at < len; n++)
		at += (size_t)snprintf(buf + at, len - at, "%s%s", at ? " | " : "", n->name);
}

/* The help and, when the entry has one, its default: "help (default X)". */
/* The help and its default, in a buffer of their size (init time: the
 * caller frees it); NULL if out of memory. */
static char *help_text(const struct irdm_opt *o)
{
	size_t len = strlen(o->help) + (o->def ? strlen(o->def) : 0) + sizeof(" (default none)");
	char *buf = malloc(len);

	if (!buf)
		return NULL;
	if (!o->def)
		snprintf(buf, len, "%s", o->help);
	else
		snprintf(buf, len, "%s (default %s)", o->help, o->def[0] ? o->def : "none");
	return buf;
}

/* Go to a new indented line before n more characters would pass LINE_WIDTH. */
static size_t make_room(FILE *f, size_t col, size_t n)
{
	if (col > HELP_COLUMN && col + 1 + n > LINE_WIDTH) {
		fprintf(f, "\n%*s", HELP_COLUMN, "");
		return HELP_COLUMN;
	}
	if (col > HELP_COLUMN) {
		fputc(' ', f);
		col++;
	}
	return col;
}

/* The help's words from HELP_COLUMN on, then the range unbroken. */
static void print_wrapped(FILE *f, const char *text, const char *range)
{
	size_t col = HELP_COLUMN;

	while (*text) {
		size_t word = strcspn(text, " ");
		col = make_room(f, col, word + (range[0] && !text[word]));
		fwrite(text, 1, word, f);
		col += word;
		text += word;
		text += strspn(text, " ");
	}
	if (range[0]) {
		fputc(';', f);
		col = make_room(f, col + 1, strlen(range));
		fputs(range, f);
	}
	fputc('\n', f);
}

void irdm_opt_print_help(FILE *f, const struct irdm_opt_table *t, enum irdm_opt_style style)
{
	char syntax[256], mv[192], range[128], *help;

	for (size_t i = 0; i < t->n_opts; i++) {
		const struct irdm_opt *o = &t->opts[i];
		metavar(o, mv, sizeof(mv));
		help = help_text(o);
		if (style == IRDM_OPT_STYLE_KEY)
			snprintf(syntax, sizeof(syntax), "  %s = %s", o->name, mv);
		else if (o->short_name)
			snprintf(syntax, sizeof(syntax), "  -%c, --%s%s%s", o->short_name, o->name,
				 mv[0] ? " " : "", mv);
		else
			snprintf(syntax, sizeof(syntax), "  --%s%s%s", o->name, mv[0] ? " " : "", mv);
		irdm_opt_range_text(o, o->name, range, sizeof(range));
		if (strlen(syntax) + 2 > HELP_COLUMN)
			fprintf(f, "%s\n%*s", syntax, HELP_COLUMN, "");
		else
			fprintf(f, "%-*s", HELP_COLUMN, syntax);
		print_wrapped(f, help ? help : o->help, range);
		free(help);
	}
}

/* Text in a table cell: '|' would end the cell. */
static void print_cell(FILE *f, const char *s)
{
	for (; *s; s++) {
		if (*s == '|')
			fputc('\\', f);
		fputc(*s, f);
	}
}

void irdm_opt_print_markdown(FILE *f, const struct irdm_opt_table *t)
{
	char mv[192], range[128], *help;

	fprintf(f, "| Key | Value | Range | Description |\n|---|---|---|---|\n");
	for (size_t i = 0; i < t->n_opts; i++) {
		const struct irdm_opt *o = &t->opts[i];
		metavar(o, mv, sizeof(mv));
		irdm_opt_range_text(o, o->name, range, sizeof(range));
		fprintf(f, "| `%s` | `", o->name);
		print_cell(f, mv);
		fputs("` | ", f);
		print_cell(f, range);
		fputs(" | ", f);
		help = help_text(o);
		print_cell(f, help ? help : o->help);
		free(help);
		fputs(" |\n", f);
	}
}
