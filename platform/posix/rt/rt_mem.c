/* SPDX-License-Identifier: MIT */
/*
 * Memory that never faults in a loop: lock it all, and touch the stack the
 * loop will use before the loop starts.
 */
#define _GNU_SOURCE
#include <alloca.h>
#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <sys/mman.h>

#include "irdm/posix/rt.h"

#if IRDM_RT_ASAN
#include <sanitizer/asan_interface.h>
#endif

/* What irdm_rt_prefault_stack() keeps free below the touched depth: its own
 * frames and a signal frame. */
#define STACK_MARGIN (16 * 1024)
/* one write per stride; below any page size, so every page is written */
#define TOUCH_STRIDE 1024

int irdm_rt_lock_memory(void)
{
#if IRDM_RT_ASAN
	/* ASan's mlockall returns 0 and locks nothing: do not pretend */
	return IRDM_ENOTSUP;
#else
	if (!mlockall(MCL_CURRENT | MCL_FUTURE))
		return IRDM_OK;
	/* EPERM: no CAP_IPC_LOCK and no RLIMIT_MEMLOCK; ENOMEM: above that limit */
	return errno == EINVAL ? IRDM_EINVAL : IRDM_EPERM;
#endif
}

void irdm_rt_unlock_memory(void)
{
	munlockall();
}

/* Bytes of the calling thread's stack below this frame, guard page excluded. */
static int stack_left(size_t *left)
{
	uintptr_t here = (uintptr_t)__builtin_frame_address(0), lo;
	pthread_attr_t a;
	size_t size, guard = 0;
	void *addr;
	int rc = IRDM_EIO;

	/* the main thread's bounds come from /proc/self/maps and RLIMIT_STACK */
	if (pthread_getattr_np(pthread_self(), &a))
		return IRDM_EIO;
	if (pthread_attr_getstack(&a, &addr, &size))
		goto destroy;
	pthread_attr_getguardsize(&a, &guard);
	lo = (uintptr_t)addr + guard;
	*left = here > lo ? here - lo : 0;
	rc = IRDM_OK;
destroy:
	pthread_attr_destroy(&a);
	return rc;
}

/* In a frame of its own, so that the block is below the caller's frames. */
static __attribute__((noinline)) void touch_stack(size_t depth_bytes)
{
	unsigned char *block = alloca(depth_bytes);
	volatile unsigned char *p = block;

	/* top down, the way the stack grows */
	for (size_t i = depth_bytes; i > 0; i = i > TOUCH_STRIDE ? i - TOUCH_STRIDE : 0)
		p[i - 1] = 0;
	p[0] = 0;
#if IRDM_RT_ASAN
	/*
	 * The instrumented writes above only read the block's shadow (mapping
	 * the shared zero page); the first redzone a deeper frame poisons there
	 * would be a copy-on-write fault.  Write the shadow too.
	 */
	__asan_poison_memory_region(block, depth_bytes);
	__asan_unpoison_memory_region(block, depth_bytes);
#endif
}

int irdm_rt_prefault_stack(size_t depth_bytes)
{
	size_t left;
	int rc;

	if (!depth_bytes)
		return IRDM_OK;
	rc = stack_left(&left);
	if (rc)
		return rc;
	/* refused rather than a SIGSEGV past the guard page */
	if (left < STACK_MARGIN || depth_bytes > left - STACK_MARGIN)
		return IRDM_EINVAL;
	touch_stack(depth_bytes);
	return IRDM_OK;
}
