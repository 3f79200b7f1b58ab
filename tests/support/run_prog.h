/* SPDX-License-Identifier: MIT */
/* Run a program of the build and keep what it said (tests; cmocka inside). */
#ifndef IRDM_TESTS_RUN_PROG_H
#define IRDM_TESTS_RUN_PROG_H

#include <stddef.h>
#include <sys/types.h>

/*
 * prog with args (NULL-terminated, at most 38), its stdout and stderr kept
 * in dir/stdout and dir/stderr and read back into out and err (either may
 * be NULL).  Return: the exit status, or 128 + the signal that killed it.
 */
int rp_run(const char *dir, const char *prog, const char *const *args, char *out,
	   size_t outlen, char *err, size_t errlen);

/* The same in two steps, for a caller that acts while it runs (a signal). */
pid_t rp_spawn(const char *dir, const char *prog, const char *const *args);
int rp_finish(const char *dir, pid_t pid, char *out, size_t outlen, char *err, size_t errlen);

#endif
