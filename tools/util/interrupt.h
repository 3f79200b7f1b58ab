/* SPDX-License-Identifier: MIT */
/*
 * An interrupted tool leaves nothing behind.  A tool registers what it
 * must not leave: a temporary file, a temporary directory of files, a
 * child's process group.  On SIGINT, SIGTERM or SIGHUP the handler removes
 * the temporaries, sends SIGTERM to the groups, then lets the signal kill
 * the tool, so its exit status names the signal (128 + N in a shell).  A
 * signal the tool was started with ignored (nohup, a background job) stays
 * ignored.  The handler calls only async-signal-safe functions.  At most
 * IRDM_INTERRUPT_SLOTS things at a time; registering is thread-safe.
 */
#ifndef IRDM_TOOLS_INTERRUPT_H
#define IRDM_TOOLS_INTERRUPT_H

#include <sys/types.h>

#define IRDM_INTERRUPT_SLOTS 16

enum irdm_interrupt_kind {
	IRDM_INTERRUPT_FILE = 1, /* unlink the path */
	IRDM_INTERRUPT_DIR,      /* remove the files in the path, then it */
	IRDM_INTERRUPT_PGROUP,   /* kill(-pgid, SIGTERM) */
};

/* Register; the handlers are installed on the first call.  Return: the
 * slot (>= 0) for irdm_interrupt_del(), or -1 if all are taken or the
 * path is too long (the thing is then not cleaned on a signal). */
int irdm_interrupt_add(enum irdm_interrupt_kind kind, const char *path, pid_t pgid);

/* Forget slot (done with it: removed, renamed into place, reaped).  A
 * negative slot is ignored. */
void irdm_interrupt_del(int slot);

#endif
