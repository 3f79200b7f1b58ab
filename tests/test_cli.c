/* SPDX-License-Identifier: MIT */
/*
 * The irdm command line, end to end: bad input of every kind gives a
 * non-zero exit, one line on stderr that names the thing and the reason,
 * and leaves no output behind (an existing image stays as it was); the
 * happy paths agree with independent computations.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "modal/response.h"
#include "image/image_response.h"
#include "support/engine_fixture.h"
#include "support/image_fixture.h"
#include "support/model_fixture.h"
#include "support/test_files.h"
#include "irdm/posix/image_map.h"

extern char **environ;

static char dir[256];
static char out_text[65536], err_text[8192];

static const char *irdm_path(void)
{
	const char *p = getenv("IRDM");

	return p ? p : "build/irdm";
}

/* Address-space cap (bytes) for the children run() starts; 0: none. */
static rlim_t child_as_limit;

/* In the child: stdout/stderr to files, the address-space cap, exec. */
static void exec_child(const char **argv, const char *out_path, const char *err_path)
{
	int fo = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	int fe = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	struct rlimit rl = { child_as_limit, child_as_limit };

	if (fo < 0 || fe < 0 || dup2(fo, 1) < 0 || dup2(fe, 2) < 0)
		_exit(126);
	if (child_as_limit && setrlimit(RLIMIT_AS, &rl))
		_exit(126);
	execve(argv[0], (char *const *)argv, environ);
	_exit(127);
}

/* Run irdm with a NULL-terminated argument list; capture stdout/stderr. */
static bool has_arg(const char *const *argv, int n, const char *arg)
{
	for (int i = 0; i < n; i++)
		if (!strcmp(argv[i], arg))
			return true;
	return false;
}

static int run(const char *first, ...)
{
	const char *argv[64];
	char out_path[300], err_path[300];
	va_list ap;
	int n = 0, status = 0;
	pid_t pid;

	argv[n++] = irdm_path();
	va_start(ap, first);
	for (const char *a = first; a && n < 61; a = va_arg(ap, const char *))
		argv[n++] = a;
	va_end(ap);
	/* the accuracy measurement (a dense eigensolve per image) only where a
	 * test asks for it by setting max_error */
	if (!strcmp(first, "precompute") && !has_arg(argv, n, "--max_error")) {
		argv[n++] = "--max_error";
		argv[n++] = "none";
	}
	argv[n] = NULL;
	snprintf(out_path, sizeof(out_path), "%s/stdout", dir);
	snprintf(err_path, sizeof(err_path), "%s/stderr", dir);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		exec_child(argv, out_path, err_path);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	tf_read_text(out_path, out_text, sizeof(out_text));
	tf_read_text(err_path, err_text, sizeof(err_text));
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static char *path_in_dir(const char *name)
{
	static char buf[16][300];
	static int k;

	k = (k + 1) % 16;
	snprintf(buf[k], sizeof(buf[k]), "%s/%s", dir, name);
	return buf[k];
}

static bool exists(const char *p)
{
	struct stat st;

	return stat(p, &st) == 0;
}

/*
 * A failure: non-zero exit, and the error is one line starting "irdm" that
 * contains `needle` (progress lines may come before it).
 */
static void expect_failure(int rc, const char *needle)
{
	size_t len = strlen(err_text);
	const char *last;

	while (len && err_text[len - 1] == '\n')
		len--;
	last = err_text + len;
	while (last > err_text && last[-1] != '\n')
		last--;
	if (rc == 0 || strncmp(last, "irdm", 4) || !strstr(last, needle))
		fail_msg("expected a one-line error with '%s' (exit %d): %s", needle, rc, err_text);
	assert_true(rc > 0 && rc < 128); /* an error exit, not a crash */
}

static int setup(void **state)
{
	(void)state;
	return tf_tmpdir(dir, sizeof(dir), "cli");
}

static int teardown(void **state)
{
	(void)state;
	return tf_rmdir(dir);
}

#define SMALL "--mesh", "box:0.1,0.1,0.2", "--resolution", "2,2,4", "--representation", "modal:10"

static void test_bad_scene_values(void **state)
{
	const char *img = path_in_dir("bad.img");

	(void)state;
	/* ranges are checked as the key is read: the message names key, value and bound */
	expect_failure(run("precompute", SMALL, "--poisson", "0.5", "-o", img, NULL),
		       "--poisson 0.5: must be < 0.5");
	expect_failure(run("precompute", SMALL, "--poisson", "0.7", "-o", img, NULL), "poisson");
	expect_failure(run("precompute", SMALL, "--young", "0", "-o", img, NULL),
		       "--young 0: must be > 0 Pa");
	expect_failure(run("precompute", SMALL, "--young", "-5", "-o", img, NULL), "young");
	expect_failure(run("precompute", SMALL, "--density", "nan", "-o", img, NULL), "density");
	expect_failure(run("precompute", SMALL, "--dt", "0", "-o", img, NULL), "--dt");
	expect_failure(run("precompute", SMALL, "--dt", "-0.001", "-o", img, NULL), "--dt");
	expect_failure(run("precompute", SMALL, "--fixed", "z<=-1", "-o", img, NULL), "selects no node");
	expect_failure(run("precompute", SMALL, "--fixed", "none", "-o", img, NULL), "fixed");
	expect_failure(run("precompute", SMALL, "--floating", "yes", "--fixed", "z<=0", "-o", img, NULL),
		       "floating");
	expect_failure(run("precompute", SMALL, "--colour", "red", "-o", img, NULL), "unknown scene key");
	expect_failure(run("precompute", SMALL, "--representation", "fir:0", "-o", img, NULL),
		       "representation");
	expect_failure(run("precompute", SMALL, "--fir_tail", "window:10", "-o", img, NULL),
		       "fir_tail = window:10 windows an FIR's tail");
	expect_failure(run("precompute", SMALL, "--fir_tail", "window:0", "-o", img, NULL),
		       "fir_tail");
	expect_failure(run("precompute", SMALL, "--fir_tail", "hann:5", "-o", img, NULL),
		       "expected window, window:L or none");
	/* the clustered static correction: its range and what it combines with */
	expect_failure(run("precompute", SMALL, "--static_correction_cluster", "3", "-o", img, NULL),
		       "static_correction_cluster = 3 is below 4 nodes per cluster");
	expect_failure(run("precompute", SMALL, "--static_correction_cluster", "1025", "-o", img,
			   NULL),
		       "static_correction_cluster");
	expect_failure(run("precompute", SMALL, "--static_correction_cluster", "8", "--exact_head",
			   "4", "-o", img, NULL),
		       "exact_head = 4 with static_correction_cluster = 8");
	expect_failure(run("precompute", SMALL, "--static_correction_cluster", "8",
			   "--representation", "fir:10", "-o", img, NULL),
		       "static_correction_cluster = 8 clusters a modal image's static correction");
	expect_failure(run("precompute", SMALL, "--static_correction_cluster", "8",
			   "--static_correction", "no", "-o", img, NULL),
		       "static_correction_cluster = 8 clusters a modal image's static correction");
	expect_failure(run("precompute", SMALL, "--touch", "z>=5", "-o", img, NULL), "selects no");
	expect_failure(run("precompute", SMALL, NULL), "-o");
	expect_failure(run("precompute", "--scene", path_in_dir("missing.scene"), "-o", img, NULL),
		       "missing.scene");
	tf_write_text(path_in_dir("bad.scene"), "young = 2000\nthis line has no equals sign\n");
	expect_failure(run("precompute", "--scene", path_in_dir("bad.scene"), "-o", img, NULL),
		       "bad.scene:2");
	tf_write_text(path_in_dir("bad.scene"), "# material\nyoung = 2000\npoisson = 0.6\n");
	expect_failure(run("precompute", "--scene", path_in_dir("bad.scene"), "-o", img, NULL),
		       "bad.scene:3: poisson = 0.6: must be < 0.5");
	tf_write_text(path_in_dir("bad.scene"), "mass = heavy\n");
	expect_failure(run("precompute", "--scene", path_in_dir("bad.scene"), "-o", img, NULL),
		       "bad.scene:1: mass = heavy: expected lumped | consistent");
	/* a key twice is refused, naming both lines (not: the last one wins) */
	tf_write_text(path_in_dir("bad.scene"), "young = 2000\npoisson = 0.3\nyoung = 3000\n");
	expect_failure(run("precompute", "--scene", path_in_dir("bad.scene"), "-o", img, NULL),
		       "bad.scene:3: young");
	assert_non_null(strstr(err_text, "line 1"));
	/* a display region that holds no surface node is refused, not ignored */
	expect_failure(run("precompute", SMALL, "--display", "z>=5", "-o", img, NULL),
		       "'display = z>=5' selects no surface node");
	/* a sample period no device could run */
	expect_failure(run("precompute", SMALL, "--dt", "1e-300", "-o", img, NULL),
		       "--dt 1e-300: must be >= 1e-06 s");
	assert_false(exists(img));
}

/* An image `image verify --require-stable` would reject is not written
 * unless the scene asks for it by name. */
static void test_uncertified_refused(void **state)
{
	const char *img = path_in_dir("uncert.img");

	(void)state;
	unlink(img);
	expect_failure(run("precompute", SMALL, "--representation", "fir:20", "--modes", "all", "--touch", "z>=0.2",
			   "--fir_tail", "none", "-o", img, NULL),
		       "scene cuboid: fir:20 is not certified stable: spectral radius 1.");
	assert_non_null(strstr(err_text, "try fir_tail = window (the default)"));
	assert_non_null(strstr(err_text, "uncertified = yes"));
	assert_int_not_equal(access(img, F_OK), 0);
	assert_int_equal(run("precompute", SMALL, "--representation", "fir:20", "--modes", "all", "--touch", "z>=0.2",
			     "--modes", "all", "--fir_tail", "none", "--uncertified", "yes", "-o", img, NULL),
			 0);
	expect_failure(run("image", "verify", "--require-stable", img, NULL),
		       "columns have an unstable force recursion");
}

static void test_bad_meshes(void **state)
{
	const char *img = path_in_dir("mesh.img");
	static const char nodes[] =
		"5 3 0 0\n1 0 0 0\n2 0.1 0 0\n3 0 0.1 0\n4 0 0 0.1\n5 0.1 0.1 0.1\n";

	(void)state;
	/* element 2 lists its nodes in the inverted order */
	tf_write_text(path_in_dir("inv.node"), nodes);
	tf_write_text(path_in_dir("inv.ele"), "2 4 0\n1 1 2 3 4\n2 5 2 3 4\n");
	expect_failure(run("precompute", "--mesh", path_in_dir("inv.node"), "--fixed", "z<=0",
			   "-o", img, NULL),
		       "element 2");
	/* zero volume: four coplanar nodes */
	tf_write_text(path_in_dir("flat.node"), "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n");
	tf_write_text(path_in_dir("flat.ele"), "1 4 0\n1 1 2 3 4\n");
	expect_failure(run("precompute", "--mesh", path_in_dir("flat.ele"), "-o", img, NULL), "element 1");
	/* NaN coordinate */
	tf_write_text(path_in_dir("nan.node"), "4 3 0 0\n1 0 0 0\n2 nan 0 0\n3 0 1 0\n4 0 0 1\n");
	tf_write_text(path_in_dir("nan.ele"), "1 4 0\n1 1 2 3 4\n");
	expect_failure(run("precompute", "--mesh", path_in_dir("nan.node"), "-o", img, NULL), "node 2");
	/* node 5 is in no element */
	tf_write_text(path_in_dir("unref.node"), nodes);
	tf_write_text(path_in_dir("unref.ele"), "1 4 0\n1 1 2 3 4\n");
	expect_failure(run("precompute", "--mesh", path_in_dir("unref.node"), "-o", img, NULL), "node 5");
	expect_failure(run("precompute", "--mesh", path_in_dir("nothing.msh"), "-o", img, NULL),
		       "nothing.msh");
	expect_failure(run("precompute", "--mesh", path_in_dir("x.xyz"), "-o", img, NULL), "x.xyz");
	assert_false(exists(img));
}

/* A failing run over an existing image leaves it byte for byte. */
/*
 * A real read failure: a directory named like a mesh opens with fopen() and
 * then fails in fread() with EISDIR.  It must surface as EIO, by name.
 */
static void test_read_failure_is_eio(void **state)
{
	const char *img = path_in_dir("eio.img");
	const char *mesh = path_in_dir("dir.node");

	(void)state;
	assert_int_equal(mkdir(mesh, 0755), 0);
	expect_failure(run("precompute", "--mesh", mesh, "--floating", "yes", "-o", img, NULL),
		       "EIO");
	assert_non_null(strstr(err_text, "dir.node"));
	assert_false(exists(img));
	rmdir(mesh);
}

#if defined(__SANITIZE_ADDRESS__)
#define BUILT_WITH_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BUILT_WITH_ASAN 1
#endif
#endif

/*
 * Memory the precompute cannot have.  The built-in cuboid with the dense
 * eigensolver (every mode: auto at its default max_error) needs about
 * 1.0 GiB (the 9504 x 9504 vectors, and two matrices of a quarter of that
 * size for each of the four blocks its symmetries split it into).  Under
 * a 300 MB
 * address-space cap the precompute refuses it before allocating, by name:
 * the GiB it needs, the cap and where the cap comes from, and what
 * builds without every mode (auto's lowest modes: not with eigensolver =
 * dense).  AddressSanitizer reserves terabytes of shadow memory,
 * so RLIMIT_AS cannot work under it; there the same cap comes from ASan's
 * allocator instead (max_allocation_size_mb with allocator_may_return_null:
 * malloc() returns NULL, as libc would), which the budget does not see, so
 * that build checks a real allocation failure: ENOMEM, "out of memory".
 * Either way no image is left behind.  The test assumes irdm is built
 * like this test (make test / make san do).
 */
static void test_alloc_failure_is_enomem(void **state)
{
	const char *img = path_in_dir("enomem.img");
	const char *old = getenv("ASAN_OPTIONS");
	char *saved = old ? strdup(old) : NULL;
	int rc;

	(void)state;
#ifdef BUILT_WITH_ASAN
	print_message("ASan build: allocation cap by ASAN_OPTIONS, not RLIMIT_AS\n");
	setenv("ASAN_OPTIONS", "allocator_may_return_null=1:max_allocation_size_mb=300", 1);
#else
	child_as_limit = (rlim_t)300 << 20;
#endif
	rc = run("precompute", "-q", "--mesh", "cuboid", "--eigensolver", "dense", "--max_error", "1e-3",
		 "-o", img, NULL);
	child_as_limit = 0;
	if (saved)
		setenv("ASAN_OPTIONS", saved, 1);
	else
		unsetenv("ASAN_OPTIONS");
	free(saved);
	expect_failure(rc, "ENOMEM");
#ifdef BUILT_WITH_ASAN
	assert_non_null(strstr(err_text, "out of memory"));
#else
	assert_non_null(strstr(err_text, "the dense eigensolve of 9504 modes of 9504 free DoFs (split by symmetry) needs 1.01 GiB, more than the 0.293 GiB of ulimit -v"));
	assert_non_null(strstr(err_text, "representation = auto chooses from the lowest modes of a Lanczos solve instead on a grounded object with lumped mass, contacts = 1, eigensolver = auto"));
	assert_non_null(strstr(err_text, "in one process; or a coarser mesh"));
#endif
	assert_false(exists(img));
}

static void test_failure_keeps_existing_image(void **state)
{
	const char *img = path_in_dir("keep.img");
	char before[65536], after[65536];

	(void)state;
	assert_int_equal(run("precompute", "-q", SMALL, "-o", img, NULL), 0);
	tf_read_text(img, before, sizeof(before));
	struct stat st0, st1;
	assert_int_equal(stat(img, &st0), 0);
	expect_failure(run("precompute", SMALL, "--young", "-1", "-o", img, NULL), "young");
	assert_int_equal(stat(img, &st1), 0);
	tf_read_text(img, after, sizeof(after));
	assert_int_equal(st0.st_size, st1.st_size);
	assert_memory_equal(before, after, sizeof(before) < (size_t)st0.st_size ? sizeof(before) : (size_t)st0.st_size);
	assert_int_equal(run("image", "verify", img, NULL), 0);
}

static void corrupt(const char *src, const char *dst, long at, int truncate_to)
{
	FILE *in = fopen(src, "rb"), *out = fopen(dst, "wb");
	int c;
	long i = 0;

	assert_non_null(in);
	assert_non_null(out);
	while ((c = fgetc(in)) != EOF) {
		if (truncate_to >= 0 && i >= truncate_to)
			break;
		fputc(i == at ? c ^ 0x40 : c, out);
		i++;
	}
	fclose(in);
	fclose(out);
}

static void test_bad_images(void **state)
{
	const char *img = path_in_dir("good.img"), *bad = path_in_dir("bad.img");

	(void)state;
	assert_int_equal(run("precompute", "-q", SMALL, "-o", img, NULL), 0);
	corrupt(img, bad, -1, 100);
	expect_failure(run("image", "verify", bad, NULL), "truncated");
	corrupt(img, bad, 0, -1);
	expect_failure(run("image", "verify", bad, NULL), "magic");
	corrupt(img, bad, 2000, -1);
	expect_failure(run("image", "info", bad, NULL), "checksum");
	tf_write_text(bad, "");
	expect_failure(run("image", "verify", bad, NULL), "bad.img");
	expect_failure(run("image", "verify", path_in_dir("none.img"), NULL), "none.img");
	expect_failure(run("image", "export", img, "--column", "99999", NULL), "99999");
	expect_failure(run("image", "export", img, "--column", "x", NULL), "--column");
	expect_failure(run("image", "export", img, "--column", "0", "--samples", "0", NULL), "--samples");
}

/*
 * export writes R[s] of the image; compare with the modal closed form
 * computed here from the same scene's model (f64 storage, so only
 * rounding separates the two).
 */
static void test_export_matches_library(void **state)
{
	const char *img = path_in_dir("exp.img"), *csv = path_in_dir("exp.csv");
	struct irdm_model m;
	char node[32];

	(void)state;
	assert_int_equal(run("precompute", "-q", "--mesh", "box:0.1,0.1,0.2", "--resolution", "2,2,4",
			     "--tets_per_hex", "6", "--representation", "modal:all", "--precision", "f64",
			     "--dt", "0.002", "-o", img, NULL),
			 0);
	fixture_model(&m, 0.1, 0.1, 0.2, 2, 2, 4, 6, 0.49, false, 0, IRDM_EIG_AUTO, 0.002);
	const double top[3] = { 0.05, 0.05, 0.2 };
	uint32_t c = fixture_nearest_node(&m.mesh, top);
	snprintf(node, sizeof(node), "%u", c);
	assert_int_equal(run("image", "export", img, "--column", node, "--samples", "50", "-o", csv, NULL), 0);
	int64_t cd[3];
	for (int a = 0; a < 3; a++)
		cd[a] = fixture_free_dof(&m, c, a);
	struct irdm_mode *zoh = malloc(m.modes.n_modes * sizeof(*zoh));
	double fir[50 * 9];
	irdm_modes_discretise(&m.modes, &m.damping, 0.002, zoh);
	irdm_fir_from_modes(&m.modes, zoh, cd, 1, cd, 1, 50, NULL, fir, NULL, NULL);
	char text[65536];
	tf_read_text(csv, text, sizeof(text));
	char want[64];
	snprintf(want, sizeof(want), "s,t_s,n%u_ux_fx,n%u_ux_fy", c, c);
	assert_non_null(strstr(text, want));
	char *line = strchr(text, '\n') + 1;
	double scale = 0, diff = 0;
	for (int s = 0; s < 50; s++) {
		double v[11];
		char *p = line;
		for (int k = 0; k < 11; k++) {
			v[k] = strtod(p, &p);
			p++;
		}
		assert_true(fabs(v[1] - (s + 1) * 0.002) < 1e-12);
		for (int e = 0; e < 9; e++) {
			diff = fmax(diff, fabs(v[2 + e] - fir[9 * s + e]));
			scale = fmax(scale, fabs(fir[9 * s + e]));
		}
		line = strchr(line, '\n') + 1;
	}
	assert_true(diff <= 1e-7 * scale);
	free(zoh);
	irdm_model_free(&m);
}

/* max |a - b| / max |a| over the numbers of two CSV texts of one shape */
/* image info on STATIC_CORR_CLUSTERS: the counts of the fixture's section
 * (3 clusters over 5 columns: 3 self pairs, 3 cross pairs of the rank
 * asked) and its size as built, in its line and in the section list. */
static void test_info_clusters(void **state)
{
	static const uint32_t ranks[] = { 2, IRDM_CORR_PAIR_DENSE };
	char want[200], err[256];
	struct img_fixture fx;
	const char *img = path_in_dir("clusters.img");

	(void)state;
	for (size_t k = 0; k < 2; k++) {
		bool dense = ranks[k] == IRDM_CORR_PAIR_DENSE;
		assert_int_equal(img_fixture_modal(&fx, IRDM_ELEM_F32, 6, 5, 2, IRDM_META_STATIC_CORR), 0);
		assert_int_equal(img_fixture_clusters(&fx, 3, ranks[k], NULL), 0);
		assert_int_equal(img_fixture_write(&fx, img, err, sizeof(err)), 0);
		assert_int_equal(run("image", "info", img, NULL), 0);
		snprintf(want, sizeof(want),
			 "\nclusters      3 over 5 columns, pairs %d dense, %d low-rank (largest rank %u), %llu bytes\n",
			 dense ? 6 : 3, dense ? 0 : 3, dense ? 0 : ranks[k],
			 (unsigned long long)fx.clusters_bytes);
		if (!strstr(out_text, want))
			fail_msg("no '%s' in: %s", want + 1, out_text);
		snprintf(want, sizeof(want), "  STATIC_CORR_CLUSTERS bytes offset");
		assert_non_null(strstr(out_text, want));
		img_fixture_free(&fx);
	}
}

static double csv_max_diff(const char *a, const char *b)
{
	double diff = 0, scale = 0;

	a = strchr(a, '\n');
	b = strchr(b, '\n');
	assert_non_null(a);
	assert_non_null(b);
	while (*a && *b) {
		char *ea, *eb;
		double x = strtod(a + 1, &ea), y = strtod(b + 1, &eb);
		assert_true(ea > a + 1 && eb > b + 1);
		diff = fmax(diff, fabs(x - y));
		scale = fmax(scale, fabs(x));
		a = ea;
		b = eb;
		if (*a == '\n' && !a[1])
			break;
	}
	return diff / scale;
}

/* Time-domain work split over parts and merged = the same run in one go. */
static void test_time_domain_split_and_merge(void **state)
{
	const char *whole = path_in_dir("whole.img"), *merged = path_in_dir("merged.img");
	const char *p1 = path_in_dir("p1.part"), *p2 = path_in_dir("p2.part");
	char parts[700], both[700], range2[32], whole_csv[65536], merged_csv[65536];
#define TD SMALL, "--representation", "fir:20", "--method", "time-domain", "--touch", "z>=0.2", \
	   "--display", "touch", "--substeps", "4", "--dt", "0.002", "--uncertified", "yes", "--fir_tail", "none"

	(void)state;
	assert_int_equal(run("precompute", "-q", TD, "--count-inputs", NULL), 0);
	int n = atoi(out_text);
	assert_true(n > 3);
	snprintf(range2, sizeof(range2), "3:%d", n);
	assert_int_equal(run("precompute", "-q", TD, "-o", whole, NULL), 0);
	assert_int_equal(run("precompute", "-q", TD, "--part", "0:3", "-o", p1, NULL), 0);
	assert_int_equal(run("precompute", "-q", TD, "--part", range2, "-o", p2, NULL), 0);
	snprintf(parts, sizeof(parts), "%s,%s", p2, p1);
	assert_int_equal(run("precompute", "-q", TD, "--merge", parts, "-o", merged, NULL), 0);
	if (run("image", "verify", merged, NULL))
		fail_msg("verify merged: %s", err_text);
	assert_int_equal(run("image", "export", whole, "--column", "40", NULL), 0);
	memcpy(whole_csv, out_text, sizeof(whole_csv));
	assert_int_equal(run("image", "export", merged, "--column", "40", NULL), 0);
	memcpy(merged_csv, out_text, sizeof(merged_csv));
	/* equal to rounding: the solver blocks right-hand sides by share size */
	assert_true(csv_max_diff(whole_csv, merged_csv) <= 1e-12);
	/* a missing share, a repeated share, a part of another scene */
	expect_failure(run("precompute", TD, "--merge", p1, "-o", merged, NULL), "in no part");
	snprintf(both, sizeof(both), "%s,%s,%s", p1, p2, p1);
	expect_failure(run("precompute", TD, "--merge", both, "-o", merged, NULL), "earlier part");
	expect_failure(run("precompute", TD, "--young", "3000", "--merge", parts, "-o", merged, NULL),
		       "different scene");
	tf_write_text(p1, "IRDMPART garbage");
	expect_failure(run("precompute", TD, "--merge", parts, "-o", merged, NULL), "p1.part");
#undef TD
}

/*
 * replay: a 1 cm step at a node; the forces written equal the brute-force
 * convolution of the image's responses; bad trajectories fail cleanly.
 */
static void test_replay(void **state)
{
	const char *img = path_in_dir("rp.img"), *traj = path_in_dir("rp.csv"), *out = path_in_dir("rpf.csv");
	char text[8192 * 8], *p = text;
	static double target[300 * 3], ref[300 * 3];
	struct irdm_image im;
	char err[256];

	(void)state;
	assert_int_equal(run("precompute", "-q", SMALL, "--representation", "modal:all", "--precision", "f64",
			     "--touch", "z>=0.2", "-o", img, NULL),
			 0);
	p += sprintf(p, "t,ux,uy,uz\n");
	for (int t = 0; t < 300; t++) {
		target[3 * t + 2] = -0.01;
		p += sprintf(p, "%.3f,0,0,-0.01\n", t * 0.001);
	}
	tf_write_text(traj, text);
	assert_int_equal(run("replay", "--image", img, "--contact", "40", "--displacement", traj, "-o", out, NULL), 0);
	assert_int_equal(irdm_image_map(img, 0, &im, err, sizeof(err)), 0);
	struct irdm_engine_config cfg;
	irdm_engine_config_default(&cfg);
	struct irdm_contact_site site;
	struct irdm_session *ses = efx_session(&im, &cfg);
	struct irdm_engine *e = ses->eng;
	assert_int_equal(irdm_engine_site_node(e, (uint32_t)irdm_image_node_of(&im, 40), &site), 0);
	irdm_session_close(ses);
	efx_reference(&im, &site, 1, 300, target, ref);
	tf_read_text(out, text, sizeof(text));
	assert_non_null(strstr(text, "t,c1_fx,c1_fy,c1_fz"));
	p = strchr(text, '\n') + 1;
	double got[300 * 3];
	for (int t = 0; t < 300; t++) {
		strtod(p, &p);
		for (int a = 0; a < 3; a++)
			got[3 * t + a] = strtod(p + 1, &p);
		p++;
	}
	assert_true(efx_rel_rms(got, ref, 300 * 3) < 1e-9);
	/* a triangle of the touchable top (every vertex a column), and one
	 * with none (the fixed bottom's) for the sites below */
	long top_tri = -1, fixed_tri = -1;
	for (uint32_t t = 0; t < im.meta->n_tris; t++) {
		int cols = 0;
		for (int k = 0; k < 3; k++)
			for (uint32_t c = 0; c < im.meta->n_cols; c++)
				cols += im.columns[c] == im.tris[3 * t + (uint32_t)k];
		if (cols == 3 && top_tri < 0)
			top_tri = t;
		if (cols == 0 && fixed_tri < 0)
			fixed_tri = t;
	}
	assert_true(top_tri >= 0 && fixed_tri >= 0);
	irdm_image_unmap(&im);
	remove(out);
	tf_write_text(traj, "t,ux,uy,uz\n0,0,0,0\n0.002,0,0,0\n");
	expect_failure(run("replay", "--image", img, "--contact", "40", "--displacement", traj, "-o", out, NULL),
		       "one row per sample");
	tf_write_text(traj, "0,0,0\n");
	expect_failure(run("replay", "--image", img, "--contact", "40", "--displacement", traj, "-o", out, NULL),
		       "numeric columns");
	tf_write_text(traj, "0,0,0,1e9\n");
	expect_failure(run("replay", "--image", img, "--contact", "40", "--displacement", traj, "-o", out, NULL),
		       "out of range");
	expect_failure(run("replay", "--image", img, "--contact", "0", "--displacement", traj, "-o", out, NULL),
		       "not a touchable node");
	expect_failure(run("replay", "--image", img, "--contact", "1,2", "--displacement", traj, "-o", out, NULL),
		       "--contact");
	expect_failure(run("replay", "--image", img, "--contact", "40", "--displacement", path_in_dir("no.csv"),
			   "-o", out, NULL),
		       "no.csv");
	expect_failure(run("replay", "--image", img, "--contact", "40", NULL), "needs");
	/* --sites: each row's site checked, named by file and row */
	{
		const char *sites = path_in_dir("rps.csv");

		tf_write_text(traj, "t,ux,uy,uz\n0,0,0,-0.001\n0.001,nan,nan,nan\n");
		tf_write_text(sites, "t,tri,b0,b1,b2\n0,99999,0.2,0.3,0.5\n0.001,-1,0,0,0\n");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "rps.csv: row 1, contact 1: triangle is not -1");
		tf_write_text(sites, "t,tri,b0,b1,b2\n0,0,0.2,0.3,0.6\n0.001,-1,0,0,0\n");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "row 1, contact 1: barycentrics must sum to 1");
		tf_write_text(sites, "t,tri,b0,b1,b2\n0,0,-0.2,0.7,0.5\n0.001,-1,0,0,0\n");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "finite and >= 0");
		tf_write_text(sites, "t,tri,b0,b1,b2\n0,-1,0,0,0\n0.001,-1,0,0,0\n");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "row 1: contact 1 has a displacement but no site");
		tf_write_text(sites, "t,tri,b0,b1,b2\n0,0,0.2,0.3,0.5\n");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "1 rows, but");
		expect_failure(run("replay", "--image", img, "--sites", sites, "--contact", "40",
				   "--displacement", traj, "-o", out, NULL),
			       "exclude each other");
		/* pushed rigidly into a triangle that cannot move: refused,
		 * saying why (the regularised solve gave 1e7 N for 1 mm before) */
		snprintf(text, sizeof(text), "t,tri,b0,b1,b2\n0,%ld,0.2,0.3,0.5\n0.001,-1,0,0,0\n",
			 fixed_tri);
		tf_write_text(sites, text);
		expect_failure(run("replay", "--image", img, "--sites", sites, "--displacement", traj,
				   "-o", out, NULL),
			       "contact targets contradict each other");
		snprintf(text, sizeof(text), "t,tri,b0,b1,b2\n0,%ld,0.2,0.3,0.5\n0.001,-1,0,0,0\n",
			 top_tri);
		tf_write_text(sites, text);
		assert_int_equal(run("replay", "--image", img, "--sites", sites, "--displacement",
				     traj, "-o", out, NULL),
				 0);
		remove(out);
	}
	assert_false(exists(out));
}

static void test_help_for_every_command(void **state)
{
	(void)state;
	assert_int_equal(run("--help", NULL), 0);
	assert_non_null(strstr(out_text, "precompute"));
	assert_int_equal(run("replay", "--help", NULL), 0);
	assert_non_null(strstr(out_text, "--displacement"));
	assert_int_equal(run("precompute", "--help", NULL), 0);
	assert_non_null(strstr(out_text, "representation"));
	const char *sub[] = { "info", "verify", "export" };
	for (int i = 0; i < 3; i++) {
		assert_int_equal(run("image", sub[i], "--help", NULL), 0);
		assert_non_null(strstr(out_text, "export IMAGE --column"));
	}
	/* generated from the tables: every key, its syntax and its range */
	assert_int_equal(run("image", "export", "--help", NULL), 0);
	assert_non_null(strstr(out_text, "1 <= samples <= 10000000"));
	assert_int_equal(run("precompute", "--help", NULL), 0);
	assert_non_null(strstr(out_text, "-1 < poisson < 0.5"));
	assert_non_null(strstr(out_text, "--count-inputs"));
	expect_failure(run("frobnicate", NULL), "frobnicate");
}

/*
 * docs/scene-format.md is generated from the scene key table ("make docs");
 * regenerate it and compare, so that it cannot go stale.
 */
static void test_scene_docs_current(void **state)
{
	static char committed[65536];
	const char *path = getenv("IRDM_SCENE_DOC");

	(void)state;
	tf_read_text(path ? path : "docs/scene-format.md", committed, sizeof(committed));
	assert_true(strlen(committed) > 0);
	assert_int_equal(run("precompute", "--help-markdown", NULL), 0);
	if (strcmp(out_text, committed))
		fail_msg("docs/scene-format.md is not what 'irdm precompute --help-markdown' writes: run 'make docs'");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_bad_scene_values),
		cmocka_unit_test(test_uncertified_refused),
		cmocka_unit_test(test_bad_meshes),
		cmocka_unit_test(test_read_failure_is_eio),
		cmocka_unit_test(test_alloc_failure_is_enomem),
		cmocka_unit_test(test_failure_keeps_existing_image),
		cmocka_unit_test(test_bad_images),
		cmocka_unit_test(test_export_matches_library),
		cmocka_unit_test(test_info_clusters),
		cmocka_unit_test(test_time_domain_split_and_merge),
		cmocka_unit_test(test_replay),
		cmocka_unit_test(test_help_for_every_command),
		cmocka_unit_test(test_scene_docs_current),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
