/* SPDX-License-Identifier: MIT */
/*
 * The loader of the slepc plugin (dist_ops.h says why a plugin): found
 * beside the executable (or its parent directory, for the test binaries)
 * or at IRDM_SLEPC_PLUGIN, loaded on the first call that needs it.
 * Without it, one rank, and the slepc eigensolver says it is not built in.
 */
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "dist/dist.h"
#include "dist/dist_ops.h"

static const struct irdm_dist_ops *ops;
static bool tried;
static char why_not[256] = "not built in";

static void *open_beside_exe(const char *up)
{
	char path[PATH_MAX];
	ssize_t len = readlink("/proc/self/exe", path, sizeof(path) - 1);
	char *slash;

	if (len <= 0)
		return NULL;
	path[len] = '\0';
	slash = strrchr(path, '/');
	if (!slash)
		return NULL;
	slash[1] = '\0';
	if (strlen(path) + strlen(up) + sizeof(IRDM_SLEPC_PLUGIN) > sizeof(path))
		return NULL;
	strcat(path, up);
	strcat(path, IRDM_SLEPC_PLUGIN);
	return access(path, R_OK) ? NULL : dlopen(path, RTLD_NOW | RTLD_LOCAL);
}

static const struct irdm_dist_ops *load(void)
{
	const char *env = getenv("IRDM_SLEPC_PLUGIN");
	irdm_slepc_plugin_fn entry;
	void *h;

	if (tried)
		return ops;
	tried = true;
	h = env ? dlopen(env, RTLD_NOW | RTLD_LOCAL) : open_beside_exe("");
	if (!h && !env)
		h = open_beside_exe("../");
	if (!h) {
		const char *e = dlerror();
		snprintf(why_not, sizeof(why_not), "not built in (%s%s)",
			 e ? e : IRDM_SLEPC_PLUGIN " is not beside irdm",
			 e ? "" : "; install petsc-dev slepc-dev and rebuild");
		return NULL;
	}
	*(void **)&entry = dlsym(h, IRDM_SLEPC_PLUGIN_ENTRY);
	ops = entry ? entry() : NULL;
	if (!ops || ops->version != IRDM_DIST_OPS_VERSION) {
		snprintf(why_not, sizeof(why_not), "%s is not this irdm's plugin", IRDM_SLEPC_PLUGIN);
		ops = NULL;
	}
	/* the handle stays open: PETSc's libraries live until exit */
	return ops;
}

bool irdm_dist_built_in(void)
{
	return load() != NULL;
}

int irdm_dist_begin(char *err, size_t errlen)
{
	if (!load()) {
		snprintf(err, errlen, "slepc: %s", why_not);
		return IRDM_EINVAL;
	}
	return ops->begin(err, errlen);
}

void irdm_dist_end(void)
{
	if (ops)
		ops->end();
}

int irdm_dist_rank(void)
{
	return ops ? ops->rank() : 0;
}

int irdm_dist_size(void)
{
	return ops ? ops->size() : 1;
}

unsigned irdm_dist_threads(void)
{
	long cpus;

	if (ops)
		return ops->threads();
	cpus = sysconf(_SC_NPROCESSORS_ONLN);
	return cpus > 0 ? (unsigned)cpus : 1;
}

void irdm_dist_abort(const char *cmd, int code, const char *reason)
{
	char line[1400];

	if (!ops || ops->size() < 2)
		return;
	snprintf(line, sizeof(line), "irdm %s: rank %d of %d: %s: %s", cmd, ops->rank(),
		 ops->size(), irdm_errname(code), reason);
	ops->abort(line);
}

void irdm_dist_wait_all(void)
{
	if (ops)
		ops->wait_all();
}

int irdm_dist_gather(const double *mine, const size_t *counts, double *all,
		     char *err, size_t errlen)
{
	if (ops)
		return ops->gather(mine, counts, all, err, errlen);
	if (counts[0])
		memmove(all, mine, counts[0] * sizeof(double));
	return IRDM_OK;
}

bool irdm_dist_fault(const char *where)
{
	return irdm_dist_fault_at(irdm_dist_rank(), where);
}

int irdm_eig_slepc(const struct irdm_fem *fem, size_t n_lowest, double sigma,
		   const struct irdm_modes_want *want, size_t n_whole,
		   irdm_progress_fn progress, void *ctx, double *w2, double *phi,
		   double *compliance, char *err, size_t errlen)
{
	int ret = irdm_dist_begin(err, errlen);

	return ret ? ret : ops->eig(fem, n_lowest, sigma, want, n_whole, progress, ctx, w2, phi, compliance, err, errlen);
}
