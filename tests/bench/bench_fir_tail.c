/* SPDX-License-Identifier: MIT */
/*
 * What the FIR tail window costs the force tick: FIR T = 500 at 2 ms
 * (the paper's) against the same with fir_tail = window:1000 (the ring
 * T + L = 1500 long), one node held 1 cm in, rigid coupling, f32.  The
 * images are the paper's cuboid at 4 x 4 x 8 cells with the top-centre
 * node alone touchable (test_fir_tail's setting): a one-node tick reads
 * T blocks of that node whatever the mesh, so the resolution does not
 * change the figure.  Not real-time scheduled: compare the two rows.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irdm/engine.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "../support/bench_util.h"

#define N_WARMUP 2000
#define N_TICKS 20000

static int time_ticks(const char *path, double *samples, struct bench_stats *st, uint32_t *T)
{
	struct irdm_session_config sc;
	struct irdm_session *s;
	struct irdm_contact_site site;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	char err[512];

	memset(&sc, 0, sizeof(sc));
	irdm_engine_config_default(&sc.engine);
	sc.engine.max_contacts = 1;
	if (irdm_session_open(&s, path, &sc, err, sizeof(err))) {
		fprintf(stderr, "fir-tail: %s\n", err);
		return -1;
	}
	*T = s->img->meta->fir_length;
	irdm_engine_site_node(s->eng, s->img->columns[0], &site);
	irdm_engine_contact_begin(s->eng, 0, &site, IRDM_CONTACT_GRAB);
	memset(cmd, 0, sizeof(cmd));
	cmd[0].mode = IRDM_CONTACT_GRAB;
	cmd[0].target_m[2] = -0.01;
	for (int t = 0; t < N_WARMUP; t++)
		irdm_engine_tick(s->eng, cmd);
	for (int t = 0; t < N_TICKS; t++) {
		struct timespec a, b;
		clock_gettime(CLOCK_MONOTONIC, &a);
		irdm_engine_tick(s->eng, cmd);
		clock_gettime(CLOCK_MONOTONIC, &b);
		samples[t] = bench_elapsed_ns(&a, &b) / 1000;
	}
	irdm_session_close(s);
	bench_stats(samples, N_TICKS, st);
	return 0;
}

int main(void)
{
	static const char *const bare_kv[] = {
		"name",
		"cuboid-4x4x8-fir500-top",
		"resolution",
		"4,4,8",
		"dt",
		"0.002",
		"representation",
		"fir:500",
		"modes",
		"all",
		"fir_tail",
		"none",
		"touch",
		"box:0.035,0.035,0.199,0.065,0.065,0.201",
		"display",
		"touch",
		NULL,
	};
	static const char *const win_kv[] = {
		"name",
		"cuboid-4x4x8-fir500-window1000-top",
		"resolution",
		"4,4,8",
		"dt",
		"0.002",
		"representation",
		"fir:500",
		"modes",
		"all",
		"fir_tail",
		"window:1000",
		"touch",
		"box:0.035,0.035,0.199,0.065,0.065,0.201",
		"display",
		"touch",
		NULL,
	};
	const char *path[2] = { "out/bench/cuboid-4x4x8-fir500-top.img",
				"out/bench/cuboid-4x4x8-fir500-window1000-top.img" };
	const char *what[2] = { "FIR T = 500 (the engine's r^s)", "FIR T = 500 + window:1000" };
	double *samples = malloc(N_TICKS * sizeof(double));
	int ret = 0;

	if (!samples || bench_ensure_image("fir-tail", path[0], NULL, bare_kv) ||
	    bench_ensure_image("fir-tail", path[1], NULL, win_kv)) {
		free(samples);
		return 1;
	}
	for (int k = 0; k < 2; k++) {
		struct bench_stats st;
		uint32_t T;
		if (time_ticks(path[k], samples, &st, &T)) {
			ret = 1;
			continue;
		}
		printf("fir-tail  %-32s ring %4u: median %5.2f us, p99 %5.2f us, max %6.1f us (%d ticks, one node)\n",
		       what[k], T, st.median, st.p99, st.max, N_TICKS);
	}
	free(samples);
	return ret;
}
