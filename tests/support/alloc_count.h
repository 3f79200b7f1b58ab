/* SPDX-License-Identifier: MIT */
/*
 * Count the allocator calls a stretch of code makes: include this header
 * in ONE file of a test executable (it defines malloc and friends, which
 * the executable then interposes for every library it links), call
 * alloc_arm() before the stretch and alloc_calls() after it.
 *
 * glibc lets the executable define the allocator (its own calls inside
 * libc go through the interposable symbol too); forwarding to the __libc_*
 * entry points keeps every block in glibc's one heap.  Under
 * AddressSanitizer (IRDM_RT_ASAN) nothing is interposed -- ASan owns the
 * allocator -- and alloc_counting() says so.  Mappings are not counted
 * here: the strict-mode child (seccomp) kills any mmap/brk.
 */
#ifndef IRDM_TESTS_ALLOC_COUNT_H
#define IRDM_TESTS_ALLOC_COUNT_H

#include <errno.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/posix/rt.h"

static atomic_bool alloc_armed;
static atomic_ulong alloc_n;

static void alloc_arm(void)
{
	atomic_store(&alloc_n, 0);
	atomic_store(&alloc_armed, true);
}

static unsigned long alloc_calls(void)
{
	atomic_store(&alloc_armed, false);
	return atomic_load(&alloc_n);
}

#if !IRDM_RT_ASAN
static bool alloc_counting(void)
{
	return true;
}

void *__libc_malloc(size_t n);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t n);
void __libc_free(void *p);
void *__libc_memalign(size_t align, size_t n);

static inline void alloc_note(void)
{
	if (atomic_load_explicit(&alloc_armed, memory_order_relaxed))
		atomic_fetch_add_explicit(&alloc_n, 1, memory_order_relaxed);
}

void *malloc(size_t n)
{
	alloc_note();
	return __libc_malloc(n);
}

void *calloc(size_t n, size_t size)
{
	alloc_note();
	return __libc_calloc(n, size);
}

void *realloc(void *p, size_t n)
{
	alloc_note();
	return __libc_realloc(p, n);
}

void free(void *p)
{
	alloc_note();
	__libc_free(p);
}

void *aligned_alloc(size_t align, size_t n)
{
	alloc_note();
	return __libc_memalign(align, n);
}

void *memalign(size_t align, size_t n)
{
	alloc_note();
	return __libc_memalign(align, n);
}

int posix_memalign(void **out, size_t align, size_t n)
{
	void *p;

	alloc_note();
	if (!align || (align & (align - 1)) || align % sizeof(void *))
		return EINVAL;
	p = __libc_memalign(align, n);
	if (!p)
		return ENOMEM;
	*out = p;
	return 0;
}
#else
static bool alloc_counting(void)
{
	return false;
}
#endif /* !IRDM_RT_ASAN */

#endif /* IRDM_TESTS_ALLOC_COUNT_H */
