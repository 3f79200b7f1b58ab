/* SPDX-License-Identifier: MIT */
/*
 * Whether the AVX2 + FMA history sums (fir_sum_avx2.c, engine_head_avx2.c)
 * may run on this processor: asked once at engine init, never in the tick.
 * Its own file because every build configuration needs it, FIR or not.
 */
#include <stdbool.h>

#include "engine_priv.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>

/*
 * AVX2, FMA and F16C from CPUID, and the YMM state enabled by the kernel
 * (OSXSAVE, then XCR0's SSE and AVX bits).  By hand rather than with
 * __builtin_cpu_supports(): clang 14 does not know "f16c" there.
 */
bool irdm_wide_usable(void)
{
	unsigned a, b, c, d, xcr0_lo, xcr0_hi;

	if (!__get_cpuid(1, &a, &b, &c, &d))
		return false;
	bool fma = c & (1u << 12), osxsave = c & (1u << 27), avx = c & (1u << 28),
	     f16c = c & (1u << 29);
	if (!(fma && osxsave && avx && f16c))
		return false;
	__asm__ volatile("xgetbv"
			 : "=a"(xcr0_lo), "=d"(xcr0_hi)
			 : "c"(0));
	if ((xcr0_lo & 6) != 6)
		return false;
	if (!__get_cpuid_count(7, 0, &a, &b, &c, &d))
		return false;
	return b & (1u << 5); /* AVX2 */
}

#else

bool irdm_wide_usable(void)
{
	return false;
}

#endif
