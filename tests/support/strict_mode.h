/* SPDX-License-Identifier: MIT */
/*
 * Run a stretch of code where a system call kills it: a forked child
 * enters seccomp strict mode (from prctl() on it may only read, write,
 * _exit and sigreturn; a system call is SIGKILL) and reports a result
 * struct through a pipe.  Used by the real-time proofs (test_engine_nosys,
 * test_controller).
 *
 * The child is single-threaded (fork copies the calling thread only) and
 * must not return: it reports with strict_exit() (SYS_exit: exit() would
 * run atexit handlers and exit_group, both forbidden).  No cmocka in the
 * child.
 */
#ifndef IRDM_TESTS_STRICT_MODE_H
#define IRDM_TESTS_STRICT_MODE_H

#include <stddef.h>

/* Child exit codes besides 0 (and SIGKILL for a system call). */
#define STRICT_UNAVAILABLE 2 /* prctl() refused strict mode: the result says why */
#define STRICT_WRITE_FAILED 4

/*
 * Fork; the child runs child(arg, fd) with fd the pipe's write end.  The
 * parent reads up to len bytes of result into res (zeroed first; *got says
 * how many came), then waits.
 * Return: the child's wait status (waitpid()).
 */
int strict_run(void (*child)(void *arg, int fd), void *arg, void *res, size_t len,
	       size_t *got);

/*
 * In the child: crash signals back to their defaults (a crash must not
 * look like a kill), then strict mode.
 * Return: 0 in strict mode, else prctl()'s errno (the child should put it
 * in its result and leave with strict_exit(..., STRICT_UNAVAILABLE)).
 */
int strict_enter(void);

/*
 * In the child: write the result and leave with code (SYS_exit).  It does
 * not return, but is not declared noreturn: AddressSanitizer calls
 * sigaltstack() before a call to a noreturn function, a system call that
 * strict mode would kill.
 */
void strict_exit(int fd, const void *res, size_t len, int code);

#endif
