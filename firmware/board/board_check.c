/* SPDX-License-Identifier: MIT */
/*
 * A board as a whole, once every line is read: required keys, keys checked
 * against each other, and the derived fields.  Each refusal is one line that
 * names the line of the key at fault ("FILE:LINE: key: reason"), or the
 * file alone when the key kept its default.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "board_priv.h"
#include "irdm/error.h"

struct check {
	const struct irdm_board *b;
	const struct irdm_opt_file *f;
	char *err;
	size_t errlen;
};

/* The line key was set on, 0 if it kept its default. */
static unsigned line_of(const struct check *c, const char *key)
{
	const struct irdm_opt *o = irdm_opt_find(c->f->table, key);
	size_t i = o ? (size_t)(o - c->f->table->opts) : 64;

	if (i >= 64 || !(c->f->seen & (UINT64_C(1) << i)))
		return 0;
	return c->f->seen_line[i];
}

/* "line 12", or "default" for a key not in the file. */
static const char *line_text(const struct check *c, const char *key, char *buf, size_t len)
{
	unsigned line = line_of(c, key);

	if (!line)
		return "default";
	snprintf(buf, len, "line %u", line);
	return buf;
}

/* "FILE:LINE: key<fmt>" or, for a key not in the file, "FILE: default key<fmt>";
 * fmt goes on with ": reason" or " = value: reason".  Returns code. */
static int fail(const struct check *c, int code, const char *key, const char *fmt, ...)
{
	unsigned line = line_of(c, key);
	size_t at;
	va_list ap;

	if (line)
		at = (size_t)snprintf(c->err, c->errlen, "%s:%u: %s", c->f->name, line, key);
	else
		at = (size_t)snprintf(c->err, c->errlen, "%s: default %s", c->f->name, key);
	if (at < c->errlen) {
		va_start(ap, fmt);
		vsnprintf(c->err + at, c->errlen - at, fmt, ap);
		va_end(ap);
	}
	return code;
}

static int check_required(const struct check *c)
{
	static const char *const required[] = { "name", "hal", "workspace_min_m",
						"workspace_max_m" };

	for (size_t i = 0; i < sizeof(required) / sizeof(required[0]); i++) {
		if (line_of(c, required[i]))
			continue;
		snprintf(c->err, c->errlen, "%s: missing required key '%s' (see docs/boards.md)",
			 c->f->name, required[i]);
		return IRDM_EMISSING;
	}
	if (!c->b->name[0])
		return fail(c, IRDM_EINVAL, "name", ": must not be empty");
	if (!c->b->hal[0])
		return fail(c, IRDM_EINVAL, "hal", ": must not be empty");
	return IRDM_OK;
}

static int check_workspace(const struct check *c)
{
	static const char axis[] = "xyz";
	const struct irdm_board *b = c->b;
	char buf[32];

	for (int i = 0; i < 3; i++)
		if (!(b->workspace_min_m[i] < b->workspace_max_m[i]))
			return fail(c, IRDM_EINVAL, "workspace_min_m",
				    ": must be < workspace_max_m (%s) on every axis; %c: %.15g >= %.15g",
				    line_text(c, "workspace_max_m", buf, sizeof(buf)), axis[i],
				    b->workspace_min_m[i], b->workspace_max_m[i]);
	return IRDM_OK;
}

static int check_devices(const struct check *c)
{
	bool second = line_of(c, "device2_base_offset_m") != 0;

	if (c->b->devices == 2 && !second)
		return fail(c, IRDM_EINVAL, "devices", " = 2: needs device2_base_offset_m");
	if (c->b->devices == 1 && second)
		return fail(c, IRDM_EINVAL, "device2_base_offset_m",
			    ": only with devices = 2");
	return IRDM_OK;
}

static int check_arm(const struct check *c)
{
	const struct irdm_device_config *d = &c->b->device;
	char buf[32];

	for (int i = 0; i < IRDM_DEVICE_JOINTS; i++)
		if (d->count_min[i] >= d->count_max[i])
			return fail(c, IRDM_EINVAL, "count_min",
				    ": must be < count_max (%s) on every joint; joint %d: %ld >= %ld",
				    line_text(c, "count_max", buf, sizeof(buf)), i + 1,
				    (long)d->count_min[i], (long)d->count_max[i]);
	/* every field has passed its own range and the counts are in order, so
	 * this cannot fail unless device.h asks for more than the table does */
	if (irdm_device_config_check(d)) {
		snprintf(c->err, c->errlen, "%s: the arm is not valid (irdm_device_config_check)",
			 c->f->name);
		return IRDM_EINVAL;
	}
	return IRDM_OK;
}

static int check_loop(const struct check *c)
{
	const struct irdm_board *b = c->b;
	double tick_hz = 1e6 / b->period_us;
	char buf[32];

	if (b->watchdog_us <= b->period_us)
		return fail(c, IRDM_EINVAL, "watchdog_us", " = %u: must be > period_us = %u (%s)",
			    b->watchdog_us, b->period_us, line_text(c, "period_us", buf, sizeof(buf)));
	if (b->deform_rate_hz > tick_hz)
		return fail(c, IRDM_EINVAL, "deform_rate_hz",
			    " = %.15g: must be <= the tick rate, %.15g Hz (period_us, %s)",
			    b->deform_rate_hz, tick_hz, line_text(c, "period_us", buf, sizeof(buf)));
	return IRDM_OK;
}

/* A given coupling must be one the device can keep passive (Colgate &
 * Schenkel: b_device > K T / 2 + B), as the automatic one is by design. */
static int check_coupling(const struct check *c)
{
	const struct irdm_board *b = c->b;
	const struct irdm_device_config *d = &b->device;
	double t_s = b->period_us * 1e-6;
	double need = b->coupling_k_n_per_m * t_s / 2 + b->coupling_b_ns_per_m;

	if (b->coupling_auto)
		return IRDM_OK;
	if (b->coupling_k_n_per_m > d->k_max_n_per_m)
		return fail(c, IRDM_EINVAL, "coupling",
			    " = %.15g,%.15g: K must be <= max_stiffness_n_per_m = %.15g N/m",
			    b->coupling_k_n_per_m, b->coupling_b_ns_per_m, d->k_max_n_per_m);
	if (!(need < d->b_device_ns_per_m))
		return fail(c, IRDM_EINVAL, "coupling",
			    " = %.15g,%.15g: not passive: K period/2 + B = %.15g N s/m, must be < "
			    "device_damping_ns_per_m = %.15g",
			    b->coupling_k_n_per_m,
			    b->coupling_b_ns_per_m, need, d->b_device_ns_per_m);
	return IRDM_OK;
}

/* The controller enables only after calibrating at this pose: the encoders
 * must be able to read it and every arm's tip must be inside the box. */
static int check_calibration(const struct check *c)
{
	static const char axis[] = "xyz";
	const struct irdm_board *b = c->b;
	struct irdm_device_config d;
	int32_t counts[IRDM_DEVICE_JOINTS];
	double tip[3];

	if (irdm_device_counts_from_angles(&b->device, b->calibration_pose_rad, counts))
		return fail(c, IRDM_EINVAL, "calibration_pose_rad",
			    ": outside the encoders' [count_min, count_max]");
	for (unsigned k = 0; k < b->devices; k++) {
		irdm_board_device(b, k, &d);
		irdm_device_fk(&d, b->calibration_pose_rad, tip);
		for (int i = 0; i < 3; i++)
			if (!(tip[i] >= b->workspace_min_m[i] && tip[i] <= b->workspace_max_m[i]))
				return fail(c, IRDM_EINVAL, "calibration_pose_rad",
					    ": arm %u's tip is outside the workspace; %c = %.6g m",
					    k + 1, axis[i], tip[i]);
	}
	return IRDM_OK;
}

int irdm_board_finish(struct irdm_board *b, const struct irdm_opt_file *f, char *err,
		      size_t errlen)
{
	/* in this order: the later checks rely on what the earlier ones proved */
	static int (*const checks[])(const struct check *c) = {
		check_required,
		check_workspace,
		check_devices,
		check_arm,
		check_loop,
		check_coupling,
		check_calibration,
	};
	const struct check c = { .b = b, .f = f, .err = err, .errlen = errlen };
	int ret = IRDM_OK;

	for (size_t i = 0; i < sizeof(checks) / sizeof(checks[0]) && !ret; i++)
		ret = checks[i](&c);
	if (!ret) {
		irdm_board_set_rotation(b);
		b->hal_line = line_of(&c, "hal");
		b->hal_options_line = line_of(&c, "hal_options");
	}
	return ret;
}
