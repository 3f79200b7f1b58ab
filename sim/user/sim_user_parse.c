/* SPDX-License-Identifier: MIT */
/*
 * Virtual-user scripts -> segments (irdm/sim_user.h states the format).
 *
 * One pass, line by line.  Each hand keeps a small state (its clock, target,
 * spring and whether it holds); a command checks itself against that state
 * and appends at most one segment, so the struct never holds a script that
 * breaks a rule and evaluation needs no checks of its own.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/posix/textfile.h"
#include "irdm/sim/sim_user.h"

#define TOKENS_MAX 12

struct hand_state {
	double clock_s; /* when the hand's last command ends */
	double target_m[3];
	double k_n_per_m, b_ns_per_m;
	int active;
	int target_home; /* target_m is an offset from home */
};

struct parser {
	struct irdm_sim_user *u;
	const char *name;
	unsigned line;
	char *err;
	size_t errlen;
	double last_at_s;
	unsigned commands;
	struct hand_state h[IRDM_SIM_USER_HANDS];
};

/* One command being read: its tokens, the hand it names and when it starts. */
struct cmd {
	char *tok[TOKENS_MAX];
	unsigned ntok, i; /* i: the next token to read */
	const char *what; /* the command word, for messages */
	unsigned hand;    /* 0-based */
	double start_s;
};

static int fail(struct parser *p, int code, const char *what, const char *fmt, ...)
{
	char reason[160];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(reason, sizeof(reason), fmt, ap);
	va_end(ap);
	if (p->err && p->errlen) {
		if (p->line)
			snprintf(p->err, p->errlen, "%s:%u: %s%s%s", p->name, p->line,
				 what ? what : "", what ? ": " : "", reason);
		else
			snprintf(p->err, p->errlen, "%s: %s", p->name, reason);
	}
	return code;
}

/* ---- tokens --------------------------------------------------------------- */

static int split(struct parser *p, char *s, struct cmd *c)
{
	char *hash = strchr(s, '#'), *save = NULL, *t;

	if (hash)
		*hash = '\0';
	c->ntok = 0;
	c->i = 0;
	for (t = strtok_r(s, " \t\r\n", &save); t; t = strtok_r(NULL, " \t\r\n", &save)) {
		if (c->ntok == TOKENS_MAX)
			return fail(p, IRDM_EFORMAT, NULL, "more than %d words", TOKENS_MAX);
		c->tok[c->ntok++] = t;
	}
	return IRDM_OK;
}

static const char *next(struct cmd *c)
{
	return c->i < c->ntok ? c->tok[c->i++] : NULL;
}

/* A number: the whole token, finite. */
static int number(struct parser *p, const struct cmd *c, const char *tok, const char *name,
		  double *v)
{
	char *end;

	if (!tok)
		return fail(p, IRDM_EFORMAT, c->what, "expected %s", name);
	*v = strtod(tok, &end);
	if (end == tok || *end)
		return fail(p, IRDM_EFORMAT, c->what, "expected %s, got '%s'", name, tok);
	if (!isfinite(*v)) /* "inf", "nan", or overflowed to inf */
		return fail(p, IRDM_EFORMAT, c->what, "%s '%s' is not finite", name, tok);
	return IRDM_OK;
}

static int in_range(struct parser *p, const struct cmd *c, const char *name, double v,
		    double lo, int lo_open, double hi)
{
	if (v < lo || (lo_open && v == lo) || v > hi)
		return fail(p, IRDM_EFORMAT, c->what, "%s %g outside %c%g, %g]", name, v,
			    lo_open ? '(' : '[', lo, hi);
	return IRDM_OK;
}

/* "X,Y,Z": three finite numbers within +-IRDM_SIM_USER_COORD_MAX_M. */
static int vector(struct parser *p, const struct cmd *c, const char *tok, double v[3])
{
	const char *s = tok;
	char *end;
	int i;

	if (!tok)
		return fail(p, IRDM_EFORMAT, c->what, "expected X,Y,Z");
	for (i = 0; i < 3; i++) {
		v[i] = strtod(s, &end);
		if (end == s || *end != (i < 2 ? ',' : '\0'))
			return fail(p, IRDM_EFORMAT, c->what, "expected X,Y,Z, got '%s'", tok);
		if (!isfinite(v[i]))
			return fail(p, IRDM_EFORMAT, c->what, "'%s' is not finite", tok);
		s = end + 1;
	}
	for (i = 0; i < 3; i++)
		if (fabs(v[i]) > IRDM_SIM_USER_COORD_MAX_M)
			return fail(p, IRDM_EFORMAT, c->what, "%g m is beyond +-%g m",
				    v[i], IRDM_SIM_USER_COORD_MAX_M);
	return IRDM_OK;
}

static int keyword(struct parser *p, const struct cmd *c, const char *tok, const char *want)
{
	if (!tok || strcmp(tok, want))
		return fail(p, IRDM_EFORMAT, c->what, "expected '%s'%s%s%s", want,
			    tok ? ", got '" : "", tok ? tok : "", tok ? "'" : "");
	return IRDM_OK;
}

static int duration(struct parser *p, const struct cmd *c, const char *tok, double *d_s)
{
	int ret = number(p, c, tok, "a duration", d_s);

	if (!ret)
		ret = in_range(p, c, "duration", *d_s, 0, 1, IRDM_SIM_USER_TIME_MAX_S);
	return ret;
}

static int finished(struct parser *p, const struct cmd *c)
{
	if (c->i < c->ntok)
		return fail(p, IRDM_EFORMAT, c->what, "unexpected '%s'", c->tok[c->i]);
	return IRDM_OK;
}

/* ---- segments -------------------------------------------------------------- */

static int push(struct parser *p, const struct cmd *c, double dur_s, const double to_m[3],
		int to_home)
{
	struct irdm_sim_user_hand *uh = &p->u->hand[c->hand];
	struct hand_state *h = &p->h[c->hand];
	struct irdm_sim_user_seg *s;

	if (uh->n == IRDM_SIM_USER_SEGMENTS_MAX)
		return fail(p, IRDM_ENOMEM, c->what, "hand %u has more than %d segments",
			    c->hand + 1, IRDM_SIM_USER_SEGMENTS_MAX);
	s = &uh->seg[uh->n++];
	s->t0_s = c->start_s;
	s->t1_s = c->start_s + dur_s;
	memcpy(s->from_m, h->target_m, sizeof(s->from_m));
	memcpy(s->to_m, to_m, sizeof(s->to_m));
	s->from_home = h->target_home;
	s->to_home = to_home;
	h->target_home = to_home;
	uh->needs_home |= to_home;
	s->k_n_per_m = h->k_n_per_m;
	s->b_ns_per_m = h->b_ns_per_m;
	s->active = h->active;
	memcpy(h->target_m, to_m, sizeof(h->target_m));
	return IRDM_OK;
}

/* A hand's clock moves on by dur_s; the end is capped like any time. */
static int advance(struct parser *p, const struct cmd *c, double dur_s)
{
	double end_s = c->start_s + dur_s;

	if (end_s > IRDM_SIM_USER_TIME_MAX_S)
		return fail(p, IRDM_EFORMAT, c->what, "ends at %g s, after %g s", end_s,
			    IRDM_SIM_USER_TIME_MAX_S);
	p->h[c->hand].clock_s = end_s;
	return IRDM_OK;
}

static int need_active(struct parser *p, const struct cmd *c, int want)
{
	if (p->h[c->hand].active != want)
		return fail(p, IRDM_EFORMAT, c->what, want ? "hand %u is not placed" : "hand %u already holds (release it first)", c->hand + 1);
	return IRDM_OK;
}

/* ---- commands -------------------------------------------------------------- */

static int cmd_place(struct parser *p, struct cmd *c)
{
	double at_m[3];
	const char *where;
	int ret, home;

	ret = need_active(p, c, 0);
	if (!ret)
		ret = keyword(p, c, next(c), "at");
	where = next(c);
	home = where && !strcmp(where, "home");
	if (home)
		memset(at_m, 0, sizeof(at_m));
	else if (!ret)
		ret = vector(p, c, where, at_m);
	if (!ret)
		ret = finished(p, c);
	if (ret)
		return ret;
	/* the target jumps while the hand is away: from == to */
	memcpy(p->h[c->hand].target_m, at_m, sizeof(at_m));
	p->h[c->hand].target_home = home;
	p->h[c->hand].active = 1;
	return push(p, c, 0, at_m, home);
}

static int cmd_move(struct parser *p, struct cmd *c)
{
	const double *cur = p->h[c->hand].target_m;
	const char *how;
	double v[3], d_s;
	int ret, relative, i;

	ret = need_active(p, c, 1);
	if (ret)
		return ret;
	how = next(c);
	relative = how && !strcmp(how, "by");
	if (!how || (!relative && strcmp(how, "to")))
		return fail(p, IRDM_EFORMAT, c->what, "expected 'to' or 'by'");
	ret = vector(p, c, next(c), v);
	if (!ret)
		ret = keyword(p, c, next(c), "over");
	if (!ret)
		ret = duration(p, c, next(c), &d_s);
	if (!ret)
		ret = finished(p, c);
	if (ret)
		return ret;
	/* from home, the sum is checked again when home is known */
	for (i = 0; relative && i < 3; i++) {
		v[i] += cur[i];
		if (fabs(v[i]) > IRDM_SIM_USER_COORD_MAX_M)
			return fail(p, IRDM_EFORMAT, c->what, "the target %g m is beyond +-%g m",
				    v[i], IRDM_SIM_USER_COORD_MAX_M);
	}
	ret = advance(p, c, d_s);
	return ret ? ret : push(p, c, d_s, v, relative && p->h[c->hand].target_home);
}

static int cmd_hold(struct parser *p, struct cmd *c)
{
	double d_s;
	int ret;

	ret = keyword(p, c, next(c), "for");
	if (!ret)
		ret = duration(p, c, next(c), &d_s);
	if (!ret)
		ret = finished(p, c);
	return ret ? ret : advance(p, c, d_s);
}

static int cmd_release(struct parser *p, struct cmd *c)
{
	int ret = need_active(p, c, 1);

	if (!ret)
		ret = finished(p, c);
	if (ret)
		return ret;
	p->h[c->hand].active = 0;
	return push(p, c, 0, p->h[c->hand].target_m, p->h[c->hand].target_home);
}

/* stiffness and damping: a new segment only if the hand holds (else the
 * next place picks the value up) */
static int cmd_spring(struct parser *p, struct cmd *c)
{
	struct hand_state *h = &p->h[c->hand];
	int stiff = !strcmp(c->what, "stiffness");
	double v;
	int ret;

	ret = number(p, c, next(c), stiff ? "K (N/m)" : "B (N s/m)", &v);
	if (!ret)
		ret = stiff ? in_range(p, c, "K", v, 0, 1, IRDM_SIM_USER_K_MAX_N_PER_M) :
			      in_range(p, c, "B", v, 0, 0, IRDM_SIM_USER_B_MAX_NS_PER_M);
	if (!ret)
		ret = finished(p, c);
	if (ret)
		return ret;
	if (stiff)
		h->k_n_per_m = v;
	else
		h->b_ns_per_m = v;
	return h->active ? push(p, c, 0, h->target_m, h->target_home) : IRDM_OK;
}

static const struct {
	const char *word;
	int (*run)(struct parser *p, struct cmd *c);
} commands[] = {
	{ "place", cmd_place },
	{ "move", cmd_move },
	{ "hold", cmd_hold },
	{ "release", cmd_release },
	{ "stiffness", cmd_spring },
	{ "damping", cmd_spring },
};

/* ---- a line ---------------------------------------------------------------- */

/* "at T": no earlier than the previous 'at' in the file. */
static int start_time(struct parser *p, struct cmd *c, int *given, double *t_s)
{
	int ret;

	*given = c->ntok && !strcmp(c->tok[0], "at");
	if (!*given)
		return IRDM_OK;
	c->what = "at";
	c->i = 1;
	ret = number(p, c, next(c), "a time", t_s);
	if (!ret)
		ret = in_range(p, c, "time", *t_s, 0, 0, IRDM_SIM_USER_TIME_MAX_S);
	if (!ret && *t_s < p->last_at_s)
		ret = fail(p, IRDM_EFORMAT, c->what, "time %g is before the previous 'at' (%g)",
			   *t_s, p->last_at_s);
	if (!ret && c->i == c->ntok)
		ret = fail(p, IRDM_EFORMAT, c->what, "expected a command after the time");
	if (!ret)
		p->last_at_s = *t_s;
	return ret;
}

static int hand_number(struct parser *p, struct cmd *c)
{
	const char *tok = next(c);
	char *end;
	long n;

	if (!tok)
		return fail(p, IRDM_EFORMAT, c->what, "expected a hand (1 to %d)",
			    IRDM_SIM_USER_HANDS);
	n = strtol(tok, &end, 10);
	if (end == tok || *end || n < 1 || n > IRDM_SIM_USER_HANDS)
		return fail(p, IRDM_EFORMAT, c->what, "expected a hand (1 to %d), got '%s'",
			    IRDM_SIM_USER_HANDS, tok);
	c->hand = (unsigned)n - 1;
	return IRDM_OK;
}

static int lookup(struct parser *p, const struct cmd *c, int *k)
{
	for (*k = 0; *k < (int)(sizeof(commands) / sizeof(commands[0])); (*k)++)
		if (!strcmp(c->what, commands[*k].word))
			return IRDM_OK;
	return fail(p, IRDM_EFORMAT, NULL, "unknown command '%s'", c->what);
}

static int parse_line(struct parser *p, char *s)
{
	struct cmd c;
	double t_s = 0;
	int given, k, ret;

	ret = split(p, s, &c);
	if (ret || !c.ntok)
		return ret;
	ret = start_time(p, &c, &given, &t_s);
	if (ret)
		return ret;
	c.what = next(&c);
	ret = lookup(p, &c, &k);
	if (!ret)
		ret = hand_number(p, &c);
	if (ret)
		return ret;
	if (given && t_s < p->h[c.hand].clock_s)
		return fail(p, IRDM_EFORMAT, c.what, "starts at %g s but hand %u is busy until %g s",
			    t_s, c.hand + 1, p->h[c.hand].clock_s);
	c.start_s = given ? t_s : p->h[c.hand].clock_s;
	ret = commands[k].run(p, &c);
	if (ret)
		return ret;
	if (c.hand + 1 > p->u->hands)
		p->u->hands = c.hand + 1;
	p->commands++;
	return IRDM_OK;
}

/* ---- whole scripts --------------------------------------------------------- */

static void parse_begin(struct parser *p, struct irdm_sim_user *u, const char *name, char *err,
			size_t errlen)
{
	unsigned i;

	memset(u, 0, sizeof(*u));
	memset(p, 0, sizeof(*p));
	p->u = u;
	p->name = name;
	p->err = err;
	p->errlen = errlen;
	for (i = 0; i < IRDM_SIM_USER_HANDS; i++) {
		p->h[i].k_n_per_m = IRDM_SIM_USER_K_DEFAULT_N_PER_M;
		p->h[i].b_ns_per_m = IRDM_SIM_USER_B_DEFAULT_NS_PER_M;
	}
	if (err && errlen)
		err[0] = '\0';
}

static int parse_end(struct parser *p, int ret)
{
	unsigned i;

	if (!ret && !p->commands) {
		p->line = 0;
		ret = fail(p, IRDM_EFORMAT, NULL, "no command");
	}
	if (ret) {
		memset(p->u, 0, sizeof(*p->u));
		return ret;
	}
	for (i = 0; i < IRDM_SIM_USER_HANDS; i++)
		if (p->h[i].clock_s > p->u->end_s)
			p->u->end_s = p->h[i].clock_s;
	return IRDM_OK;
}

/*
 * At most LINE_CHARS characters before the newline: the file reader's
 * buffer holds them, the newline and the NUL.
 */
#define LINE_CHARS (IRDM_SIM_USER_LINE_MAX - 2)

static int too_long(struct parser *p)
{
	return fail(p, IRDM_EFORMAT, NULL, "line longer than %d characters", LINE_CHARS);
}

int irdm_sim_user_parse(struct irdm_sim_user *u, const char *name, const char *text,
			char *err, size_t errlen)
{
	struct parser p;
	char buf[IRDM_SIM_USER_LINE_MAX];
	const char *s = text;
	int ret = IRDM_OK;

	if (!u || !text)
		return IRDM_EINVAL;
	parse_begin(&p, u, name ? name : "(script)", err, errlen);
	while (!ret && *s) {
		const char *nl = strchr(s, '\n');
		size_t len = nl ? (size_t)(nl - s) + 1 : strlen(s);

		p.line++;
		if (len - (nl != NULL) > LINE_CHARS) {
			ret = too_long(&p);
			break;
		}
		memcpy(buf, s, len);
		buf[len] = '\0';
		ret = parse_line(&p, buf);
		s += len;
	}
	return parse_end(&p, ret);
}

int irdm_sim_user_load(struct irdm_sim_user *u, const char *path, char *err, size_t errlen)
{
	struct irdm_text_file t;
	struct parser p;
	char buf[IRDM_SIM_USER_LINE_MAX];
	int ret;

	if (!u || !path)
		return IRDM_EINVAL;
	parse_begin(&p, u, path, err, errlen);
	ret = irdm_text_open(&t, path, IRDM_TEXT_MAX_BYTES, err, errlen);
	if (ret)
		return parse_end(&p, ret);
	/* one character short of the buffer: the reader's line, newline dropped */
	while ((ret = irdm_text_line(&t, buf, LINE_CHARS + 1, err, errlen)) > 0) {
		p.line++;
		ret = parse_line(&p, buf);
		if (ret)
			break;
	}
	irdm_text_close(&t);
	return parse_end(&p, ret);
}
