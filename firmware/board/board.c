/* SPDX-License-Identifier: MIT */
/*
 * Board files: read the lines (from memory here; from a file in
 * platform/posix/board/board_file.c) through the option table, then check the board as a whole.  Runs once at
 * start, never in the tick.
 */
#include <stdio.h>
#include <string.h>

#include "board_priv.h"
#include "irdm/error.h"

void irdm_board_default(struct irdm_board *b)
{
	char why[256];

	memset(b, 0, sizeof(*b));
	/* every default is the table's: a default it refused would be a broken
	 * table, which tests/test_board.c rules out entry by entry */
	(void)irdm_opt_set_defaults(irdm_board_options(), b, why, sizeof(why));
	irdm_board_set_rotation(b);
}

void irdm_board_read_begin(struct irdm_opt_file *f, struct irdm_board *b, const char *name)
{
	irdm_board_default(b);
	memset(f, 0, sizeof(*f));
	f->table = irdm_board_options();
	f->obj = b;
	f->name = name;
	f->reject_duplicates = true;
}

int irdm_board_read_line(struct irdm_opt_file *f, const char *s, size_t len, char *err,
			 size_t errlen)
{
	char line[IRDM_BOARD_LINE_MAX];

	f->line_no++;
	if (len >= sizeof(line)) {
		snprintf(err, errlen, "%s:%u: line longer than %d characters", f->name, f->line_no,
			 IRDM_BOARD_LINE_MAX - 1);
		return IRDM_EFORMAT;
	}
	memcpy(line, s, len);
	line[len] = 0;
	return irdm_opt_parse_line(f, line, err, errlen);
}

int irdm_board_parse(struct irdm_board *b, const char *name, const char *text,
		     char *err, size_t errlen)
{
	struct irdm_opt_file f;
	int ret = IRDM_OK;

	irdm_board_read_begin(&f, b, name);
	while (*text && !ret) {
		size_t len = strcspn(text, "\n");
		ret = irdm_board_read_line(&f, text, len, err, errlen);
		text += len + (text[len] == '\n');
	}
	if (!ret)
		ret = irdm_board_finish(b, &f, err, errlen);
	return ret;
}

void irdm_board_engine_config(const struct irdm_board *b, struct irdm_engine_config *cfg)
{
	const struct irdm_device_config *d = &b->device;

	irdm_engine_config_haptic(cfg, b->period_us * 1e-6, d->k_max_n_per_m, d->b_device_ns_per_m,
				  d->max_force_n);
	if (!b->coupling_auto) {
		cfg->coupling_k_n_per_m = b->coupling_k_n_per_m;
		cfg->coupling_b_ns_per_m = b->coupling_b_ns_per_m;
	}
}
