// SPDX-License-Identifier: MIT
/*
 * Tetrahedralise a closed triangle surface by running Debian's `tetgen`
 * (1.5) in a private mkdtemp() directory, then read its .node/.ele back.
 * tetgen is started with posix_spawnp() and an argument vector, so no
 * shell ever sees a path.  $IRDM_TETGEN overrides the program name.
 *
 * With its output in a file tetgen's own messages are mostly lost (it
 * aborts on bad input before flushing stdout), so failures carry the
 * last line it did write plus a hint about the usual causes.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "irdm/error.h"
#include "irdm/posix/outdir.h"
#include "mesh/mesh_priv.h"
#include "util/interrupt.h"

extern char **environ;

/* Quality bound on the radius-edge ratio; no volume bound (units vary). */
#define DEFAULT_SWITCHES "pq1.414"
#define PATH_BYTES 4096

struct tg_run {
	char dir[PATH_BYTES - 32]; /* room left for "/surf.1.node" */
	char smesh[PATH_BYTES];
	char node[PATH_BYTES];
	char ele[PATH_BYTES];
	char log[PATH_BYTES];
	char sw[128];
	char out_what[256]; /* "<what> (tetgen output)" */
};

/* "-" + switches (+ 'p' so the .smesh facets are read) + 'Q' (quiet). */
static int build_switches(struct tg_run *r, const char *sw, const char *what,
			  char *err, size_t errlen)
{
	size_t i;
	int n;

	if (!sw || !*sw)
		sw = DEFAULT_SWITCHES;
	if (*sw == '-')
		sw++;
	for (i = 0; sw[i]; i++) {
		char c = sw[i];

		if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
		      (c >= '0' && c <= '9') || c == '.' || c == '/' ||
		      c == '-')) {
			mesh_err(err, errlen, what,
				 "tetgen switches may hold only letters, digits, '.', '/' and '-'");
			return IRDM_EINVAL;
		}
	}
	n = snprintf(r->sw, sizeof(r->sw), "-%s%s%s", strchr(sw, 'p') ? "" : "p",
		     sw, strchr(sw, 'Q') ? "" : "Q");
	if (n < 0 || (size_t)n >= sizeof(r->sw)) {
		mesh_err(err, errlen, what, "tetgen switches are too long");
		return IRDM_EINVAL;
	}
	return 0;
}

static int make_paths(struct tg_run *r, const char *what, char *err,
		      size_t errlen)
{
	const char *tmp = getenv("TMPDIR");
	int n;

	if (!tmp || !*tmp)
		tmp = "/tmp";
	n = snprintf(r->dir, sizeof(r->dir), "%s/irdm-mesh-XXXXXX", tmp);
	if (n < 0 || (size_t)n >= sizeof(r->dir)) {
		mesh_err(err, errlen, what, "TMPDIR is too long");
		return IRDM_EINVAL;
	}
	if (!mkdtemp(r->dir)) {
		mesh_err(err, errlen, what, "cannot create a temporary directory in %s: %s",
			 tmp, strerror(errno));
		return IRDM_EIO;
	}
	snprintf(r->smesh, sizeof(r->smesh), "%s/surf.smesh", r->dir);
	snprintf(r->node, sizeof(r->node), "%s/surf.1.node", r->dir);
	snprintf(r->ele, sizeof(r->ele), "%s/surf.1.ele", r->dir);
	snprintf(r->log, sizeof(r->log), "%s/tetgen.log", r->dir);
	snprintf(r->out_what, sizeof(r->out_what), "%s (tetgen output)", what);
	return 0;
}

/* Remove the private directory and whatever tetgen left in it. */
static void remove_dir(const char *dir)
{
	irdm_outdir_remove_files(dir);
}

/*
 * Write a .smesh (0-based, only referenced vertices, so tetgen sees no
 * stray points).  %.17g round-trips every double.
 */
static int write_smesh(const struct tg_run *r, const struct irdm_surface *s,
		       const char *what, char *err, size_t errlen)
{
	uint32_t *remap;
	size_t i, nv = 0;
	FILE *f;
	int bad;

	remap = malloc(s->n_verts * sizeof(*remap));
	if (!remap) {
		mesh_err(err, errlen, what, "out of memory");
		return IRDM_ENOMEM;
	}
	for (i = 0; i < s->n_verts; i++)
		remap[i] = UINT32_MAX;
	for (i = 0; i < 3 * s->n_tris; i++)
		remap[s->tris[i]] = 0;
	for (i = 0; i < s->n_verts; i++)
		if (!remap[i])
			remap[i] = (uint32_t)nv++;
	f = fopen(r->smesh, "w");
	if (!f) {
		mesh_err(err, errlen, what, "cannot write %s: %s", r->smesh,
			 strerror(errno));
		free(remap);
		return IRDM_EIO;
	}
	fprintf(f, "%zu 3 0 0\n", nv);
	for (i = 0; i < s->n_verts; i++)
		if (remap[i] != UINT32_MAX)
			fprintf(f, "%lu %.17g %.17g %.17g\n", (unsigned long)remap[i],
				s->pos_m[3 * i], s->pos_m[3 * i + 1], s->pos_m[3 * i + 2]);
	fprintf(f, "%zu 0\n", s->n_tris);
	for (i = 0; i < s->n_tris; i++)
		fprintf(f, "3 %lu %lu %lu\n", (unsigned long)remap[s->tris[3 * i]],
			(unsigned long)remap[s->tris[3 * i + 1]],
			(unsigned long)remap[s->tris[3 * i + 2]]);
	fprintf(f, "0\n0\n");
	bad = ferror(f);
	bad |= fclose(f);
	free(remap);
	if (bad) {
		mesh_err(err, errlen, what, "cannot write %s", r->smesh);
		return IRDM_EIO;
	}
	return IRDM_OK;
}

/*
 * The last line tetgen wrote that says more than "Opening <file>." or the
 * C++ runtime's "terminate called ...".
 */
static void last_log_line(const char *log, char *out, size_t outlen)
{
	char scratch[8];
	struct mtext t;
	struct mline l, last = { NULL, 0, 0, 0 };
	char *txt;
	size_t len;

	out[0] = '\0';
	if (mesh_read_file(log, &txt, &len, scratch, sizeof(scratch)))
		return;
	mtext_init(&t, txt, len, -1);
	while (mtext_next_line(&t, &l))
		if (!mline_is(&l, "terminate") && !mline_is(&l, "Opening"))
			last = l;
	if (last.p) {
		size_t n = last.len - last.pos, i;

		for (i = 0; i < n && i + 1 < outlen; i++) {
			char c = last.p[last.pos + i];

			out[i] = c >= ' ' && c < 127 ? c : '?';
		}
		out[i] = '\0';
	}
	free(txt);
}

/*
 * tetgen runs in a process group of its own: a terminal's Ctrl-C reaches
 * irdm alone, whose handler (util/interrupt.h) stops the group and removes
 * the directory, so no tetgen outlives an interrupted irdm.
 */
static int spawn_tetgen(const struct tg_run *r, const char *prog, pid_t *pid)
{
	posix_spawn_file_actions_t fa;
	posix_spawnattr_t at;
	char *argv[4];
	int rc;

	argv[0] = (char *)prog;
	argv[1] = (char *)r->sw;
	argv[2] = (char *)r->smesh;
	argv[3] = NULL;
	rc = posix_spawn_file_actions_init(&fa);
	if (rc)
		return rc;
	rc = posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
	if (!rc)
		rc = posix_spawn_file_actions_addopen(&fa, 1, r->log,
						      O_WRONLY | O_CREAT | O_TRUNC,
						      0600);
	if (!rc)
		rc = posix_spawn_file_actions_adddup2(&fa, 1, 2);
	if (!rc)
		rc = posix_spawnattr_init(&at);
	if (!rc) {
		rc = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP);
		if (!rc)
			rc = posix_spawnattr_setpgroup(&at, 0);
		if (!rc)
			rc = posix_spawnp(pid, prog, &fa, &at, argv, environ);
		posix_spawnattr_destroy(&at);
	}
	posix_spawn_file_actions_destroy(&fa);
	return rc;
}

static int run_tetgen(const struct tg_run *r, const char *what, char *err,
		      size_t errlen)
{
	const char *prog = getenv("IRDM_TETGEN");
	char last[160];
	pid_t pid;
	int rc, status, slot;

	if (!prog || !*prog)
		prog = "tetgen";
	rc = spawn_tetgen(r, prog, &pid);
	if (rc) {
		mesh_err(err, errlen, what, "cannot run %s: %s%s", prog, strerror(rc),
			 rc == ENOENT ? " (install Debian's tetgen package)" : "");
		return IRDM_ECHILD;
	}
	slot = irdm_interrupt_add(IRDM_INTERRUPT_PGROUP, NULL, pid);
	while (waitpid(pid, &status, 0) < 0) {
		if (errno != EINTR) {
			mesh_err(err, errlen, what, "waiting for %s: %s", prog,
				 strerror(errno));
			irdm_interrupt_del(slot);
			return IRDM_ECHILD;
		}
	}
	irdm_interrupt_del(slot);
	if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
		return 0;
	last_log_line(r->log, last, sizeof(last));
	mesh_err(err, errlen, what,
		 "%s %s failed (%s %d; is the surface closed and free of self-intersections?)%s%s",
		 prog, r->sw, WIFEXITED(status) ? "exit status" : "signal",
		 WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status),
		 last[0] ? ": " : "", last);
	return IRDM_ECHILD;
}

static int read_result(const struct tg_run *r, struct irdm_mesh *m,
		       const char *what, char *err, size_t errlen)
{
	struct mesh_labels lab = { r->out_what, r->out_what, NULL, NULL };
	char *node_txt = NULL, *ele_txt = NULL, last[160];
	size_t node_len, ele_len;
	int ret;

	if (access(r->ele, F_OK)) {
		last_log_line(r->log, last, sizeof(last));
		mesh_err(err, errlen, what,
			 "tetgen produced no tetrahedra (is the surface closed?)%s%s",
			 last[0] ? ": " : "", last);
		return IRDM_ECHILD;
	}
	ret = mesh_read_file(r->node, &node_txt, &node_len, err, errlen);
	if (!ret)
		ret = mesh_read_file(r->ele, &ele_txt, &ele_len, err, errlen);
	if (!ret)
		ret = mesh_parse_tetgen_labeled(node_txt, node_len, ele_txt, ele_len, m,
						&lab, err, errlen);
	if (ret)
		goto out_free;
	ret = mesh_finish_labeled(m, &lab, err, errlen);
out_free:
	mesh_labels_free(&lab);
	free(ele_txt);
	free(node_txt);
	return ret;
}

int irdm_surface_tetrahedralize(const struct irdm_surface *s, const char *switches,
				const char *what, struct irdm_mesh *m,
				char *err, size_t errlen)
{
	struct tg_run *r;
	int ret, slot;

	memset(m, 0, sizeof(*m));
	if (!what)
		what = "surface";
	ret = surface_check(s, what, err, errlen);
	if (!ret)
		ret = surface_check_closed(s, what, err, errlen);
	if (ret)
		return ret;
	r = calloc(1, sizeof(*r));
	if (!r) {
		mesh_err(err, errlen, what, "out of memory");
		return IRDM_ENOMEM;
	}
	ret = build_switches(r, switches, what, err, errlen);
	if (!ret)
		ret = make_paths(r, what, err, errlen);
	if (ret)
		goto out_free;
	slot = irdm_interrupt_add(IRDM_INTERRUPT_DIR, r->dir, 0);
	ret = write_smesh(r, s, what, err, errlen);
	if (!ret)
		ret = run_tetgen(r, what, err, errlen);
	if (!ret)
		ret = read_result(r, m, what, err, errlen);
	remove_dir(r->dir);
	irdm_interrupt_del(slot);
	if (!ret)
		mesh_set_name(m, what);
out_free:
	free(r);
	return ret;
}
