/* SPDX-License-Identifier: MIT */
/*
 * Help and documentation from an option table (irdm/options.h): the
 * --help lines and the Markdown reference are printed from the same
 * entries that parse the values, so they cannot disagree.  Init time only
 * (stdio): the tools, irdm-fw and the board documentation use it.
 */
#ifndef IRDM_OPTIONS_DOC_H
#define IRDM_OPTIONS_DOC_H

#include <stdio.h>

#include "irdm/options.h"

enum irdm_opt_style {
	IRDM_OPT_STYLE_KEY, /* "  dt = SECONDS    help" (file keys) */
	IRDM_OPT_STYLE_ARG, /* "  --dt SECONDS    help" (arguments) */
};

/* One line per entry (two if the syntax is long): syntax, help, default, range. */
void irdm_opt_print_help(FILE *f, const struct irdm_opt_table *t, enum irdm_opt_style style);

/* A Markdown table: key, value syntax, range and unit, description and default. */
void irdm_opt_print_markdown(FILE *f, const struct irdm_opt_table *t);

#endif
