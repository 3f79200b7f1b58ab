/* SPDX-License-Identifier: MIT */
/*
 * The memory a tool may plan for: the machine's physical memory, lowered
 * by the process's address-space and data limits (ulimit -v, ulimit -d)
 * when set, and by the scene's max_memory_mib.  A step that would need more is refused before it starts:
 * on Linux a large malloc() succeeds on overcommitted memory and the
 * kernel kills the process later, hours into a dense eigensolve.
 */
#ifndef IRDM_TOOLS_MEMORY_H
#define IRDM_TOOLS_MEMORY_H

/* Lower the budget to bytes for the rest of the process ("max_memory_mib",
 * the scene's); 0: no cap of its own. */
void irdm_memory_cap(double bytes);

/* The budget in bytes, and in *what (static text) where it comes from:
 * "physical memory", "ulimit -v", "ulimit -d" or "max_memory_mib".  0 if unknown. */
double irdm_memory_budget(const char **what);

#endif
