/* SPDX-License-Identifier: MIT */
/*
 * The deformation context against independent references:
 *  - small images made by the real precompute (modal f64/f32/f16 with static
 *    correction, FIR, floating);
 *  - a force history simulated here, then the displayed positions compared
 *    with a brute-force convolution over the whole history of the responses
 *    read back by irdm_image_response();
 *  - the clustered static correction (dense and low-rank pairs, both
 *    orders) against its blocks read one by one by irdm_image_corr_value();
 *  - the rigid pose of a floating image against a hand-computed rotation;
 *  - the triple buffer: newest tick, nothing new -> false, and no torn
 *    snapshot under a writer thread hammering publish;
 *  - the thread: frames arrive, at a priority below the caller's.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "image/image_response.h"
#include "irdm/posix/deform_worker.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "precompute/precompute.h"

void openblas_set_num_threads(int n);

enum { IMG_MODAL64,
       IMG_MODAL32,
       IMG_MODAL16,
       IMG_FIR,
       IMG_FLOAT,
       IMG_CL64,
       IMG_CL32,
       IMG_N };

static const char *const scene_kv[IMG_N][18] = {
	[IMG_MODAL64] = { "mesh", "box:0.1,0.1,0.2", "resolution", "2,2,4", "representation",
			  "modal:20", "precision", "f64", NULL },
	[IMG_MODAL32] = { "mesh", "box:0.1,0.1,0.2", "resolution", "2,2,4", "representation",
			  "modal:20", "precision", "f32", NULL },
	[IMG_MODAL16] = { "mesh", "box:0.1,0.1,0.2", "resolution", "2,2,4", "representation",
			  "modal:20", "precision", "f16", NULL },
	[IMG_FIR] = { "mesh", "box:0.1,0.1,0.2", "resolution", "2,2,4", "representation",
		      "fir:50", "precision", "f64", "touch", "z>=0.2", "display", "surface", "uncertified",
		      "yes", "fir_tail", "none", NULL },
	[IMG_FLOAT] = { "mesh", "box:0.1,0.1,0.1", "resolution", "2,2,2", "representation",
			"modal:20", "precision", "f64", "floating", "yes", NULL },
	/* the clustered correction: 313 touchable columns in 32 clusters of at
	 * most 16, tol 1e-3: 228 dense and 300 low-rank pairs (rank <= 14) */
	[IMG_CL64] = { "mesh", "box:0.1,0.1,0.2", "resolution", "6,6,12", "representation",
		       "modal:20", "precision", "f64", "static_correction_cluster", "16",
		       "static_correction_tol", "1e-3", NULL },
	[IMG_CL32] = { "mesh", "box:0.1,0.1,0.2", "resolution", "6,6,12", "representation",
		       "modal:20", "precision", "f32", "static_correction_cluster", "16",
		       "static_correction_tol", "1e-3", NULL },
};

static char tmpdir[64];
static struct irdm_image images[IMG_N];

#define N_TICKS 107
#define N_FORCE 2

/* ---- fixtures ---------------------------------------------------------- */

/* cmocka 1.1 has no assert_double_equal */
#define assert_close(a, b, tol) \
	do { \
		double a_ = (a), b_ = (b); \
		if (!(fabs(a_ - b_) <= (tol))) \
			fail_msg("%s = %.17g, expected %.17g (tolerance %g)", #a, a_, b_, (double)(tol)); \
	} while (0)

static int build_image(int which, char *err, size_t errlen)
{
	struct irdm_scene sc;
	struct irdm_precompute_opts o = { 0 };
	struct irdm_precompute_report rep;
	char path[128];

	irdm_scene_defaults(&sc);
	sc.max_error = 0; /* not what is tested here */
	for (const char *const *kv = scene_kv[which]; *kv; kv += 2)
		if (irdm_scene_set(&sc, kv[0], kv[1], "test", err, errlen))
			return -1;
	if (irdm_scene_check(&sc, err, errlen))
		return -1;
	snprintf(path, sizeof(path), "%s/img%d.img", tmpdir, which);
	o.out_path = path;
	if (irdm_precompute(&sc, &o, &rep, err, errlen))
		return -1;
	return irdm_image_map(path, 0, &images[which], err, errlen);
}

static int group_setup(void **state)
{
	char err[512];

	(void)state;
	snprintf(tmpdir, sizeof(tmpdir), "/tmp/test_deform.XXXXXX");
	if (!mkdtemp(tmpdir))
		return -1;
	for (int i = 0; i < IMG_N; i++)
		if (build_image(i, err, sizeof(err))) {
			fprintf(stderr, "image %d: %s\n", i, err);
			return -1;
		}
	openblas_set_num_threads(1);
	return 0;
}

static int group_teardown(void **state)
{
	char path[128];

	(void)state;
	for (int i = 0; i < IMG_N; i++) {
		irdm_image_unmap(&images[i]);
		snprintf(path, sizeof(path), "%s/img%d.img", tmpdir, i);
		unlink(path);
	}
	rmdir(tmpdir);
	return 0;
}

/*
 * A session with the deformation channel and its worker; the tests publish
 * to the channel themselves (the engine is there, never ticked).
 */
struct ctx {
	struct irdm_session *s;
	struct irdm_deform *d;        /* the session's channel */
	struct irdm_deform_worker *w; /* and its worker */
	double *pos;
	const struct irdm_image *img;
};

static void ctx_init(struct ctx *c, const struct irdm_image *img)
{
	struct irdm_session_config sc = { .deform = true };
	char err[256];

	irdm_engine_config_default(&sc.engine);
	c->img = img;
	c->pos = calloc(3 * (size_t)img->meta->n_nodes, sizeof(double));
	assert_non_null(c->pos);
	if (irdm_session_open_image(&c->s, img, &sc, err, sizeof(err)) ||
	    irdm_session_deform_open(c->s, err, sizeof(err)))
		fail_msg("session: %s", err);
	c->d = c->s->deform;
	c->w = c->s->worker;
	assert_int_equal(irdm_deform_rows(c->w), img->meta->n_nodes);
}

static void ctx_free(struct ctx *c)
{
	irdm_session_close(c->s);
	free(c->pos);
}

/* ---- a simulated force history ---------------------------------------- */

static uint64_t rng = 0x9e3779b97f4a7c15ull;

static double uniform(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (double)(rng >> 11) / 9007199254740992.0 * 2 - 1;
}

struct history {
	uint32_t col[N_FORCE];
	double f[N_TICKS][N_FORCE][3]; /* N */
};

static void random_history(const struct irdm_image *img, struct history *h)
{
	h->col[0] = 0;
	h->col[1] = img->meta->n_cols - 1;
	for (int t = 0; t < N_TICKS; t++)
		for (int e = 0; e < N_FORCE; e++)
			for (int j = 0; j < 3; j++)
				h->f[t][e][j] = uniform();
}

static void force_tick(const struct history *h, int t, struct irdm_force_tick *ft)
{
	memset(ft, 0, sizeof(*ft));
	ft->n = N_FORCE;
	for (int e = 0; e < N_FORCE; e++) {
		ft->col[e] = h->col[e];
		memcpy(ft->f_n[e], h->f[t][e], sizeof(ft->f_n[e]));
	}
}

/* Modal states after every tick of the history, from the image's A, b, phi. */
static void modal_states(const struct irdm_image *img, const struct history *h, double *x)
{
	const struct irdm_meta *m = img->meta;
	size_t K = m->n_modes;

	memset(x, 0, 2 * K * sizeof(double));
	for (int t = 0; t < N_TICKS; t++)
		for (size_t k = 0; k < K; k++) {
			const struct irdm_mode *md = &img->modes[k];
			double g = 0;
			for (int e = 0; e < N_FORCE; e++)
				for (size_t j = 0; j < 3; j++)
					g += irdm_elem_get(img->mode_shapes, m->precision,
							   ((size_t)img->columns[h->col[e]] * 3 + j) * K + k) *
					     h->f[t][e][j];
			double q = md->a[0] * x[2 * k] + md->a[1] * x[2 * k + 1] + md->b[0] * g;
			double v = md->a[2] * x[2 * k] + md->a[3] * x[2 * k + 1] + md->b[1] * g;
			x[2 * k] = q;
			x[2 * k + 1] = v;
		}
}

/* Brute force: u_r = sum_e sum_{s <= t} R_{c_e, r}[s] f_e[t - s], t the last tick. */
static void reference_disp(const struct irdm_image *img, const struct history *h, double *u)
{
	uint32_t n = img->meta->n_nodes;
	double *R = malloc(N_TICKS * 9 * sizeof(double));

	assert_non_null(R);
	memset(u, 0, 3 * (size_t)n * sizeof(double));
	for (uint32_t r = 0; r < n; r++)
		for (int e = 0; e < N_FORCE; e++) {
			assert_int_equal(irdm_image_response(img, h->col[e], r, N_TICKS, R), 0);
			for (int s = 0; s < N_TICKS; s++)
				for (int i = 0; i < 3; i++)
					for (int j = 0; j < 3; j++)
						u[3 * r + (uint32_t)i] += R[9 * s + 3 * i + j] *
									  h->f[N_TICKS - 1 - s][e][j];
		}
	free(R);
}

/* max |pos - rest - u_ref| / max |u_ref| */
static double rel_error(const struct irdm_image *img, const double *pos, const double *uref)
{
	double diff = 0, scale = 0;

	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		for (int i = 0; i < 3; i++) {
			double u = pos[3 * r + (uint32_t)i] - img->nodes[r].pos_m[i];
			diff = fmax(diff, fabs(u - uref[3 * r + (uint32_t)i]));
			scale = fmax(scale, fabs(uref[3 * r + (uint32_t)i]));
		}
	assert_true(scale > 0);
	return diff / scale;
}

/* ---- modal and FIR against the brute-force convolution ----------------- */

static double modal_case(int which)
{
	const struct irdm_image *img = &images[which];
	struct history *h = malloc(sizeof(*h));
	double *x = malloc(2 * img->meta->n_modes * sizeof(double));
	double *uref = malloc(3 * (size_t)img->meta->n_nodes * sizeof(double));
	struct irdm_force_tick ft;
	struct ctx c;
	uint64_t tick = 0;
	double e;

	assert_non_null(h);
	assert_non_null(x);
	assert_non_null(uref);
	assert_non_null(img->corr_start); /* the default scene keeps it, */
	assert_true(img->corr_rank > 0);  /* and its far field */
	random_history(img, h);
	modal_states(img, h, x);
	reference_disp(img, h, uref);
	ctx_init(&c, img);
	force_tick(h, N_TICKS - 1, &ft);
	irdm_deform_publish_modal(c.d, N_TICKS - 1, x, &ft, NULL);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	assert_int_equal(tick, N_TICKS - 1);
	e = rel_error(img, c.pos, uref);
	ctx_free(&c);
	free(h);
	free(x);
	free(uref);
	return e;
}

static void test_modal_f64(void **state)
{
	(void)state;
	double e = modal_case(IMG_MODAL64);
	print_message("modal f64: relative error %.3g\n", e);
	assert_true(e <= 1e-9);
}

static void test_modal_f32_f16(void **state)
{
	(void)state;
	/* the same shapes the reference reads, multiplied in float by BLAS */
	double e32 = modal_case(IMG_MODAL32), e16 = modal_case(IMG_MODAL16);
	print_message("modal f32: %.3g, f16: %.3g\n", e32, e16);
	assert_true(e32 <= 1e-5);
	assert_true(e16 <= 1e-5);
}

static void test_fir(void **state)
{
	const struct irdm_image *img = &images[IMG_FIR];
	uint32_t T = img->meta->fir_length;
	struct history *h = malloc(sizeof(*h));
	struct irdm_force_tick *ticks = calloc(T, sizeof(*ticks));
	double *uref = malloc(3 * (size_t)img->meta->n_nodes * sizeof(double));
	struct irdm_fir_ring ring = { .T = T, .tick = ticks };
	struct ctx c;
	uint64_t tick;

	(void)state;
	assert_non_null(h);
	assert_non_null(ticks);
	assert_non_null(uref);
	assert_true(T < N_TICKS); /* the ring wraps: head is not T - 1 */
	random_history(img, h);
	reference_disp(img, h, uref); /* zeros past T: the whole history */
	for (int t = 0; t < N_TICKS; t++) {
		ring.head = (uint32_t)t % T;
		force_tick(h, t, &ticks[ring.head]);
	}
	/* a column out of range is ignored, not read */
	ticks[ring.head].col[ticks[ring.head].n] = img->meta->n_cols + 7;
	ticks[ring.head].f_n[ticks[ring.head].n][2] = 1e3;
	ticks[ring.head].n++;
	ctx_init(&c, img);
	irdm_deform_publish_fir(c.d, N_TICKS - 1, &ring, NULL);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	assert_int_equal(tick, N_TICKS - 1);
	double e = rel_error(img, c.pos, uref);
	print_message("FIR f64: relative error %.3g\n", e);
	assert_true(e <= 1e-9);
	ctx_free(&c);
	free(h);
	free(ticks);
	free(uref);
}

/* ---- the clustered static correction ----------------------------------- */

#define N_CL_FORCE 4

/*
 * Force nodes in four different clusters (the first, the last and two
 * between), each at a different member index, with random forces.
 */
static void cluster_forces(const struct irdm_image *img, struct irdm_force_tick *ft)
{
	const uint32_t *st = img->corr_cl_start;
	uint32_t nC = img->corr_clusters->n_clusters;
	const uint32_t pick[N_CL_FORCE] = { 0, nC / 3, 2 * nC / 3, nC - 1 };

	assert_true(nC >= N_CL_FORCE);
	memset(ft, 0, sizeof(*ft));
	ft->n = N_CL_FORCE;
	for (uint32_t e = 0; e < N_CL_FORCE; e++) {
		uint32_t a = pick[e], n = st[a + 1] - st[a];
		ft->col[e] = img->corr_cl_members[st[a] + (3 * e + 1) % n];
		for (int j = 0; j < 3; j++)
			ft->f_n[e][j] = uniform();
	}
}

/*
 * The pairs these forces read, as (dense, low-rank) x (a < b, a > b) with
 * a the displaced cluster and b the force's: every kind must occur, or the
 * comparison would not see a wrong branch.
 */
static void cluster_pair_kinds(const struct irdm_image *img, const struct irdm_force_tick *ft)
{
	uint32_t nC = img->corr_clusters->n_clusters, n[2][2] = { { 0 } }, j;

	for (uint32_t e = 0; e < ft->n; e++) {
		uint32_t b = irdm_image_corr_cluster(img, ft->col[e], &j);
		for (uint32_t a = 0; a < nC; a++)
			if (a != b)
				n[irdm_image_corr_pair(img, a, b)->rank != IRDM_CORR_PAIR_DENSE][a > b]++;
	}
	print_message("clustered: %u clusters, max rank %u; pairs read: dense %u (a < b) %u (a > b), low-rank %u (a < b) %u (a > b)\n",
		      nC, img->corr_clusters->max_rank, n[0][0], n[0][1], n[1][0], n[1][1]);
	for (int d = 0; d < 2; d++)
		for (int o = 0; o < 2; o++)
			assert_true(n[d][o] > 0);
}

/*
 * Each mode's static response to the forces, phi_k^T f / omega_k^2: the
 * kept modes' share of the static displacement, so that Phi y and the
 * correction (the dropped modes' share) come at their physical sizes.
 */
static void static_modal_states(const struct irdm_image *img, const struct irdm_force_tick *ft,
				double *x)
{
	size_t K = img->meta->n_modes;

	memset(x, 0, 2 * K * sizeof(double));
	for (size_t k = 0; k < K; k++) {
		double w = img->modes[k].omega_rad_s, g = 0;
		for (uint32_t e = 0; e < ft->n; e++)
			for (size_t j = 0; j < 3; j++)
				g += irdm_elem_get(img->mode_shapes, img->meta->precision,
						   ((size_t)img->columns[ft->col[e]] * 3 + j) * K + k) *
				     ft->f_n[e][j];
		x[2 * k] = g / (w * w);
	}
}

/* Brute force: u_r = sum_k Phi[r][k] x_k + sum_e block(col_e -> r) f_e, the
 * blocks read one by one by irdm_image_corr_value(). */
static void cluster_reference(const struct irdm_image *img, const struct irdm_force_tick *ft,
			      const double *x, double *u)
{
	size_t K = img->meta->n_modes;
	double blk[9];

	for (size_t i = 0; i < 3 * (size_t)img->meta->n_nodes; i++) {
		u[i] = 0;
		for (size_t k = 0; k < K; k++)
			u[i] += irdm_elem_get(img->mode_shapes, img->meta->precision, i * K + k) *
				x[2 * k];
	}
	for (uint32_t c = 0; c < img->meta->n_cols; c++)
		for (uint32_t e = 0; e < ft->n; e++) {
			double *uc = u + 3 * (size_t)img->columns[c];
			irdm_image_corr_value(img, ft->col[e], c, blk);
			for (int i = 0; i < 3; i++)
				for (int j = 0; j < 3; j++)
					uc[i] += blk[3 * i + j] * ft->f_n[e][j];
		}
}

/* The displayed displacement of every node under ft with states x
 * (NULL: zero, the correction alone), relative to the brute force. */
static double cluster_case(struct ctx *c, const struct irdm_force_tick *ft, const double *x,
			   uint64_t t)
{
	const struct irdm_image *img = c->img;
	size_t K = img->meta->n_modes;
	double *x0 = calloc(2 * K, sizeof(double));
	double *uref = malloc(3 * (size_t)img->meta->n_nodes * sizeof(double));
	uint64_t tick = 0;
	double e;

	assert_non_null(x0);
	assert_non_null(uref);
	cluster_reference(img, ft, x ? x : x0, uref);
	irdm_deform_publish_modal(c->d, t, x ? x : x0, ft, NULL);
	assert_true(irdm_deform_update(c->w, c->pos, &tick));
	assert_int_equal(tick, t);
	e = rel_error(img, c->pos, uref);
	free(x0);
	free(uref);
	return e;
}

static void clusters(int which, double tol_corr, double tol_all)
{
	const struct irdm_image *img = &images[which];
	double *x = malloc(2 * img->meta->n_modes * sizeof(double));
	struct irdm_force_tick ft;
	struct ctx c;

	assert_non_null(x);
	assert_non_null(img->corr_clusters);
	assert_true(img->meta->n_cols >= 200);
	cluster_forces(img, &ft);
	cluster_pair_kinds(img, &ft);
	static_modal_states(img, &ft, x);
	ctx_init(&c, img);
	double e_corr = cluster_case(&c, &ft, NULL, 1), e_all = cluster_case(&c, &ft, x, 2);
	print_message("clustered %s: relative error %.3g (correction alone), %.3g (with Phi y)\n",
		      which == IMG_CL64 ? "f64" : "f32", e_corr, e_all);
	ctx_free(&c);
	free(x);
	assert_true(e_corr <= tol_corr);
	assert_true(e_all <= tol_all);
}

/*
 * The worker's clustered product against the blocks one by one.  The
 * correction is summed in double from the image's values on both sides
 * (only the order differs: U (V^T f) against (U V^T) f), so it agrees to
 * double rounding for either precision; Phi y is an f32 BLAS product on an
 * f32 image.  Measured (gcc, clang, sanitizers alike): f64 1.3e-15 alone,
 * 8.3e-16 with Phi y; f32 1.0e-15 alone, 1.2e-7 with Phi y; each bound
 * about 8x above.
 */
static void test_clusters_f64(void **state)
{
	(void)state;
	clusters(IMG_CL64, 1e-14, 8e-15);
}

static void test_clusters_f32(void **state)
{
	(void)state;
	clusters(IMG_CL32, 1e-14, 1e-6);
}

/* ---- floating: the rigid pose ------------------------------------------ */

/* 90 degrees about z: (x, y, z) -> (-y, x, z), by hand. */
static void rot_z90(const double v[3], double out[3])
{
	out[0] = -v[1];
	out[1] = v[0];
	out[2] = v[2];
}

static void check_pose(const struct irdm_image *img, const double *pos, const double *uref,
		       const double com[3], double tol)
{
	const double *cr = img->rigid->com_m;

	for (uint32_t r = 0; r < img->meta->n_nodes; r++) {
		double v[3], w[3];
		for (int i = 0; i < 3; i++)
			v[i] = img->nodes[r].pos_m[i] + (uref ? uref[3 * r + (uint32_t)i] : 0) - cr[i];
		rot_z90(v, w);
		for (int i = 0; i < 3; i++)
			assert_close(pos[3 * r + (uint32_t)i], com[i] + w[i], tol);
	}
}

static void test_floating_pose(void **state)
{
	const struct irdm_image *img = &images[IMG_FLOAT];
	size_t K = img->meta->n_modes, n = img->meta->n_nodes;
	struct history *h = malloc(sizeof(*h));
	double *x = calloc(2 * K, sizeof(double)), *uref = malloc(3 * n * sizeof(double));
	const double s = sqrt(0.5);
	struct irdm_pose pose = { .com_m = { 1.0, -2.0, 0.5 }, .q = { s, 0, 0, s } };
	struct irdm_force_tick ft;
	struct ctx c;
	uint64_t tick;
	double umax = 0;

	(void)state;
	assert_non_null(img->rigid);
	assert_non_null(h);
	assert_non_null(x);
	assert_non_null(uref);
	ctx_init(&c, img);

	/* undeformed: the rest shape rotated about the rest centre of mass */
	irdm_deform_publish_modal(c.d, 1, x, NULL, &pose);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	check_pose(img, c.pos, NULL, pose.com_m, 1e-12);

	/* deformed: the deformation is applied in the body frame, then moved */
	random_history(img, h);
	modal_states(img, h, x);
	reference_disp(img, h, uref);
	for (size_t i = 0; i < 3 * n; i++)
		umax = fmax(umax, fabs(uref[i]));
	force_tick(h, N_TICKS - 1, &ft);
	irdm_deform_publish_modal(c.d, 2, x, &ft, &pose);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	check_pose(img, c.pos, uref, pose.com_m, 1e-9 * umax + 1e-12);

	/* an unnormalised quaternion is the same rotation */
	for (int i = 0; i < 4; i++)
		pose.q[i] *= 3.0;
	irdm_deform_publish_modal(c.d, 3, x, &ft, &pose);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	check_pose(img, c.pos, uref, pose.com_m, 1e-9 * umax + 1e-12);
	ctx_free(&c);
	free(h);
	free(x);
	free(uref);
}

static void test_grounded_ignores_pose(void **state)
{
	const struct irdm_image *img = &images[IMG_MODAL64];
	double *x = calloc(2 * img->meta->n_modes, sizeof(double));
	struct irdm_pose pose = { .com_m = { 5, 5, 5 }, .q = { 0, 1, 0, 0 } };
	struct ctx c;
	uint64_t tick;

	(void)state;
	assert_non_null(x);
	ctx_init(&c, img);
	irdm_deform_publish_modal(c.d, 1, x, NULL, &pose);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		for (int i = 0; i < 3; i++)
			assert_close(c.pos[3 * r + (uint32_t)i], img->nodes[r].pos_m[i], 0);
	ctx_free(&c);
	free(x);
}

/* ---- the triple buffer ------------------------------------------------- */

static void test_newest_and_nothing_new(void **state)
{
	const struct irdm_image *img = &images[IMG_MODAL64];
	double *x = calloc(2 * img->meta->n_modes, sizeof(double));
	struct ctx c;
	uint64_t tick = 0;

	(void)state;
	assert_non_null(x);
	ctx_init(&c, img);
	assert_false(irdm_deform_update(c.w, c.pos, &tick));
	for (uint64_t t = 1; t <= 3; t++)
		irdm_deform_publish_modal(c.d, t, x, NULL, NULL);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	assert_int_equal(tick, 3);
	assert_false(irdm_deform_update(c.w, c.pos, &tick));
	assert_int_equal(tick, 3);
	irdm_deform_publish_modal(c.d, 4, x, NULL, NULL);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	assert_int_equal(tick, 4);
	assert_false(irdm_deform_update(c.w, c.pos, &tick));
	/* a publish of the wrong representation is ignored */
	struct irdm_fir_ring ring = { 0 };
	irdm_deform_publish_fir(c.d, 5, &ring, NULL);
	assert_false(irdm_deform_update(c.w, c.pos, &tick));
	ctx_free(&c);
	free(x);
}

static void test_init_errors(void **state)
{
	const struct irdm_image *img = &images[IMG_MODAL64];
	size_t sz = irdm_deform_mem_size(img), wsz = irdm_deform_worker_mem_size(img);
	void *mem = malloc(sz), *wmem = malloc(wsz);
	struct irdm_session_config sc = { .deform = false };
	struct irdm_session *s;
	struct irdm_deform_worker *w;
	struct irdm_deform *d;
	struct irdm_image bad = { 0 };
	char err[256];

	(void)state;
	assert_non_null(mem);
	assert_non_null(wmem);
	assert_int_equal(irdm_deform_mem_size(&bad), 0);
	assert_int_equal(irdm_deform_worker_mem_size(&bad), 0);
	assert_int_equal(irdm_deform_init(&d, &bad, mem, sz, err, sizeof(err)), IRDM_EINVAL);
	assert_int_equal(irdm_deform_init(&d, img, mem, sz - 65, err, sizeof(err)), IRDM_ENOMEM);
	assert_null(d);
	assert_non_null(strstr(err, "needed"));
	assert_int_equal(irdm_deform_worker_init(&w, NULL, wmem, wsz, err, sizeof(err)), IRDM_EINVAL);
	assert_int_equal(irdm_deform_init(&d, img, mem, sz, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_deform_worker_init(&w, d, wmem, wsz - 65, err, sizeof(err)),
			 IRDM_ENOMEM);
	assert_null(w);
	assert_non_null(strstr(err, "needed"));

	/* a session without the channel has nothing for a worker to read */
	irdm_engine_config_default(&sc.engine);
	assert_int_equal(irdm_session_open_image(&s, img, &sc, err, sizeof(err)), IRDM_OK);
	assert_null(s->deform);
	assert_int_equal(irdm_session_deform_open(s, err, sizeof(err)), IRDM_EINVAL);
	irdm_session_close(s);
	/* one worker per channel */
	sc.deform = true;
	assert_int_equal(irdm_session_open_image(&s, img, &sc, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_session_deform_open(s, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_session_deform_open(s, err, sizeof(err)), IRDM_EBUSY);
	irdm_session_close(s);
	/* a configuration the engine refuses */
	sc.engine.max_contacts = IRDM_MAX_CONTACTS + 1;
	assert_int_equal(irdm_session_open_image(&s, img, &sc, err, sizeof(err)), IRDM_EINVAL);
	assert_null(s);
	free(mem);
	free(wmem);
}

/* Channel and worker in memory of any alignment (here 8 past malloc's). */
static void test_misaligned_memory(void **state)
{
	const struct irdm_image *img = &images[IMG_MODAL16];
	size_t sz = irdm_deform_mem_size(img), wsz = irdm_deform_worker_mem_size(img);
	char *mem = malloc(sz + 8), *wmem = malloc(wsz + 8);
	double *x = calloc(2 * img->meta->n_modes, sizeof(double));
	double *pos = calloc(3 * (size_t)img->meta->n_nodes, sizeof(double));
	struct irdm_deform_worker *w = NULL;
	struct irdm_deform *d = NULL;
	uint64_t tick = 0;
	char err[256];

	(void)state;
	assert_non_null(mem);
	assert_non_null(wmem);
	assert_non_null(x);
	assert_non_null(pos);
	if (irdm_deform_init(&d, img, mem + 8, sz, err, sizeof(err)) ||
	    irdm_deform_worker_init(&w, d, wmem + 8, wsz, err, sizeof(err)))
		fail_msg("deform init: %s", err);
	irdm_deform_publish_modal(d, 7, x, NULL, NULL);
	assert_true(irdm_deform_update(w, pos, &tick));
	assert_int_equal(tick, 7);
	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		for (int i = 0; i < 3; i++)
			assert_close(pos[3 * r + (uint32_t)i], img->nodes[r].pos_m[i], 0);
	free(mem);
	free(wmem);
	free(x);
	free(pos);
}

/*
 * Every state of tick t is t c_k and every force t f0: the displacement is
 * t w with w the displacement of tick 1.  A snapshot mixing two ticks is off
 * by a relative |t1 - t2| / t >> 1e-9.
 */
#define HAMMER_FRAMES 20000           /* frames the reader checks */
#define HAMMER_MAX_TICKS 100000000ull /* writer's bound if the reader stalls */
#define HAMMER_SECONDS 1.5            /* or this long */

static double now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct hammer {
	struct irdm_deform *d;
	uint32_t K, col;
	atomic_bool enough;        /* reader -> writer: stop */
	atomic_bool done;          /* writer -> reader */
	atomic_uint_fast64_t last; /* writer's last tick */
};

static void hammer_state(uint64_t t, uint32_t K, uint32_t col, double *x,
			 struct irdm_force_tick *ft)
{
	for (uint32_t k = 0; k < K; k++) {
		x[2 * k] = (double)t * 1e-3 / (k + 1);
		x[2 * k + 1] = -(double)t;
	}
	memset(ft, 0, sizeof(*ft));
	ft->n = 1;
	ft->col[0] = col;
	ft->f_n[0][0] = 0.5 * (double)t;
	ft->f_n[0][1] = -0.25 * (double)t;
	ft->f_n[0][2] = (double)t;
}

static void *hammer_writer(void *arg)
{
	struct hammer *hm = arg;
	double *x = malloc(2 * hm->K * sizeof(double));
	struct irdm_force_tick ft;

	uint64_t t;

	for (t = 2; x && t <= HAMMER_MAX_TICKS && !atomic_load(&hm->enough); t++) {
		hammer_state(t, hm->K, hm->col, x, &ft);
		irdm_deform_publish_modal(hm->d, t, x, &ft, NULL);
	}
	atomic_store(&hm->last, t - 1);
	free(x);
	atomic_store(&hm->done, true);
	return NULL;
}

static void check_linear(const struct irdm_image *img, const double *pos, const double *w,
			 double wmax, uint64_t t)
{
	/* rounding grows with t and the terms' size; a tear is ~ |w| */
	double tol = 1e-11 * (double)t * wmax;

	for (uint32_t r = 0; r < img->meta->n_nodes; r++)
		for (int i = 0; i < 3; i++) {
			size_t k = 3 * r + (size_t)i;
			double u = pos[k] - img->nodes[r].pos_m[i], ref = (double)t * w[k];
			if (fabs(u - ref) > tol)
				fail_msg("torn snapshot at tick %llu: node %u axis %d: %.17g vs %.17g",
					 (unsigned long long)t, r, i, u, ref);
		}
}

static void test_no_torn_snapshot(void **state)
{
	const struct irdm_image *img = &images[IMG_MODAL64];
	uint32_t n3 = 3 * img->meta->n_nodes;
	double *w = malloc(n3 * sizeof(double)), *x = malloc(2 * img->meta->n_modes * sizeof(double));
	struct hammer hm = { .K = img->meta->n_modes, .col = img->meta->n_cols / 2 };
	struct irdm_force_tick ft;
	struct ctx c;
	pthread_t tid;
	uint64_t tick, last = 1, frames = 0;
	double wmax = 0;

	(void)state;
	assert_non_null(w);
	assert_non_null(x);
	ctx_init(&c, img);
	hm.d = c.d;
	hammer_state(1, hm.K, hm.col, x, &ft);
	irdm_deform_publish_modal(c.d, 1, x, &ft, NULL);
	assert_true(irdm_deform_update(c.w, c.pos, &tick));
	for (uint32_t k = 0; k < n3; k++)
		w[k] = c.pos[k] - img->nodes[k / 3].pos_m[k % 3];
	for (uint32_t k = 0; k < n3; k++)
		wmax = fmax(wmax, fabs(w[k]));
	double t_end = now_s() + HAMMER_SECONDS;

	atomic_init(&hm.done, false);
	atomic_init(&hm.enough, false);
	atomic_init(&hm.last, 0);
	assert_int_equal(pthread_create(&tid, NULL, hammer_writer, &hm), 0);
	while (!atomic_load(&hm.done)) {
		if (!irdm_deform_update(c.w, c.pos, &tick))
			continue;
		assert_true(tick > last); /* never an old one again */
		check_linear(img, c.pos, w, wmax, tick);
		last = tick;
		if (++frames == HAMMER_FRAMES || now_s() > t_end)
			atomic_store(&hm.enough, true);
	}
	pthread_join(tid, NULL);
	/* the newest is there once, then nothing */
	if (irdm_deform_update(c.w, c.pos, &tick)) {
		check_linear(img, c.pos, w, wmax, tick);
		last = tick;
	}
	assert_int_equal(last, atomic_load(&hm.last));
	assert_false(irdm_deform_update(c.w, c.pos, &tick));
	print_message("triple buffer: %llu consistent frames read during %llu publishes\n",
		      (unsigned long long)frames, (unsigned long long)last);
	assert_true(frames > 0);
	ctx_free(&c);
	free(w);
	free(x);
}

/* ---- the thread -------------------------------------------------------- */

struct frames {
	atomic_uint_fast64_t last, count;
	atomic_int policy, prio, nice;
	atomic_bool finite;
	uint32_t n3;
};

static void on_frame(void *arg, const double *pos, uint64_t tick)
{
	struct frames *fr = arg;
	struct sched_param sp;
	int policy;

	for (uint32_t i = 0; i < fr->n3; i++)
		if (!isfinite(pos[i]))
			atomic_store(&fr->finite, false);
	if (!pthread_getschedparam(pthread_self(), &policy, &sp)) {
		atomic_store(&fr->policy, policy);
		atomic_store(&fr->prio, sp.sched_priority);
	}
	atomic_store(&fr->nice, getpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid)));
	atomic_store(&fr->last, tick);
	atomic_fetch_add(&fr->count, 1);
}

static void sleep_ms(long ms)
{
	struct timespec ts = { ms / 1000, (ms % 1000) * 1000000L };

	while (nanosleep(&ts, &ts) && errno == EINTR)
		;
}

static void run_thread(struct frames *fr)
{
	const struct irdm_image *img = &images[IMG_MODAL64];
	double *x = calloc(2 * img->meta->n_modes, sizeof(double));
	struct irdm_deform_thread *th;
	struct ctx c;
	char err[256] = "";

	assert_non_null(x);
	ctx_init(&c, img);
	memset(fr, 0, sizeof(*fr));
	atomic_store(&fr->finite, true);
	fr->n3 = 3 * img->meta->n_nodes;
	assert_int_equal(irdm_deform_thread_start(&th, c.w, 0, on_frame, fr, err, sizeof(err)),
			 IRDM_EINVAL);
	if (irdm_deform_thread_start(&th, c.w, 500, on_frame, fr, err, sizeof(err)))
		fail_msg("%s", err);
	if (err[0])
		print_message("%s\n", err);
	struct irdm_deform_thread *th2;
	assert_int_equal(irdm_deform_thread_start(&th2, c.w, 500, on_frame, fr, err, sizeof(err)),
			 IRDM_EBUSY);
	for (uint64_t t = 1; t <= 5; t++) {
		x[0] = 1e-3 * (double)t;
		irdm_deform_publish_modal(c.d, t, x, NULL, NULL);
		sleep_ms(20);
	}
	irdm_deform_thread_stop(th);
	irdm_deform_thread_stop(NULL);
	assert_int_equal(atomic_load(&fr->last), 5);
	assert_true(atomic_load(&fr->count) >= 2 && atomic_load(&fr->count) <= 5);
	assert_true(atomic_load(&fr->finite));
	ctx_free(&c);
	free(x);
}

static void test_thread_other(void **state)
{
	struct frames fr;
	int nice0;

	(void)state;
	errno = 0;
	nice0 = getpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid));
	run_thread(&fr);
	assert_int_equal(atomic_load(&fr.policy), SCHED_OTHER);
	assert_int_equal(atomic_load(&fr.nice), nice0 + 5 > 19 ? 19 : nice0 + 5);
}

static void test_thread_fifo(void **state)
{
	struct sched_param sp = { .sched_priority = 10 }, sp0;
	struct frames fr;
	int policy0;

	(void)state;
	pthread_getschedparam(pthread_self(), &policy0, &sp0);
	if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp)) {
		print_message("SCHED_FIFO not permitted here: FIFO path not tested\n");
		skip();
	}
	run_thread(&fr);
	pthread_setschedparam(pthread_self(), policy0, &sp0);
	assert_int_equal(atomic_load(&fr.policy), SCHED_FIFO);
	assert_int_equal(atomic_load(&fr.prio), 9);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_modal_f64),
		cmocka_unit_test(test_modal_f32_f16),
		cmocka_unit_test(test_fir),
		cmocka_unit_test(test_clusters_f64),
		cmocka_unit_test(test_clusters_f32),
		cmocka_unit_test(test_floating_pose),
		cmocka_unit_test(test_grounded_ignores_pose),
		cmocka_unit_test(test_newest_and_nothing_new),
		cmocka_unit_test(test_init_errors),
		cmocka_unit_test(test_misaligned_memory),
		cmocka_unit_test(test_no_torn_snapshot),
		cmocka_unit_test(test_thread_other),
		cmocka_unit_test(test_thread_fifo),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
