/* SPDX-License-Identifier: MIT */
/*
 * Real-time set-up, in one place for every loop that must not be late: the
 * deformation thread, the benches, the tests and the 1 kHz controller.
 * docs/architecture.md ("Memory and threading") says why each step exists:
 * locked memory and a pre-faulted stack so that the loop never takes a page
 * fault, an explicit scheduling policy so that a thread never inherits one
 * by accident, and a report read back from the system so that a program
 * never claims real time it did not get.
 *
 * Only the sleep and the timespec helpers are meant for inside a loop; the
 * rest is init-time (it may allocate, read /proc and make system calls).
 * Linux (glibc) only: the module uses the _np thread calls and /proc.
 */
#ifndef IRDM_RT_H
#define IRDM_RT_H

#include <pthread.h>
#include <sched.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#include <time.h>

#include "irdm/error.h"

#define IRDM_RT_ANY_CPU (-1)
/*
 * Every online CPU but n: where a helper thread (deformation, log writer)
 * goes when the force thread owns CPU n, so that it neither shares that
 * CPU's caches nor needs it to run.  On a one-CPU machine it is any CPU.
 * Encoded below -1 (n >= 0): IRDM_RT_CPU_EXCEPT(0) is -2.
 */
#define IRDM_RT_CPU_EXCEPT(n) (-2 - (n))

/*
 * 1 in a build with AddressSanitizer, whose mlockall() locks nothing (so
 * irdm_rt_lock_memory() says IRDM_ENOTSUP) and which owns the allocator and
 * the stack's shadow: what a real-time check can prove differs there.
 */
#if defined(__SANITIZE_ADDRESS__)
#define IRDM_RT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define IRDM_RT_ASAN 1
#endif
#endif
#ifndef IRDM_RT_ASAN
#define IRDM_RT_ASAN 0
#endif

/* How a thread is to be scheduled. */
struct irdm_rt_sched {
	int policy;   /* SCHED_FIFO or SCHED_OTHER */
	int priority; /* SCHED_FIFO: 1..99; SCHED_OTHER: 0 */
	int cpu;      /* the one CPU it may run on, IRDM_RT_ANY_CPU or IRDM_RT_CPU_EXCEPT(n) */
};

/* What the system granted, read back by irdm_rt_report_get(). */
struct irdm_rt_report {
	bool preempt_rt;         /* the kernel is PREEMPT_RT */
	int policy;              /* the calling thread's, -1 if unknown */
	int priority;            /* its static priority (0 outside SCHED_FIFO/RR) */
	int cpu;                 /* the CPU it ran on during the call, -1 if unknown */
	uint64_t cpu_mask;       /* its affinity, CPUs 0..63: bit n is CPU n */
	unsigned n_cpus;         /* CPUs in its affinity (any number), 0 if unknown */
	bool memory_locked;      /* everything mapped is locked (VmLck covers VmSize) */
	unsigned long locked_kb; /* VmLck of /proc/self/status */
	unsigned long mapped_kb; /* VmSize */
};

/* ---- memory ---- */

/*
 * Lock every page mapped now and every page mapped later
 * (mlockall(MCL_CURRENT | MCL_FUTURE)): with MCL_FUTURE the kernel
 * populates each new mapping as it is made, so later allocations do not
 * fault either and the heap needs no pre-faulting of its own.  Process-wide.
 *
 * Return: IRDM_OK; IRDM_EPERM if the system refused (no CAP_IPC_LOCK and
 * RLIMIT_MEMLOCK too small; part of the memory may then be locked);
 * IRDM_ENOTSUP under AddressSanitizer, whose mlockall does nothing;
 * IRDM_EINVAL if the kernel rejects the flags.
 */
int irdm_rt_lock_memory(void);

/* Undo irdm_rt_lock_memory() (munlockall: every lock of the process). */
void irdm_rt_unlock_memory(void);

/*
 * Write to depth_bytes of the calling thread's stack below the caller, so
 * that frames down to that depth never fault later (with memory locked the
 * pages then stay).  Call from the thread that will run the loop, from the
 * function that will run it.
 *
 * Return: IRDM_OK; IRDM_EINVAL if depth_bytes (and a margin for this call)
 * does not fit in what is left of the thread's stack: nothing is touched;
 * IRDM_EIO if the stack's bounds cannot be read.
 */
int irdm_rt_prefault_stack(size_t depth_bytes);

/* ---- idle states ---- */

/*
 * Keep every CPU out of idle states that take longer than max_us to leave,
 * for as long as the returned handle is held (a PM QoS request: writing
 * the limit to /dev/cpu_dma_latency and keeping the file open, as
 * cyclictest does by default).  An idle CPU in a deep state, or a virtual
 * CPU the host descheduled on HLT, answers its timer tens of microseconds
 * late: a loop that sleeps most of its period pays that on every wake.
 * The kernel drops the request when the handle is closed or the process
 * ends, however it ends.  Process-wide, and it costs power: idle CPUs poll.
 *
 * Return: the handle (>= 0); IRDM_EPERM if the device cannot be opened
 * (root only on most systems); IRDM_ENOTSUP if there is no such device;
 * IRDM_EIO if the kernel refused the value.
 */
int irdm_rt_cpu_latency_hold(int32_t max_us);

/* Drop a request irdm_rt_cpu_latency_hold() made (nothing for a handle < 0). */
void irdm_rt_cpu_latency_release(int hold);

/*
 * The limit in force now, us, from all requests of every process (the
 * kernel's answer to a read of /dev/cpu_dma_latency); -1 if it cannot be
 * read.  2000000000 means none.
 */
int32_t irdm_rt_cpu_latency_us(void);

/* ---- scheduling ---- */

/*
 * Initialise *attr for a thread with explicit scheduling s (it never
 * inherits the creator's policy).  On IRDM_OK the caller owns *attr and
 * destroys it with pthread_attr_destroy(); on an error *attr is not
 * initialised.
 *
 * Return: IRDM_OK; IRDM_EINVAL if the policy is not SCHED_FIFO or
 * SCHED_OTHER, the priority is out of the policy's range or the CPU is
 * neither IRDM_RT_ANY_CPU nor a CPU or IRDM_RT_CPU_EXCEPT() of one below
 * CPU_SETSIZE; IRDM_ENOMEM if the
 * attributes cannot be allocated.
 */
int irdm_rt_thread_attr(pthread_attr_t *attr, const struct irdm_rt_sched *s);

/*
 * Start fn(arg) in a thread scheduled as s; nothing is downgraded: if the
 * system refuses s, no thread is started.
 *
 * Return: IRDM_OK; IRDM_EPERM if the system refused the policy or
 * priority; IRDM_EINVAL as irdm_rt_thread_attr(), or if the CPU is not
 * available; IRDM_ENOMEM as irdm_rt_thread_attr(); IRDM_ETHREAD if no
 * thread could be created (resources).
 */
int irdm_rt_thread_start(pthread_t *tid, const struct irdm_rt_sched *s,
			 void *(*fn)(void *), void *arg);

/*
 * Schedule the calling thread as s: the CPU first (when one is given), then
 * the policy and priority.  Stops at the first refusal, so on an error the
 * CPU may be set without the policy: irdm_rt_report_get() says what holds.
 *
 * Return: IRDM_OK; IRDM_EINVAL as irdm_rt_thread_attr(), or if the CPU is
 * not available; IRDM_EPERM if the system refused the policy or priority.
 */
int irdm_rt_set_self(const struct irdm_rt_sched *s);

/* The one CPU the calling thread may run on, or -1 if it may run on more. */
int irdm_rt_pinned_cpu(void);

/* ---- report ---- */

/*
 * Whether a kernel is PREEMPT_RT, from the text of /sys/kernel/realtime
 * (NULL if the file is absent: only PREEMPT_RT kernels have it) and the
 * kernel version string (uname -v, NULL if unknown).  The file decides
 * when present ("1"); without it, a version containing "PREEMPT_RT" does.
 * Apart from irdm_rt_report_get() so that both cases can be tested.
 */
bool irdm_rt_kernel_is_preempt_rt(const char *sys_realtime, const char *uname_version);

/*
 * Fill *r for the calling thread from what the system says now: the
 * kernel, the policy and priority (pthread_getschedparam), the CPU and the
 * affinity, the locked and mapped memory.  A part that cannot be read is
 * left at its "unknown" or "no" value and the rest is still filled.
 *
 * Return: IRDM_OK; IRDM_EIO if some part could not be read.
 */
int irdm_rt_report_get(struct irdm_rt_report *r);

/*
 * Real time as far as this process can make it: a PREEMPT_RT kernel,
 * SCHED_FIFO or SCHED_RR at a priority above 0, all memory locked.
 */
bool irdm_rt_report_realtime(const struct irdm_rt_report *r);

/*
 * One line (no newline) for a program to print before its loop, e.g.
 *   "real-time: yes (kernel PREEMPT_RT, SCHED_FIFO priority 80, memory locked); CPU 1, affinity 1"
 *   "real-time: NO (kernel not PREEMPT_RT, SCHED_OTHER, memory not locked); CPU 0, affinity 0-1"
 * It says "yes" only when irdm_rt_report_realtime() holds.
 *
 * Return: IRDM_OK; IRDM_EINVAL if buf is NULL or len is 0; IRDM_ENOMEM if
 * the line was cut to fit len (buf still holds a terminated prefix).
 */
int irdm_rt_report_format(const struct irdm_rt_report *r, char *buf, size_t len);

/* ---- the loop's CPU to itself (init-time: reads /proc/self/task) ---- */

/*
 * A thread of this process as the system schedules it now.  A thread's
 * name is its comm (pthread_setname_np); one a library started (OpenBLAS's
 * pool) carries the program's.
 */
struct irdm_rt_task {
	pid_t tid;
	char name[16];
	int policy; /* -1 if unknown (the thread ended meanwhile) */
	int priority;
	uint64_t cpu_mask; /* CPUs 0..63, as irdm_rt_report */
	unsigned n_cpus;   /* 0 if unknown */
	bool loop;         /* the loop's thread: set by irdm_rt_isolation_check() */
	bool intrudes;     /* not the loop's and may run on its CPU: likewise */
};

/*
 * Take CPU cpu from every thread of the process but keep_tid (the loop's):
 * a thread's affinity loses that CPU, and one pinned to it alone moves to
 * every other online CPU.  Threads a library started before main (a BLAS
 * pool) inherited the whole machine; threads started later inherit their
 * creator's mask: call once every thread is up, then check.
 *
 * Return: IRDM_OK; IRDM_EINVAL if cpu is not below CPU_SETSIZE or is the
 * only online CPU; IRDM_EIO if /proc/self/task cannot be read; IRDM_EPERM
 * if a thread's affinity could not be changed (the others still are).
 */
int irdm_rt_isolate_cpu(int cpu, pid_t keep_tid);

/*
 * Every thread of the process, read back: up to max of them into tasks[]
 * (*n says how many were read), each marked `intrudes` when it is not
 * loop_tid and may run on cpu.  A thread whose affinity cannot be read
 * intrudes too: nothing says it stays off the CPU.  With cpu < 0 (a loop
 * with no CPU of its own) none intrudes: the threads are only read.
 *
 * Return: the number of intruders (0: the CPU is the loop's alone), or
 * IRDM_EIO if /proc/self/task cannot be read, IRDM_ENOMEM if the process
 * has more than max threads (those read are filled).
 */
int irdm_rt_isolation_check(int cpu, pid_t loop_tid, struct irdm_rt_task *tasks, size_t max,
			    size_t *n);

/*
 * One line (no newline) for a thread, e.g.
 *   "thread 4242 'irdm-fw': SCHED_FIFO priority 80, CPUs 1 (the loop)"
 *   "thread 4243 'irdm-fw': SCHED_OTHER, CPUs 0-1 (may run on the loop's CPU)"
 * Return: as irdm_rt_report_format().
 */
int irdm_rt_task_format(const struct irdm_rt_task *t, char *buf, size_t len);

/* ---- time (safe inside a loop: no allocation, one system call) ---- */

/*
 * Sleep until t on CLOCK_MONOTONIC (absolute, so a loop's period does not
 * drift by its own work), resuming after signals.
 *
 * Return: IRDM_OK; IRDM_EINVAL if t->tv_nsec is outside [0, 1e9).
 */
int irdm_rt_sleep_until(const struct timespec *t);

/*
 * Timespec arithmetic on normalised values (0 <= tv_nsec < 1e9; a negative
 * time has a negative tv_sec, -0.25 s is { -1, 750000000 }).
 */
void irdm_rt_timespec_add(struct timespec *t, const struct timespec *dt);             /* t += dt */
int64_t irdm_rt_timespec_diff_ns(const struct timespec *a, const struct timespec *b); /* b - a */
int irdm_rt_timespec_cmp(const struct timespec *a, const struct timespec *b);         /* <0, 0, >0 */

#endif /* IRDM_RT_H */
