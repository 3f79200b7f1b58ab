/* SPDX-License-Identifier: MIT */
/*
 * The force tick is hard real time (docs/architecture.md, "Memory and
 * threading"), proven rather than claimed.
 *
 *  - No allocation: this executable interposes the allocator (malloc,
 *    calloc, realloc, reallocarray, free, aligned_alloc, posix_memalign,
 *    memalign, valloc, pvalloc) and the mappings (mmap, mmap64, munmap,
 *    mremap, brk, sbrk); a call while `armed` is counted, and N ticks of a
 *    realistic haptic scenario after init must count none.
 *  - No page fault: getrusage(RUSAGE_THREAD) minor and major fault counts
 *    do not move across those ticks (after a warm-up, with the memory
 *    locked and the stack pre-faulted as docs/architecture.md asks).
 *  - No system call: the same ticks run in a forked child that has put
 *    itself in seccomp strict mode, where any system call but read, write,
 *    _exit and sigreturn kills it with SIGKILL.
 *
 * The scenario: modal (300 modes + static correction), FIR (T = 500),
 * hybrid (300 modes + an exact head of 32 + 32 samples) and clustered
 * (300 modes + the clustered correction: dense and low-rank pairs read
 * whenever a contact begins) images of the
 * paper's cuboid at a modest resolution, the haptic
 * configuration (virtual coupling + passivity control + force limit), two
 * contacts -- a push on a top node that slides to a neighbouring node every
 * 50 ticks (irdm_engine_site_node + irdm_engine_contact_begin inside the
 * loop) and a grab (on a triangle point where the image has one) -- with
 * sinusoidal targets, and a deformation context attached that receives a
 * snapshot every 16 ticks; the worker's update of the newest one (the
 * clustered correction's product included) is measured for allocation and
 * page faults as the ticks are.  The forces must be finite and not all zero, so
 * the test cannot pass by doing nothing; a NaN target must fault the
 * engine, again without allocating.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <linux/seccomp.h>

#include <cmocka.h>

#include "irdm/posix/deform_worker.h"
#include "irdm/engine.h"
#include "irdm/posix/image_map.h"
#include "irdm/posix/rt.h"
#include "irdm/posix/session.h"
#include "irdm/session.h"
#include "support/engine_fixture.h"
#include "support/strict_mode.h"

void openblas_set_num_threads(int n);

/*
 * AddressSanitizer (make san) replaces malloc and friends and mmap with
 * its own interceptors; a second definition in the executable would fight
 * them (ASan's allocator must see every block it later frees or reports).
 * Under ASan only the allocator interposition is left out -- the page fault
 * and system call proofs still run.
 */
#define RT_ASAN IRDM_RT_ASAN

#ifndef SECCOMP_MODE_STRICT
#define SECCOMP_MODE_STRICT 1
#endif

#define N_WARMUP 100
#define N_TICKS 5000
#define SLIDE_EVERY 50
#define PUBLISH_EVERY 16

/* A PHANToM-Desktop-class device, as in test_stability.c. */
#define DEVICE_K 1000.0
#define DEVICE_B 5.0
#define DEVICE_F 7.9

/* ---- allocator and mapping interposition ---- */

enum { I_MALLOC,
       I_CALLOC,
       I_REALLOC,
       I_REALLOCARRAY,
       I_FREE,
       I_ALIGNED_ALLOC,
       I_POSIX_MEMALIGN,
       I_MEMALIGN,
       I_VALLOC,
       I_PVALLOC,
       I_MMAP,
       I_MMAP64,
       I_MUNMAP,
       I_MREMAP,
       I_BRK,
       I_SBRK,
       I_COUNT };

static const char *const fn_name[I_COUNT] = {
	"malloc",
	"calloc",
	"realloc",
	"reallocarray",
	"free",
	"aligned_alloc",
	"posix_memalign",
	"memalign",
	"valloc",
	"pvalloc",
	"mmap",
	"mmap64",
	"munmap",
	"mremap",
	"brk",
	"sbrk",
};

static atomic_bool armed;
static atomic_ulong calls[I_COUNT];

static unsigned long calls_total(void)
{
	unsigned long n = 0;

	for (int i = 0; i < I_COUNT; i++)
		n += atomic_load(&calls[i]);
	return n;
}

static void arm(void)
{
	for (int i = 0; i < I_COUNT; i++)
		atomic_store(&calls[i], 0);
	atomic_store(&armed, true);
}

static void disarm(void)
{
	atomic_store(&armed, false);
}

/* "malloc 2, free 2" (the calls counted while armed) */
static const char *calls_text(char *buf, size_t len)
{
	size_t o = 0;

	buf[0] = 0;
	for (int i = 0; i < I_COUNT; i++) {
		unsigned long n = atomic_load(&calls[i]);
		if (n && o < len)
			o += (size_t)snprintf(buf + o, len - o, "%s%s %lu", o ? ", " : "",
					      fn_name[i], n);
	}
	return buf;
}

#if !RT_ASAN
/*
 * glibc lets the executable define the allocator (its own calls inside
 * libc go through the interposable symbol too); forwarding to the
 * __libc_* entry points keeps every block in glibc's one heap, so a block
 * from either side can be freed on the other.
 */
void *__libc_malloc(size_t n);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t n);
void __libc_free(void *p);
void *__libc_memalign(size_t align, size_t n);
void *__libc_valloc(size_t n);
void *__libc_pvalloc(size_t n);
void *__sbrk(intptr_t inc);

static inline void note(int fn)
{
	if (atomic_load_explicit(&armed, memory_order_relaxed))
		atomic_fetch_add_explicit(&calls[fn], 1, memory_order_relaxed);
}

void *malloc(size_t n)
{
	note(I_MALLOC);
	return __libc_malloc(n);
}

void *calloc(size_t n, size_t size)
{
	note(I_CALLOC);
	return __libc_calloc(n, size);
}

void *realloc(void *p, size_t n)
{
	note(I_REALLOC);
	return __libc_realloc(p, n);
}

void *reallocarray(void *p, size_t n, size_t size)
{
	note(I_REALLOCARRAY);
	if (size && n > SIZE_MAX / size) {
		errno = ENOMEM;
		return NULL;
	}
	return __libc_realloc(p, n * size);
}

void free(void *p)
{
	note(I_FREE);
	__libc_free(p);
}

void *aligned_alloc(size_t align, size_t n)
{
	note(I_ALIGNED_ALLOC);
	return __libc_memalign(align, n);
}

int posix_memalign(void **out, size_t align, size_t n)
{
	void *p;

	note(I_POSIX_MEMALIGN);
	if (!align || (align & (align - 1)) || align % sizeof(void *))
		return EINVAL;
	p = __libc_memalign(align, n);
	if (!p)
		return ENOMEM;
	*out = p;
	return 0;
}

void *memalign(size_t align, size_t n)
{
	note(I_MEMALIGN);
	return __libc_memalign(align, n);
}

void *valloc(size_t n)
{
	note(I_VALLOC);
	return __libc_valloc(n);
}

void *pvalloc(size_t n)
{
	note(I_PVALLOC);
	return __libc_pvalloc(n);
}

/*
 * The real mapping calls come from dlsym(RTLD_NEXT).  dlsym may allocate
 * (its dlerror buffer): that reaches the malloc/calloc above, which go
 * straight to __libc_* and never back into dlsym, so there is no
 * recursion and no bootstrap buffer is needed.  glibc's own malloc maps
 * through internal aliases, not through these symbols (it is counted at
 * malloc already).  If dlsym cannot help, the raw system call does.
 */
typedef void *(*mmap_fn)(void *, size_t, int, int, int, off_t);
typedef int (*munmap_fn)(void *, size_t);
typedef void *(*mremap_fn)(void *, size_t, size_t, int, ...);
typedef int (*brk_fn)(void *);

static void *real(const char *name, _Atomic(void *) *slot)
{
	void *f = atomic_load(slot);

	if (!f) {
		f = dlsym(RTLD_NEXT, name);
		atomic_store(slot, f);
	}
	return f;
}

static _Atomic(void *) real_mmap, real_munmap, real_mremap, real_brk;

void *mmap(void *addr, size_t len, int prot, int flags, int fd, off_t off)
{
	mmap_fn f = (mmap_fn)real("mmap", &real_mmap);

	note(I_MMAP);
	if (f)
		return f(addr, len, prot, flags, fd, off);
	return (void *)syscall(SYS_mmap, addr, len, prot, flags, fd, off);
}

void *mmap64(void *addr, size_t len, int prot, int flags, int fd, off64_t off)
{
	mmap_fn f = (mmap_fn)real("mmap", &real_mmap);

	note(I_MMAP64);
	if (f)
		return f(addr, len, prot, flags, fd, (off_t)off);
	return (void *)syscall(SYS_mmap, addr, len, prot, flags, fd, off);
}

int munmap(void *addr, size_t len)
{
	munmap_fn f = (munmap_fn)real("munmap", &real_munmap);

	note(I_MUNMAP);
	if (f)
		return f(addr, len);
	return (int)syscall(SYS_munmap, addr, len);
}

void *mremap(void *old, size_t old_len, size_t new_len, int flags, ...)
{
	mremap_fn f = (mremap_fn)real("mremap", &real_mremap);
	void *new_addr = NULL;
	va_list ap;

	note(I_MREMAP);
	if (flags & MREMAP_FIXED) {
		va_start(ap, flags);
		new_addr = va_arg(ap, void *);
		va_end(ap);
	}
	if (f)
		return f(old, old_len, new_len, flags, new_addr);
	return (void *)syscall(SYS_mremap, old, old_len, new_len, flags, new_addr);
}

int brk(void *addr)
{
	brk_fn f = (brk_fn)real("brk", &real_brk);

	note(I_BRK);
	if (f)
		return f(addr);
	errno = ENOMEM;
	return -1;
}

void *sbrk(intptr_t inc)
{
	note(I_SBRK);
	return __sbrk(inc);
}
#endif /* !RT_ASAN */

/* ---- the real-time conditions (docs/architecture.md, "Memory and threading") ---- */

static bool locked;

/* Stack pre-faulted below the warm-up: the tick's frames never fault. */
#define STACK_PREFAULT (256 * 1024)

static void faults(long *minflt, long *majflt)
{
	struct rusage ru;

	assert_int_equal(getrusage(RUSAGE_THREAD, &ru), 0);
	*minflt = ru.ru_minflt;
	*majflt = ru.ru_majflt;
}

/* ---- images and the scenario ---- */

static char dir[64];
static struct irdm_image modal_img, fir_img, hybrid_img, clustered_img;

struct rig {
	const struct irdm_image *img;
	struct irdm_session *s; /* engine, deformation channel and worker */
	struct irdm_engine *e;  /* the session's */
	uint32_t push_row[4];   /* the push slides over these */
	int n_push;
	struct irdm_contact_site grab;
	bool grab_on_tri;
	uint64_t t; /* scenario time, ticks */
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	double *pos; /* the worker's frame, 3 n_nodes */
};

struct run_result {
	uint32_t magic;
	int prctl_errno; /* seccomp child: prctl failed */
	unsigned long ticks_ok, ticks_bad, slides, retouches;
	double max_f;
	bool all_finite;
	int nan_rc, nan_rc2; /* the NaN-target ticks */
	bool nan_zero_force;
	unsigned long alloc_calls; /* seccomp child: counted while armed */
};

#define RESULT_MAGIC 0x52545431u

static bool is_col(const struct irdm_image *img, uint32_t row)
{
	for (uint32_t c = 0; c < img->meta->n_cols; c++)
		if (img->columns[c] == row)
			return true;
	return false;
}

/*
 * The triangle with centroid nearest p whose vertices are all columns and
 * none of them in avoid[2] (a contact sharing a node with another makes
 * the coupled system singular).
 */
static int tri_near(const struct irdm_image *img, const double p[3], const uint32_t avoid[2],
		    uint32_t *tri)
{
	double best = INFINITY;
	int found = -1;

	for (uint32_t t = 0; t < img->meta->n_tris; t++) {
		const uint32_t *v = &img->tris[3 * t];
		double d = 0;
		bool ok = true;
		for (int k = 0; k < 3; k++)
			if (!is_col(img, v[k]) || v[k] == avoid[0] || v[k] == avoid[1])
				ok = false;
		if (!ok)
			continue;
		for (int a = 0; a < 3; a++) {
			double c = (img->nodes[v[0]].pos_m[a] + img->nodes[v[1]].pos_m[a] +
				    img->nodes[v[2]].pos_m[a]) /
				   3;
			d += (c - p[a]) * (c - p[a]);
		}
		if (d < best) {
			best = d;
			*tri = t;
			found = 0;
		}
	}
	return found;
}

/* Two contacts on the top face, at the columns nearest these points. */
static void rig_init(struct rig *r, const struct irdm_image *img)
{
	static const double push_at[2][3] = { { 0.035, 0.05, 0.2 }, { 0.05, 0.05, 0.2 } };
	const double grab_at[3] = { 0.07, 0.05, 0.2 };
	struct irdm_session_config sc = { .deform = true };
	char err[512];
	uint32_t tri = 0;

	memset(r, 0, sizeof(*r));
	r->img = img;
	r->pos = calloc(3 * (size_t)img->meta->n_nodes, sizeof(double));
	assert_non_null(r->pos);
	irdm_engine_config_haptic(&sc.engine, img->meta->dt_s, DEVICE_K, DEVICE_B, DEVICE_F);
	sc.engine.publish_every = PUBLISH_EVERY;
	if (irdm_session_open_image(&r->s, img, &sc, err, sizeof(err)) ||
	    irdm_session_deform_open(r->s, err, sizeof(err)))
		fail_msg("session: %s", err);
	r->e = r->s->eng;

	/* push: alternates between two neighbouring top nodes, so each slide
	 * lands on a new node */
	r->n_push = 0;
	for (int i = 0; i < 2; i++)
		r->push_row[r->n_push++] = efx_column_row_near(img, push_at[i]);
	assert_int_not_equal(r->push_row[0], r->push_row[1]);
	uint32_t g = efx_column_row_near(img, grab_at);
	assert_int_not_equal(g, r->push_row[0]);
	assert_int_not_equal(g, r->push_row[1]);
	/* grab: on a triangle point if all of some triangle is touchable */
	r->grab_on_tri = !tri_near(img, grab_at, r->push_row, &tri);
	if (r->grab_on_tri) {
		const double bary[3] = { 0.5, 0.3, 0.2 };
		assert_int_equal(irdm_engine_site_point(r->e, tri, bary, &r->grab), 0);
	} else {
		assert_int_equal(irdm_engine_site_node(r->e, g, &r->grab), 0);
	}
	print_message("  %s: %u rows, %u columns, %s, push slides over rows %u/%u, grab on %s\n",
		      img->meta->representation == IRDM_REPR_MODAL ? "modal" : "FIR",
		      img->meta->n_nodes, img->meta->n_cols,
		      img->corr_start ? "static correction" : "no static correction",
		      r->push_row[0], r->push_row[1], r->grab_on_tri ? "a triangle point" : "a node");
}

static void rig_free(struct rig *r)
{
	irdm_session_close(r->s);
	free(r->pos);
}

/*
 * One tick of the scenario.  Only what a real force loop does between two
 * ticks: slide the push to the next node every SLIDE_EVERY ticks (a new
 * site), re-touch a released push (softly: irdm_engine_contact_soften()),
 * set the targets.  No libc but sin().
 */
static int scenario_tick(struct rig *r, struct run_result *res)
{
	struct irdm_engine *e = r->e;
	struct irdm_contact_cmd *cmd = r->cmd;
	const struct irdm_contact_state *c0 = irdm_engine_contact(e, 0);
	double w = 2 * M_PI * (double)r->t * r->img->meta->dt_s; /* rad at 1 Hz */
	int rc;

	if (r->t % SLIDE_EVERY == 0 || c0->mode == IRDM_CONTACT_OFF) {
		bool was_off = c0->mode == IRDM_CONTACT_OFF;
		struct irdm_contact_site s;
		uint32_t row = r->push_row[(r->t / SLIDE_EVERY) % (uint64_t)r->n_push];
		if (irdm_engine_site_node(e, row, &s) ||
		    irdm_engine_contact_begin(e, 0, &s, IRDM_CONTACT_PUSH))
			return -1;
		/* a released push comes back with the tool inside: softly */
		if (was_off && irdm_engine_contact_soften(e, 0))
			return -1;
		if (r->t % SLIDE_EVERY == 0)
			res->slides++;
		else
			res->retouches++;
	}
	if (irdm_engine_contact(e, 1)->mode == IRDM_CONTACT_OFF &&
	    irdm_engine_contact_begin(e, 1, &r->grab, IRDM_CONTACT_GRAB))
		return -1;
	/* the push: 2..6 mm into the surface, stroking 1 mm sideways */
	const double *n0 = irdm_engine_contact(e, 0)->site.normal;
	double depth = 0.004 + 0.002 * sin(3 * w);
	cmd[0].mode = IRDM_CONTACT_PUSH;
	for (int a = 0; a < 3; a++)
		cmd[0].target_m[a] = -depth * n0[a];
	cmd[0].target_m[0] += 0.001 * sin(2 * w);
	/* the grab: pulled around a 3 mm Lissajous figure */
	cmd[1].mode = IRDM_CONTACT_GRAB;
	cmd[1].target_m[0] = 0.003 * sin(4 * w);
	cmd[1].target_m[1] = 0.003 * cos(3 * w);
	cmd[1].target_m[2] = 0.003 * sin(5 * w);
	r->t++;

	rc = irdm_engine_tick(e, cmd);
	if (rc) {
		res->ticks_bad++;
		return rc;
	}
	res->ticks_ok++;
	for (unsigned i = 0; i < 2; i++) {
		const double *f = irdm_engine_contact(e, i)->force_n;
		double f2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
		if (!isfinite(f2))
			res->all_finite = false;
		else if (f2 > res->max_f * res->max_f)
			res->max_f = sqrt(f2);
	}
	return 0;
}

static void run(struct rig *r, unsigned long n, struct run_result *res)
{
	for (unsigned long i = 0; i < n; i++)
		if (scenario_tick(r, res))
			return;
}

/* A NaN target: the engine faults (zero force) and stays faulted. */
static void nan_target(struct rig *r, struct run_result *res)
{
	r->cmd[1].target_m[1] = NAN;
	res->nan_rc = irdm_engine_tick(r->e, r->cmd);
	r->cmd[1].target_m[1] = 0;
	res->nan_rc2 = irdm_engine_tick(r->e, r->cmd);
	res->nan_zero_force = true;
	for (unsigned i = 0; i < IRDM_MAX_CONTACTS; i++) {
		const double *f = irdm_engine_contact(r->e, i)->force_n;
		if (f[0] != 0 || f[1] != 0 || f[2] != 0)
			res->nan_zero_force = false;
	}
}

/*
 * Before arming: every path of the scenario once (slides, re-touches, the
 * NaN fault and the reset out of it), then the stack, so that first-touch
 * faults are over.
 */
static void warm_up(struct rig *r)
{
	struct run_result warm = { .all_finite = true };

	run(r, N_WARMUP, &warm);
	nan_target(r, &warm);
	irdm_engine_reset(r->e);
	run(r, N_WARMUP, &warm);
	/* and the worker's code and scratch: its first update is not measured */
	irdm_deform_update(r->s->worker, r->pos, NULL);
	/* a refusal (no room on the stack) would show as page faults */
	irdm_rt_prefault_stack(STACK_PREFAULT);
	/* and the harness: its counters' first write is a fault too */
	arm();
	disarm();
}

static void check_result(const char *what, const struct run_result *res, unsigned long n)
{
	print_message("  %s: %lu ticks ok, %lu faulted, %lu slides, %lu re-touches, max |F| %.4f N\n",
		      what, res->ticks_ok, res->ticks_bad, res->slides, res->retouches, res->max_f);
	assert_int_equal(res->ticks_bad, 0);
	assert_int_equal(res->ticks_ok, n);
	assert_true(res->all_finite);
	/* the contacts did push and pull: not a test that passes by doing nothing */
	assert_true(res->max_f > 1e-3);
	assert_true(res->max_f < DEVICE_F);
	assert_true(res->slides >= n / SLIDE_EVERY - 1);
	assert_int_equal(res->nan_rc, IRDM_EFAULT);
	assert_int_equal(res->nan_rc2, IRDM_EFAULT);
	assert_true(res->nan_zero_force);
}

/* ---- proof 1 and 2: no allocation, no page fault ---- */

/* The worker's update of the newest snapshot, measured as the ticks are:
 * it allocates nothing after init either (its scratch, e.g. the clustered
 * correction's weights, is laid out then). */
struct update_result {
	bool updated, pos_finite;
	uint64_t tick;
	unsigned long ncalls;
	long minflt, majflt;
	char calls[256];
};

static void measured_update(struct rig *r, struct update_result *u)
{
	long min0, maj0, min1, maj1;

	memset(u, 0, sizeof(*u));
	arm();
	faults(&min0, &maj0);
	u->updated = irdm_deform_update(r->s->worker, r->pos, &u->tick);
	faults(&min1, &maj1);
	disarm();
	u->ncalls = calls_total();
	calls_text(u->calls, sizeof(u->calls));
	u->minflt = min1 - min0;
	u->majflt = maj1 - maj0;
	u->pos_finite = true;
	for (size_t i = 0; u->updated && i < 3 * (size_t)r->img->meta->n_nodes; i++)
		u->pos_finite = u->pos_finite && isfinite(r->pos[i]);
}

static void check_update(const struct update_result *u, uint64_t ticks)
{
	print_message("  deformation update: page faults minor %ld, major %ld\n", u->minflt,
		      u->majflt);
	if (!RT_ASAN)
		print_message("  deformation update: %lu allocator/mapping calls%s%s\n", u->ncalls,
			      u->ncalls ? ": " : "", u->calls);
	if (u->ncalls)
		fail_msg("the deformation update called the allocator or mapped memory: %s",
			 u->calls);
	if (u->minflt || u->majflt)
		fail_msg("the deformation update took page faults: %ld minor, %ld major",
			 u->minflt, u->majflt);
	/* the snapshots did go out: the newest is the last multiple of 16 */
	assert_true(u->updated);
	assert_true(u->pos_finite);
	assert_int_equal(u->tick % PUBLISH_EVERY, 0);
	assert_true(u->tick + PUBLISH_EVERY > ticks - 1); /* the newest, before the reset tick */
}

static void alloc_and_fault_free(const struct irdm_image *img)
{
	struct run_result res = { .all_finite = true };
	struct update_result upd;
	long min0, maj0, min1, maj1;
	unsigned long ncalls;
	char buf[256];
	struct rig r;

	rig_init(&r, img);
	warm_up(&r);

	arm();
	faults(&min0, &maj0);
	run(&r, N_TICKS, &res);
	nan_target(&r, &res);
	faults(&min1, &maj1);
	disarm();
	ncalls = calls_total();
	calls_text(buf, sizeof(buf));

	measured_update(&r, &upd);
	/* out of the fault */
	irdm_engine_reset(r.e);
	memset(r.cmd, 0, sizeof(r.cmd));
	int reset_rc = irdm_engine_tick(r.e, r.cmd);
	uint64_t ticks = irdm_engine_stats(r.e)->ticks;
	rig_free(&r); /* before any assertion: no leak on failure */

	check_result("armed", &res, N_TICKS);
	if (RT_ASAN)
		print_message("  allocator interposition skipped: built with AddressSanitizer, which owns malloc and mmap\n");
	else
		print_message("  allocator/mapping calls during %d ticks: %lu%s%s\n", N_TICKS, ncalls,
			      ncalls ? ": " : "", buf);
	print_message("  page faults during %d ticks: minor %ld, major %ld (memory %slocked)\n",
		      N_TICKS, min1 - min0, maj1 - maj0, locked ? "" : "NOT ");
	if (ncalls)
		fail_msg("the tick called the allocator or mapped memory: %s", buf);
	if (min1 != min0 || maj1 != maj0)
		fail_msg("the tick took page faults: %ld minor, %ld major (memory %slocked; a fault in the image mapping means the loader's MAP_POPULATE/touch did not hold)",
			 min1 - min0, maj1 - maj0, locked ? "" : "not ");
	check_update(&upd, ticks);
	assert_int_equal(reset_rc, IRDM_OK);
}

static void test_modal_alloc_and_fault_free(void **state)
{
	(void)state;
	alloc_and_fault_free(&modal_img);
}

static void test_fir_alloc_and_fault_free(void **state)
{
	(void)state;
	alloc_and_fault_free(&fir_img);
}

static void test_hybrid_alloc_and_fault_free(void **state)
{
	(void)state;
	alloc_and_fault_free(&hybrid_img);
}

static void test_clustered_alloc_and_fault_free(void **state)
{
	(void)state;
	alloc_and_fault_free(&clustered_img);
}

/* ---- proof 3: no system call ---- */

/* The ticks in seccomp strict mode (support/strict_mode.h). */
static void strict_child(void *arg, int fd)
{
	struct rig *r = arg;
	struct run_result res = { .magic = RESULT_MAGIC, .all_finite = true };

	/* faults are not system calls, but keep the measured part clean */
	warm_up(r);
	res.prctl_errno = strict_enter();
	if (res.prctl_errno)
		strict_exit(fd, &res, sizeof(res), STRICT_UNAVAILABLE);
	arm();
	run(r, N_TICKS, &res);
	nan_target(r, &res);
	disarm();
	res.alloc_calls = calls_total();
	strict_exit(fd, &res, sizeof(res), 0);
}

static void no_system_call(const struct irdm_image *img)
{
	struct run_result res;
	struct rig r;
	size_t got;
	int status;

	rig_init(&r, img);
	status = strict_run(strict_child, &r, &res, sizeof(res), &got);
	rig_free(&r);

	if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
		fail_msg("killed by SIGKILL in seccomp strict mode: the tick made a system call");
	if (WIFSIGNALED(status))
		fail_msg("the strict-mode child died of signal %d (%s)", WTERMSIG(status),
			 strsignal(WTERMSIG(status)));
	if (got == sizeof(res) && res.prctl_errno) {
		if (res.prctl_errno == EINVAL) {
			print_message("  seccomp strict mode not available in this kernel: skipped\n");
			skip();
		}
		fail_msg("prctl(PR_SET_SECCOMP, SECCOMP_MODE_STRICT): %s", strerror(res.prctl_errno));
	}
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 0);
	assert_int_equal(got, sizeof(res));
	assert_int_equal(res.magic, RESULT_MAGIC);
	check_result("seccomp strict", &res, N_TICKS);
	print_message("  %d ticks in seccomp strict mode: no system call%s\n", N_TICKS,
		      RT_ASAN ? "" : res.alloc_calls ? "" :
						       ", no allocator call");
	if (!RT_ASAN)
		assert_int_equal(res.alloc_calls, 0);
}

static void test_modal_no_system_call(void **state)
{
	(void)state;
	no_system_call(&modal_img);
}

static void test_fir_no_system_call(void **state)
{
	(void)state;
	no_system_call(&fir_img);
}

static void test_hybrid_no_system_call(void **state)
{
	(void)state;
	no_system_call(&hybrid_img);
}

static void test_clustered_no_system_call(void **state)
{
	(void)state;
	no_system_call(&clustered_img);
}

/* The harness can fail: a system call in strict mode does kill the child. */
static void slip_child(void *arg, int fd)
{
	int e = strict_enter();

	(void)arg;
	if (e)
		strict_exit(fd, &e, sizeof(e), STRICT_UNAVAILABLE);
	syscall(SYS_getppid);
	strict_exit(fd, &e, sizeof(e), 0);
}

static void test_strict_mode_catches_a_system_call(void **state)
{
	int status, e;
	size_t got;

	(void)state;
	status = strict_run(slip_child, NULL, &e, sizeof(e), &got);
	if (WIFEXITED(status) && WEXITSTATUS(status) == STRICT_UNAVAILABLE) {
		print_message("  seccomp strict mode not available (errno %d): skipped\n", e);
		skip();
	}
	assert_true(WIFSIGNALED(status));
	assert_int_equal(WTERMSIG(status), SIGKILL);
}

/* ---- the interposers themselves ---- */

/* Each interposer counts when armed (called through volatile pointers so
 * that the compiler cannot elide a malloc/free pair). */
static void test_interposers_count(void **state)
{
	void *(*volatile m)(size_t) = malloc;
	void *(*volatile c)(size_t, size_t) = calloc;
	void *(*volatile re)(void *, size_t) = realloc;
	void *(*volatile al)(size_t, size_t) = aligned_alloc;
	int (*volatile pm)(void **, size_t, size_t) = posix_memalign;
	void (*volatile fr)(void *) = free;
	char buf[256];
	void *p, *q;

	(void)state;
	if (RT_ASAN) {
		print_message("  built with AddressSanitizer: the allocator is not interposed (ASan owns it)\n");
		skip();
	}
	arm();
	p = m(100);
	p = re(p, 100000);
	fr(p);
	p = c(10, 10);
	fr(p);
	p = al(64, 128);
	fr(p);
	assert_int_equal(pm(&q, 64, 256), 0);
	fr(q);
	p = mmap(NULL, 65536, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	assert_true(p != MAP_FAILED);
	p = mremap(p, 65536, 131072, MREMAP_MAYMOVE);
	assert_true(p != MAP_FAILED);
	assert_int_equal(munmap(p, 131072), 0);
	assert_true(sbrk(0) != (void *)-1);
	disarm();
	print_message("  counted: %s\n", calls_text(buf, sizeof(buf)));
	assert_int_equal(atomic_load(&calls[I_MALLOC]), 1);
	assert_int_equal(atomic_load(&calls[I_REALLOC]), 1);
	assert_int_equal(atomic_load(&calls[I_CALLOC]), 1);
	assert_int_equal(atomic_load(&calls[I_ALIGNED_ALLOC]), 1);
	assert_int_equal(atomic_load(&calls[I_POSIX_MEMALIGN]), 1);
	assert_int_equal(atomic_load(&calls[I_FREE]), 4);
	assert_int_equal(atomic_load(&calls[I_MMAP]), 1);
	assert_int_equal(atomic_load(&calls[I_MREMAP]), 1);
	assert_int_equal(atomic_load(&calls[I_MUNMAP]), 1);
	assert_int_equal(atomic_load(&calls[I_SBRK]), 1);
	/* and nothing while disarmed */
	p = m(100);
	fr(p);
	assert_int_equal(atomic_load(&calls[I_MALLOC]), 1);
}

/* ---- fixture ---- */

static int setup(void **state)
{
	char p1[128], p2[128];

	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/irdm-rt-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(p1, sizeof(p1), "%s/modal.img", dir);
	snprintf(p2, sizeof(p2), "%s/fir.img", dir);
	/* 300 modes + static correction, the whole top face touchable */
	efx_image(&modal_img, p1, "resolution", "6,6,12", "representation", "modal:300",
		  "static_correction", "yes", "touch", "z>=0.2", "display", "surface", NULL);
	/*
	 * FIR T = 500.  The precompute's stability check costs ~10 s per
	 * column at T = 500, so only four nodes of the top face along y = 5 cm
	 * (x = 3.3 .. 8.3 cm) are touchable.
	 */
	efx_image(&fir_img, p2, "resolution", "6,6,12", "representation", "fir:500", "uncertified", "yes",
		  "touch", "box:0.03,0.049,0.199,0.09,0.051,0.201", "display", "touch", NULL);
	/* the hybrid: 300 modes and the other 1464's exact head (32 + 32
	 * samples: the head's ring and sums), the top face touchable */
	snprintf(p2, sizeof(p2), "%s/hybrid.img", dir);
	efx_image(&hybrid_img, p2, "resolution", "6,6,12", "representation", "modal:300",
		  "exact_head", "32", "touch", "z>=0.2", "display", "touch", NULL);
	/* the clustered correction: clusters of at most 8 of the top face's
	 * columns, so that the contacts' blocks come from dense and low-rank
	 * pairs */
	snprintf(p2, sizeof(p2), "%s/clustered.img", dir);
	efx_image(&clustered_img, p2, "resolution", "6,6,12", "representation", "modal:300",
		  "static_correction_cluster", "8", "static_correction_tol", "1e-3", "touch", "z>=0.2",
		  "display", "touch", NULL);
	if (!clustered_img.corr_clusters)
		return -1;
	/*
	 * Lock what is mapped and what will be.  Best effort: without it the
	 * fault check can still pass on an idle machine, and says "NOT
	 * locked".  Under ASan it is not supported (ASan's mlockall does
	 * nothing) and its shadow memory is not ours to lock.
	 */
	int rc = irdm_rt_lock_memory();

	/* the deformation thread's BLAS threads, as a caller of
	 * irdm_deform_update() sets them (irdm/posix/deform_worker.h) */
	openblas_set_num_threads(IRDM_DEFORM_BLAS_THREADS);

	locked = rc == IRDM_OK;
	if (!locked)
		print_message("mlockall: %s: the page fault check runs without locked memory\n",
			      irdm_strerror(rc));
	return 0;
}

static int teardown(void **state)
{
	char cmd[128];

	(void)state;
	if (locked)
		irdm_rt_unlock_memory();
	irdm_image_unmap(&modal_img);
	irdm_image_unmap(&fir_img);
	irdm_image_unmap(&hybrid_img);
	irdm_image_unmap(&clustered_img);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	return system(cmd) ? -1 : 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_interposers_count),
		cmocka_unit_test(test_strict_mode_catches_a_system_call),
		cmocka_unit_test(test_modal_alloc_and_fault_free),
		cmocka_unit_test(test_fir_alloc_and_fault_free),
		cmocka_unit_test(test_modal_no_system_call),
		cmocka_unit_test(test_fir_no_system_call),
		cmocka_unit_test(test_hybrid_alloc_and_fault_free),
		cmocka_unit_test(test_hybrid_no_system_call),
		cmocka_unit_test(test_clustered_alloc_and_fault_free),
		cmocka_unit_test(test_clustered_no_system_call),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
