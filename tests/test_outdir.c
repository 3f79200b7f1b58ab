/* SPDX-License-Identifier: MIT */
/*
 * Output directories (irdm/posix/outdir.h): each way an output could destroy a
 * user's files, tried against the module every directory-writing tool uses.
 *  - a missing DIR is created; DIR written by the same tool is replaced and
 *    its old files go;
 *  - a DIR holding a file the tool did not write, a DIR written by another
 *    tool, a regular file or a symbolic link at DIR: refused, naming the
 *    path, nothing changed, nothing left beside it;
 *  - --force replaces a directory of files, never a file nor a directory
 *    holding a directory;
 *  - DIR.old and DIR.tmp (a user's) are never touched;
 *  - a DIR changed during the run is refused at the end;
 *  - a killed run's beside-directory is removed by the next run, a running
 *    one's is left.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/error.h"
#include "irdm/posix/outdir.h"
#include "support/test_files.h"

static char dir[256];

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "outdir");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

static const char *at(char *buf, const char *fmt, ...)
{
	va_list ap;
	int n;

	n = snprintf(buf, 512, "%s/", dir);
	va_start(ap, fmt);
	vsnprintf(buf + n, 512 - (size_t)n, fmt, ap);
	va_end(ap);
	return buf;
}

static bool exists(const char *path)
{
	struct stat st;

	return !lstat(path, &st);
}

/* Entries of the scratch directory whose name holds the beside-name marker. */
static unsigned beside_dirs(void)
{
	struct dirent *d;
	unsigned n = 0;
	DIR *h = opendir(dir);

	assert_non_null(h);
	while ((d = readdir(h)))
		n += strstr(d->d_name, IRDM_OUTDIR_TMP) != NULL;
	closedir(h);
	return n;
}

static void put(const char *path, const char *text)
{
	tf_write_text(path, text);
}

static void expect_text(const char *path, const char *text)
{
	char buf[256];

	tf_read_text(path, buf, sizeof(buf));
	assert_string_equal(buf, text);
}

/* One whole output of tool: the named files, each holding its name. */
static int write_out(const char *target, const char *tool, bool force, const char *const *files,
		     struct irdm_outdir *od)
{
	char path[IRDM_OUTDIR_PATH_MAX + 64];
	int rc = irdm_outdir_begin(od, target, tool, force);

	if (rc)
		return rc;
	for (const char *const *f = files; *f; f++) {
		snprintf(path, sizeof(path), "%s/%s", od->tmp, *f);
		put(path, *f);
	}
	return irdm_outdir_commit(od);
}

static void expect_refused(int rc, const struct irdm_outdir *od, const char *needle)
{
	if (rc != IRDM_EEXIST || !strstr(od->why, needle))
		fail_msg("expected EEXIST naming '%s'; got %d: %s", needle, rc, od->why);
	assert_int_equal(beside_dirs(), 0);
}

static void test_fresh_then_replaced(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;

	(void)state;
	at(out, "fresh");
	assert_int_equal(write_out(out, "tool-a", false, (const char *const[]){ "a", "b", NULL },
				   &od),
			 0);
	expect_text(at(p, "fresh/a"), "a");
	assert_true(exists(at(p, "fresh/%s", IRDM_OUTDIR_MARKER)));
	/* the same tool again: replaced whole, b (not written this time) gone */
	assert_int_equal(write_out(out, "tool-a", false, (const char *const[]){ "a", "c", NULL },
				   &od),
			 0);
	expect_text(at(p, "fresh/c"), "c");
	assert_false(exists(at(p, "fresh/b")));
	assert_int_equal(beside_dirs(), 0);
	/* an empty directory (mkdir by the user) holds nothing to lose */
	assert_int_equal(mkdir(at(p, "empty"), 0777), 0);
	assert_int_equal(write_out(p, "tool-a", false, (const char *const[]){ "a", NULL }, &od), 0);
	expect_text(at(p, "empty/a"), "a");
}

static void test_foreign_directory(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;
	int rc;

	(void)state;
	at(out, "user");
	assert_int_equal(mkdir(out, 0777), 0);
	put(at(p, "user/thesis.tex"), "mine");
	rc = write_out(out, "tool-a", false, (const char *const[]){ "a", NULL }, &od);
	expect_refused(rc, &od, "user/thesis.tex: not written by tool-a");
	expect_text(at(p, "user/thesis.tex"), "mine");
	/* a stray file in the tool's own output is the user's: refused too */
	at(out, "mixed");
	assert_int_equal(write_out(out, "tool-a", false, (const char *const[]){ "a", NULL }, &od),
			 0);
	put(at(p, "mixed/notes.txt"), "mine");
	rc = write_out(out, "tool-a", false, (const char *const[]){ "a", NULL }, &od);
	expect_refused(rc, &od, "mixed/notes.txt: not written by tool-a");
	expect_text(at(p, "mixed/notes.txt"), "mine");
	/* another tool's output is not this tool's to replace */
	assert_int_equal(unlink(at(p, "mixed/notes.txt")), 0);
	rc = write_out(out, "tool-b", false, (const char *const[]){ "a", NULL }, &od);
	expect_refused(rc, &od, "not written by tool-b");
	expect_text(at(p, "mixed/a"), "a");
}

static void test_not_a_directory(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;
	int rc;

	(void)state;
	at(out, "file");
	put(out, "a file");
	for (int force = 0; force < 2; force++) {
		rc = write_out(out, "tool-a", force, (const char *const[]){ "a", NULL }, &od);
		expect_refused(rc, &od, "file: exists and is not a directory");
		expect_text(out, "a file");
	}
	assert_false(exists(at(p, "file.old")));
	/* a link to a directory: neither the link nor what it points at */
	assert_int_equal(mkdir(at(p, "elsewhere"), 0777), 0);
	put(at(p, "elsewhere/x"), "x");
	assert_int_equal(symlink(at(p, "elsewhere"), at(out, "link")), 0);
	rc = write_out(out, "tool-a", true, (const char *const[]){ "a", NULL }, &od);
	expect_refused(rc, &od, "symbolic link");
	expect_text(at(p, "elsewhere/x"), "x");
	assert_false(exists(at(p, "elsewhere/a")));
}

static void test_force(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;
	int rc;

	(void)state;
	at(out, "forced");
	assert_int_equal(mkdir(out, 0777), 0);
	put(at(p, "forced/old.txt"), "old");
	assert_int_equal(write_out(out, "tool-a", true, (const char *const[]){ "a", NULL }, &od), 0);
	expect_text(at(p, "forced/a"), "a");
	assert_false(exists(at(p, "forced/old.txt")));
	assert_int_equal(beside_dirs(), 0);
	/* the tool's own output with a file added: --force takes both */
	put(at(p, "forced/added"), "added");
	assert_int_equal(write_out(out, "tool-a", true, (const char *const[]){ "b", NULL }, &od), 0);
	assert_false(exists(at(p, "forced/added")));
	assert_false(exists(at(p, "forced/a")));
	assert_int_equal(beside_dirs(), 0);
	/* a directory inside: not even --force removes a tree */
	at(out, "tree");
	assert_int_equal(mkdir(out, 0777), 0);
	assert_int_equal(mkdir(at(p, "tree/sub"), 0777), 0);
	put(at(p, "tree/sub/deep"), "deep");
	rc = write_out(out, "tool-a", true, (const char *const[]){ "a", NULL }, &od);
	expect_refused(rc, &od, "tree/sub: a directory inside the output");
	expect_text(at(p, "tree/sub/deep"), "deep");
}

/* DIR.old and DIR.tmp are names a user may have used: never touched. */
static void test_neighbours_untouched(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;

	(void)state;
	at(out, "frames");
	assert_int_equal(mkdir(at(p, "frames.old"), 0777), 0);
	put(at(p, "frames.old/keep"), "old");
	put(at(p, "frames.tmp"), "tmp");
	for (int run = 0; run < 2; run++)
		assert_int_equal(write_out(out, "tool-a", false,
					   (const char *const[]){ "a", NULL }, &od),
				 0);
	expect_text(at(p, "frames.old/keep"), "old");
	expect_text(at(p, "frames.tmp"), "tmp");
}

/* DIR made or changed while the tool ran: refused at the end, kept. */
static void test_changed_during_run(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;

	(void)state;
	at(out, "race");
	assert_int_equal(irdm_outdir_begin(&od, out, "tool-a", false), 0);
	assert_int_equal(mkdir(out, 0777), 0);
	put(at(p, "race/made-meanwhile"), "mine");
	expect_refused(irdm_outdir_commit(&od), &od, "race/made-meanwhile");
	expect_text(at(p, "race/made-meanwhile"), "mine");
	/* abort leaves nothing */
	at(out, "aborted");
	assert_int_equal(irdm_outdir_begin(&od, out, "tool-a", false), 0);
	put(at(p, "%s/x", od.tmp + strlen(dir) + 1), "x");
	irdm_outdir_abort(&od);
	assert_int_equal(beside_dirs(), 0);
	assert_false(exists(out));
}

/* A beside-directory holding a marker whose writer is pid. */
static void fake_debris(const char *name, long pid)
{
	char p[512], text[256];

	assert_int_equal(mkdir(at(p, "%s", name), 0777), 0);
	snprintf(text, sizeof(text), "irdm-output 1\ntool tool-a\nversion 0\npid %ld\nstate writing\n",
		 pid);
	put(at(p, "%s/%s", name, IRDM_OUTDIR_MARKER), text);
	put(at(p, "%s/frame_00001.vtk", name), "half");
}

static void test_debris(void **state)
{
	char out[512], p[512];
	struct irdm_outdir od;
	pid_t dead = fork();

	(void)state;
	if (dead == 0)
		_exit(0);
	assert_true(dead > 0);
	assert_int_equal(waitpid(dead, NULL, 0), dead);
	fake_debris("series" IRDM_OUTDIR_TMP "AbC123", dead);
	fake_debris("series" IRDM_OUTDIR_TMP "live00", (long)getppid());
	/* not ours: no marker */
	assert_int_equal(mkdir(at(p, "series" IRDM_OUTDIR_TMP "user00"), 0777), 0);
	at(out, "series");
	assert_int_equal(write_out(out, "tool-a", false, (const char *const[]){ "a", NULL }, &od),
			 0);
	assert_int_equal(od.debris_removed, 1);
	assert_false(exists(at(p, "series" IRDM_OUTDIR_TMP "AbC123")));
	assert_true(exists(at(p, "series" IRDM_OUTDIR_TMP "live00/frame_00001.vtk")));
	assert_true(exists(at(p, "series" IRDM_OUTDIR_TMP "user00")));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fresh_then_replaced),
		cmocka_unit_test(test_foreign_directory),
		cmocka_unit_test(test_not_a_directory),
		cmocka_unit_test(test_force),
		cmocka_unit_test(test_neighbours_untouched),
		cmocka_unit_test(test_changed_during_run),
		cmocka_unit_test(test_debris),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
