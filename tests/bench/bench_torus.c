/* SPDX-License-Identifier: MIT */
/*
 * The precompute of tests/test_static_torus.c's torus (support/torus.h:
 * about 2,500 touchable nodes, floating, modal:300, the clustered static
 * correction) with one BLAS thread: its wall time and its CPU time (user +
 * system of the child) beside the 60 s budget, its peak memory and image
 * size.  Prints; never fails on time (a shared machine's load moves it:
 * 37.8 s of CPU quiet, 44 to 51 s under .ci/run); fails if the precompute
 * does.
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

#define OFF "out/bench/torus.off"
#define SCENE "out/bench/torus.scene"
#define IMG "out/bench/torus.img"
#define LOG "out/bench/torus.log"
#define BUDGET_S 60.0

static double cpu_s(const struct rusage *ru)
{
	return (double)ru->ru_utime.tv_sec + 1e-6 * (double)ru->ru_utime.tv_usec +
	       (double)ru->ru_stime.tv_sec + 1e-6 * (double)ru->ru_stime.tv_usec;
}

static int write_scene(void)
{
	FILE *f = fopen(SCENE, "w");

	if (!f)
		return -1;
	fprintf(f, "name = torus\nmesh = %s\nmesh_scale = %g\nfloating = yes\ntarget_nodes = %d\n"
		   "static_correction_cluster = %s\nstatic_correction_tol = %s\n",
		OFF, TORUS_SCALE, TORUS_NODES, TORUS_CLUSTER, TORUS_CLUSTER_TOL);
	return fclose(f) ? -1 : 0;
}

int main(void)
{
	const char *irdm = getenv("IRDM") ? getenv("IRDM") : "build/irdm";
	struct rusage ru;
	struct stat st;
	char cmd[1024];

	if ((mkdir("out", 0777) && errno != EEXIST) || (mkdir("out/bench", 0777) && errno != EEXIST) ||
	    torus_write_off(OFF, TORUS_NU, TORUS_NV) || write_scene()) {
		fprintf(stderr, "torus cannot write %s or %s: %s\n", OFF, SCENE, strerror(errno));
		return 1;
	}
	/* one BLAS thread: the CPU time is then the time on one core; with
	 * two, the second spins whenever the other core is busy */
	snprintf(cmd, sizeof(cmd), "OPENBLAS_NUM_THREADS=1 %s precompute --scene %s -o %s > %s 2>&1",
		 irdm, SCENE, IMG, LOG);
	printf("torus %s\n", cmd);
	fflush(stdout);
	double t0 = bench_now_us();
	int rc = system(cmd);
	double secs = (bench_now_us() - t0) * 1e-6;
	if (rc) {
		fprintf(stderr, "torus the precompute failed (status %d); its log: %s\n", rc, LOG);
		return 1;
	}
	if (getrusage(RUSAGE_CHILDREN, &ru) || stat(IMG, &st)) {
		fprintf(stderr, "torus %s: %s\n", IMG, strerror(errno));
		return 1;
	}
	printf("torus precompute %.1f s wall, %.1f s CPU (budget %.0f s), peak %.0f MiB, image %.1f MB\n",
	       secs, cpu_s(&ru), BUDGET_S, (double)ru.ru_maxrss / 1024, (double)st.st_size / 1e6);
	return 0;
}
