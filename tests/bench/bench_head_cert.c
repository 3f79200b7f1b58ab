/* SPDX-License-Identifier: MIT */
/*
 * What an exact FIR head costs the modal stability certificate
 * (irdm_stability_modal_cert_head): one node of K = 250 kept modes (1 ..
 * 250 Hz, 1 ms) with heads of 1 .. 300 samples, the exact response of 100
 * dropped fast modes (0.5 .. 5 kHz, heavily damped, so that every case is
 * stable and the search does the same work).  Prints the time per
 * certificate (the fastest of REPEAT) and per transfer-function
 * evaluation on the circles.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modal/modal.h"
#include "modal/stability.h"
#include "../support/bench_util.h"
#include "../support/stab_cert.h"

#define K_KEPT 250
#define K_DROPPED 100
#define K_ALL (K_KEPT + K_DROPPED)
#define MAX_HEAD 300
#define REPEAT 20 /* the fastest run counts: a shared machine */

/* deterministic, spread shapes and modes; the dropped ones fast and damped */
static void node_modes(struct irdm_mode *zoh, double *phi)
{
	for (int k = 0; k < K_ALL; k++) {
		if (k < K_KEPT)
			irdm_zoh_mode(2 * M_PI * (1.0 + k), 0.02, 1e-3, &zoh[k]);
		else
			irdm_zoh_mode(2 * M_PI * (500.0 + 45.0 * (k - K_KEPT)), 0.5, 1e-3, &zoh[k]);
		for (int i = 0; i < 3; i++)
			phi[i * K_ALL + k] = cos(1.0 + 0.7 * k * (i + 1) + i) / sqrt(k + 1.0);
	}
}

int main(void)
{
	static const size_t lengths[] = { 1, 20, 100, MAX_HEAD };
	struct irdm_mode *zoh = malloc(K_ALL * sizeof(*zoh));
	double *phi = malloc(3 * K_ALL * sizeof(double)), *phi_c = malloc(3 * K_KEPT * sizeof(double));
	double *head = malloc(9 * MAX_HEAD * sizeof(double));
	int ret = 1;

	if (!zoh || !phi || !phi_c || !head)
		goto out_free;
	node_modes(zoh, phi);
	for (int i = 0; i < 3; i++)
		memcpy(&phi_c[i * K_KEPT], &phi[i * K_ALL], K_KEPT * sizeof(double));
	printf("head-cert: K = %d kept modes, head of %d dropped modes, fastest of %d runs\n", K_KEPT,
	       K_DROPPED, REPEAT);
	for (size_t l = 0; l < sizeof(lengths) / sizeof(lengths[0]); l++) {
		size_t H = lengths[l];
		struct irdm_stab_cert c;
		stab_dropped_head(zoh, phi, K_ALL, K_KEPT, K_ALL, H, head);
		double us = INFINITY;
		for (int r = 0; r < REPEAT; r++) {
			double t0 = bench_now_us();
			if (irdm_stability_modal_cert_head(zoh, K_KEPT, phi_c, head, H, &c)) {
				fprintf(stderr, "head-cert: certificate failed at H = %zu\n", H);
				goto out_free;
			}
			us = fmin(us, bench_now_us() - t0);
		}
		printf("head-cert: H %4zu  rho %.9f  %2u circles %6zu points  %8.2f ms  %6.2f us/point\n",
		       H, c.rho, c.circles, c.points, us / 1000, us / (double)c.points);
	}
	ret = 0;
out_free:
	free(zoh);
	free(phi);
	free(phi_c);
	free(head);
	return ret;
}
