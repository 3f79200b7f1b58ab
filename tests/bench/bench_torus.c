/* SPDX-License-Identifier: MIT */
/*
 * Two precomputes of a torus (support/torus.h: about 2,500 touchable
 * nodes, floating) with one BLAS thread, each with its wall time and CPU
 * time (user + system of the child) beside the 60 s budget, its peak
 * memory and image size beside 50 MB:
 *  - clustered: tests/test_static_torus.c's settings (max_error = none:
 *    modal:300, the clustered static correction, not measured);
 *  - default: the torus as a generator writes it (seam vertices repeated,
 *    equal to about 1e-9) with every setting at its default: welded, then
 *    representation = auto at max_error = 1e-3; the representation chosen
 *    and its measured error are printed.
 * Prints; never fails on time or size (a shared machine's load moves the
 * times: the clustered one took 37.8 s of CPU quiet, 44 to 51 s under
 * .ci/run); fails if a precompute does.
 *
 * Run from the repository root with IRDM=build/irdm; files in out/bench/.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "../support/bench_util.h"
#include "../support/torus.h"

#define BUDGET_S 60.0
#define SIZE_MB 50.0

struct torus_case {
	const char *tag, *off, *scene, *img, *log;
	int (*write_off)(const char *path, unsigned nu, unsigned nv);
	const char *keys; /* scene keys past the mesh's */
};

static const struct torus_case cases[] = {
	{ "clustered", "out/bench/torus.off", "out/bench/torus.scene", "out/bench/torus.img",
	  "out/bench/torus.log", torus_write_off,
	  "static_correction_cluster = " TORUS_CLUSTER "\nstatic_correction_tol = " TORUS_CLUSTER_TOL
	  "\nmax_error = none\n" },
	{ "default", "out/bench/torus-seams.off", "out/bench/torus-seams.scene",
	  "out/bench/torus-seams.img", "out/bench/torus-seams.log", torus_write_off_seams, "" },
};

static double cpu_s(const struct rusage *ru)
{
	return (double)ru->ru_utime.tv_sec + 1e-6 * (double)ru->ru_utime.tv_usec +
	       (double)ru->ru_stime.tv_sec + 1e-6 * (double)ru->ru_stime.tv_usec;
}

static int write_scene(const struct torus_case *c)
{
	FILE *f = fopen(c->scene, "w");

	if (!f)
		return -1;
	fprintf(f, "name = torus\nmesh = %s\nmesh_scale = %g\nfloating = yes\ntarget_nodes = %d\n%s",
		c->off, TORUS_SCALE, TORUS_NODES, c->keys);
	return fclose(f) ? -1 : 0;
}

/* The log's lines that start with one of the keys, tagged. */
static void print_log(const struct torus_case *c)
{
	static const char *const keys[] = { "welded", "representation", "modes ",
					    "image nodes", "time ", "force error" };
	char line[1024];
	FILE *f = fopen(c->log, "r");

	while (f && fgets(line, sizeof(line), f))
		for (size_t k = 0; k < sizeof(keys) / sizeof(keys[0]); k++)
			if (k == 0 ? strstr(line, keys[k]) != NULL : /* within the mesh line */
				     strncmp(line, keys[k], strlen(keys[k])) == 0)
				printf("torus %-9s %s", c->tag, line);
	if (f)
		fclose(f);
}

/* One case: the CPU time is the children's since the last case. */
static int run(const char *irdm, const struct torus_case *c, double *cpu_before)
{
	struct rusage ru;
	struct stat st;
	char cmd[1024];

	if (c->write_off(c->off, TORUS_NU, TORUS_NV) || write_scene(c)) {
		fprintf(stderr, "torus cannot write %s or %s: %s\n", c->off, c->scene, strerror(errno));
		return 1;
	}
	/* one BLAS thread: the CPU time is then the time on one core; with
	 * two, the second spins whenever the other core is busy */
	snprintf(cmd, sizeof(cmd), "OPENBLAS_NUM_THREADS=1 %s precompute --scene %s -o %s > %s 2>&1",
		 irdm, c->scene, c->img, c->log);
	printf("torus %-9s %s\n", c->tag, cmd);
	fflush(stdout);
	double t0 = bench_now_us();
	int rc = system(cmd);
	double secs = (bench_now_us() - t0) * 1e-6;
	if (rc) {
		fprintf(stderr, "torus %s: the precompute failed (status %d); its log: %s\n", c->tag, rc,
			c->log);
		return 1;
	}
	if (getrusage(RUSAGE_CHILDREN, &ru) || stat(c->img, &st)) {
		fprintf(stderr, "torus %s: %s\n", c->img, strerror(errno));
		return 1;
	}
	print_log(c);
	printf("torus %-9s precompute %.1f s wall, %.1f s CPU (budget %.0f s), peak %.0f MiB, image %.1f MB (target %.0f MB)\n",
	       c->tag, secs, cpu_s(&ru) - *cpu_before, BUDGET_S, (double)ru.ru_maxrss / 1024,
	       (double)st.st_size / 1e6, SIZE_MB);
	fflush(stdout);
	*cpu_before = cpu_s(&ru);
	return 0;
}

int main(void)
{
	const char *irdm = getenv("IRDM") ? getenv("IRDM") : "build/irdm";
	double cpu = 0;

	if ((mkdir("out", 0777) && errno != EEXIST) || (mkdir("out/bench", 0777) && errno != EEXIST)) {
		fprintf(stderr, "torus cannot make out/bench: %s\n", strerror(errno));
		return 1;
	}
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++)
		if (run(irdm, &cases[k], &cpu))
			return 1;
	return 0;
}
