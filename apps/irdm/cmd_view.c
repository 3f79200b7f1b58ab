/* SPDX-License-Identifier: MIT */
/* irdm view: a recorded irdm-fw run played back in the browser. */
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "irdm/error.h"
#include "view/view_playback.h"
#include "view/view_server.h"

static const char usage[] =
	"usage: irdm view RUN.log --board BOARD --image IMAGE [--listen [ADDR:]PORT]\n"
	"                 [--every S]\n"
	"       irdm view DIR [--listen [ADDR:]PORT]\n"
	"\n"
	"Plays a run of irdm-fw (its --log) back in the browser: the page of\n"
	"irdm-fw --view (docs/view.md) with a time slider, play and a speed\n"
	"(0.1x to 4x).  The log holds the controller's side of each tick; the\n"
	"deformed surface is replayed on IMAGE and BOARD, the ones the run used\n"
	"(as irdm replay --log does), a frame every S seconds (default 0.02).\n"
	"DIR: a directory irdm render wrote (frames.pvd): its frames as they are,\n"
	"the surface and each contact's point and force, without the controller's\n"
	"state.\n"
	"Serves on ADDR:PORT (default 127.0.0.1:8080; PORT 0: any free port; an\n"
	"address other than 127.0.0.1 is served with a warning) until SIGINT or\n"
	"SIGTERM; prints the page's address first.  The page only watches.\n"
	"Exit: 0 stopped by a signal, 1 bad log, board or image, or the address\n"
	"cannot be served, 2 usage.\n";

static volatile sig_atomic_t signalled;

static void on_signal(int sig)
{
	signalled = sig;
}

/* In the server's thread, 10 times a second: a signal stops it (the
 * handler itself only sets the flag). */
static void watch_signal(void *ctx, struct view_server *s)
{
	(void)ctx;
	if (signalled)
		view_server_stop(s);
}

static bool is_dir(const char *path)
{
	struct stat st;

	return !stat(path, &st) && S_ISDIR(st.st_mode);
}

struct args {
	struct view_playback_opts pb;
	const char *listen;
};

/* 0 parsed, 1 help printed, 2 usage error (said). */
static int parse(struct args *a, int argc, char **argv)
{
	a->pb.every_s = 0.02;
	a->listen = "127.0.0.1:8080";
	for (int i = 1; i < argc; i++) {
		const char *o = argv[i];
		char *end;

		if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
			fputs(usage, stdout);
			return 1;
		}
		if (o[0] == '-' && o[1]) {
			if (strcmp(o, "--board") && strcmp(o, "--image") && strcmp(o, "--listen") &&
			    strcmp(o, "--every")) {
				fprintf(stderr, "irdm view: unknown option '%s' (see --help)\n", o);
				return 2;
			}
			if (i + 1 >= argc) {
				fprintf(stderr, "irdm view: %s needs a value\n", o);
				return 2;
			}
			if (!strcmp(o, "--board"))
				a->pb.board = argv[++i];
			else if (!strcmp(o, "--image"))
				a->pb.image = argv[++i];
			else if (!strcmp(o, "--listen"))
				a->listen = argv[++i];
			else {
				a->pb.every_s = strtod(argv[++i], &end);
				if (*end || !(a->pb.every_s > 0) || a->pb.every_s > 86400) {
					fprintf(stderr, "irdm view: --every '%s': expected seconds > 0\n",
						argv[i]);
					return 2;
				}
			}
		} else if (!a->pb.log) {
			a->pb.log = o;
		} else {
			fprintf(stderr, "irdm view: one RUN.log only ('%s' is extra)\n", o);
			return 2;
		}
	}
	if (a->pb.log && is_dir(a->pb.log)) {
		if (a->pb.board || a->pb.image) {
			fprintf(stderr, "irdm view: %s is a render directory: it needs no --board "
					"or --image\n",
				a->pb.log);
			return 2;
		}
		return 0;
	}
	if (!a->pb.log || !a->pb.board || !a->pb.image) {
		fprintf(stderr, "irdm view: needs RUN.log, --board BOARD and --image IMAGE, or a "
				"render directory (see --help)\n");
		return 2;
	}
	return 0;
}

static int serve(struct view_server *s, const char *addr)
{
	struct sigaction sa;

	if (strcmp(addr, VIEW_DEFAULT_ADDR))
		fprintf(stderr, "irdm view: warning: listening on %s:%u: whoever reaches it can "
				"watch the run\n",
			addr, view_server_port(s));
	printf("view: http://%s:%u/ (Ctrl-C to stop)\n", addr, view_server_port(s));
	fflush(stdout);
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	return view_server_run(s);
}

int irdm_cmd_view(int argc, char **argv)
{
	struct args a = { 0 };
	struct view_server_config c = { .rate_hz = 10, .tick = watch_signal, .max_frame = 1 };
	struct view_playback_summary sum;
	struct view_server *s;
	char addr[64], err[1024];
	int rc = parse(&a, argc, argv);

	if (rc)
		return rc == 1 ? 0 : 2;
	if (view_parse_listen(a.listen, addr, sizeof(addr), &c.port)) {
		fprintf(stderr, "irdm view: --listen '%s': expected [ADDR:]PORT, PORT 0..65535\n",
			a.listen);
		return 2;
	}
	c.addr = addr;
	rc = view_server_open(&s, &c, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("view", rc, err);
		return 1;
	}
	if (is_dir(a.pb.log))
		rc = view_render_dir_load(s, a.pb.log, &sum, err, sizeof(err));
	else
		rc = view_playback_load(s, &a.pb, &sum, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("view", rc, err);
		view_server_close(s);
		return 1;
	}
	if (is_dir(a.pb.log))
		printf("view: %s: %zu frames to %.3f s\n", a.pb.log, sum.frames, sum.duration_s);
	else
		printf("view: %s: %zu ticks (%.3f s), %zu frames; replayed forces within %.3g N of "
		       "the log's (peak %.3g N)\n",
		       a.pb.log, sum.records, sum.duration_s, sum.frames,
		       sum.log_max_diff_n, sum.log_peak_n);
	rc = serve(s, addr);
	view_server_close(s);
	return rc ? 1 : 0;
}
