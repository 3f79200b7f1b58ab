/* SPDX-License-Identifier: MIT */
/*
 * The slepc plugin's MPI side: PETSc and SLEPc started and stopped, the
 * rank, the abort that stops every rank, the idle wait, the gather; and
 * the table the loader (tools/dist/dist.c) takes.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "dist/plugin/plugin.h"
#include "modal/lapack.h"

static int rank_now;
static int size_now = 1;
static unsigned threads_now;

int irdm_mpi_rank(void)
{
	return rank_now;
}

int irdm_mpi_size(void)
{
	return size_now;
}

static unsigned machine_cores(void)
{
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);

	return cpus > 0 ? (unsigned)cpus : 1;
}

static unsigned mpi_threads(void)
{
	return threads_now ? threads_now : machine_cores();
}

bool irdm_mpi_fault(const char *where)
{
	return irdm_dist_fault_at(rank_now, where);
}

#include <slepcsys.h>

/*
 * The sanitizer build: OpenMPI leaks by design in plugins it unloads (some
 * within MPI_Init, the rest at MPI_Finalize), whose frames then cannot be
 * named, so no suppression could tell them from ours.  So MPI_Init's
 * allocations are not leak-checked, and the leak check runs before
 * MPI_Finalize, while the plugins are loaded: tests/lsan-mpi.supp names
 * MPI's libraries (never ours, nor PETSc's), and LSAN_OPTIONS=
 * leak_check_at_exit=0 skips the unnamed check at exit.
 */
#if defined(__SANITIZE_ADDRESS__)
#define IRDM_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define IRDM_LSAN 1
#endif
#endif
#ifdef IRDM_LSAN
#include <sanitizer/lsan_interface.h>
#define leak_check_before_finalize() __lsan_do_leak_check()
#define leaks_ignored_begin() __lsan_disable()
#define leaks_ignored_end() __lsan_enable()
#else
#define leak_check_before_finalize() ((void)0)
#define leaks_ignored_begin() ((void)0)
#define leaks_ignored_end() ((void)0)
#endif

static bool started;

/* Ranks sharing this machine, to split its cores between them. */
static int ranks_on_this_machine(void)
{
	MPI_Comm node;
	int n = 1;

	if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node))
		return 1;
	MPI_Comm_size(node, &n);
	MPI_Comm_free(&node);
	return n > 0 ? n : 1;
}

int irdm_mpi_begin(char *err, size_t errlen)
{
	unsigned per_rank;
	bool ok;

	if (started)
		return IRDM_OK;
	/* our own crash reports stay ours (and the sanitizers'): PETSc's
	 * handler would catch SIGSEGV and SIGFPE */
	leaks_ignored_begin();
	ok = !PetscOptionsSetValue(NULL, "-no_signal_handler", NULL) &&
	     !SlepcInitialize(NULL, NULL, NULL, NULL);
	leaks_ignored_end();
	if (!ok) {
		snprintf(err, errlen, "slepc: PETSc/SLEPc failed to start (MPI_Init?)");
		return IRDM_ENUMERIC;
	}
	/* errors come back as codes, reported once with the rank by the
	 * caller, not as PETSc's tracebacks on every rank */
	PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
	started = true;
	MPI_Comm_rank(MPI_COMM_WORLD, &rank_now);
	MPI_Comm_size(MPI_COMM_WORLD, &size_now);
	per_rank = machine_cores() / (unsigned)ranks_on_this_machine();
	threads_now = per_rank ? per_rank : 1;
	if ((unsigned)openblas_get_num_threads() > threads_now)
		openblas_set_num_threads((int)threads_now);
	return IRDM_OK;
}

static void mpi_end(void)
{
	if (!started)
		return;
	PetscPopErrorHandler();
	leak_check_before_finalize();
	SlepcFinalize();
	started = false;
	rank_now = 0;
	size_now = 1;
	threads_now = 0;
}

static void mpi_abort(const char *line)
{
	if (!started || size_now < 2)
		return;
	fprintf(stderr, "%s\n", line);
	fflush(stderr);
	MPI_Abort(MPI_COMM_WORLD, 1);
	_exit(1); /* MPI_Abort does not return; if it did, still stop */
}

static void mpi_wait_all(void)
{
	const struct timespec nap = { 0, 2000000 }; /* 2 ms */
	MPI_Request req;
	int done = 0;

	if (!started || size_now < 2)
		return;
	if (MPI_Ibarrier(MPI_COMM_WORLD, &req))
		return;
	while (!done && !MPI_Test(&req, &done, MPI_STATUS_IGNORE))
		if (!done)
			nanosleep(&nap, NULL);
}

static int mpi_gather(const double *mine, const size_t *counts, double *all,
		      char *err, size_t errlen)
{
	int *cnt = NULL, *off = NULL, ret = IRDM_ENUMERIC;
	size_t total = 0;

	if (!started || size_now < 2) {
		if (counts[0])
			memmove(all, mine, counts[0] * sizeof(double));
		return IRDM_OK;
	}
	cnt = malloc((size_t)size_now * sizeof(int));
	off = malloc((size_t)size_now * sizeof(int));
	if (!cnt || !off) {
		snprintf(err, errlen, "gather: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	for (int r = 0; r < size_now; r++) {
		/* MPI counts are int: a block beyond 2^31 doubles must be split by
		 * more ranks (16 GiB a rank) */
		if (counts[r] > 0x7fffffff || total > 0x7fffffff - counts[r]) {
			snprintf(err, errlen, "gather: %zu doubles from rank %d exceed MPI's int counts: use more ranks",
				 counts[r], r);
			ret = IRDM_ERANGE;
			goto out_free;
		}
		cnt[r] = (int)counts[r];
		off[r] = (int)total;
		total += counts[r];
	}
	if (MPI_Gatherv(mine, cnt[rank_now], MPI_DOUBLE, all, cnt, off, MPI_DOUBLE, 0,
			MPI_COMM_WORLD)) {
		snprintf(err, errlen, "gather: MPI_Gatherv failed");
		goto out_free;
	}
	ret = IRDM_OK;
out_free:
	free(cnt);
	free(off);
	return ret;
}

static const struct irdm_dist_ops ops = {
	.version = IRDM_DIST_OPS_VERSION,
	.begin = irdm_mpi_begin,
	.end = mpi_end,
	.rank = irdm_mpi_rank,
	.size = irdm_mpi_size,
	.threads = mpi_threads,
	.abort = mpi_abort,
	.wait_all = mpi_wait_all,
	.gather = mpi_gather,
	.eig = irdm_slepc_eig,
};

__attribute__((visibility("default"))) const struct irdm_dist_ops *irdm_slepc_plugin(void);

const struct irdm_dist_ops *irdm_slepc_plugin(void)
{
	return &ops;
}
