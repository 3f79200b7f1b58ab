/* SPDX-License-Identifier: MIT */
/*
 * Every way out of irdm-fw turns the torque off.  Two kinds of signal:
 *
 *  - the ones asking the process to end (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
 *    SIGPIPE, SIGXCPU, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF,
 *    SIGPWR, SIGSTKFLT and the real-time signals): the handler only sets
 *    the loop's flag; the next tick shuts down (torque zero, state off,
 *    logged) and irdm-fw exits FW_EXIT_SIGNAL.  A second one while the
 *    loop runs means the loop is not listening: the emergency path below.
 *    Before the loop the drives are not enabled yet (start_devices checks
 *    the flag), after it the torque is off already: a second one there
 *    changes nothing, so a clean run keeps its exit code and its log.
 *  - the ones after which the process cannot go on (SIGSEGV, SIGBUS,
 *    SIGFPE, SIGILL, SIGABRT, and SIGTRAP and SIGSYS: a bug, or a seccomp
 *    filter's kill): the handler may not return to the code that
 *    faulted, so it takes the emergency path at once: every open device's
 *    emergency_off (irdm/hal.h: async-signal-safe, for SocketCAN frames
 *    built at open and written with write(2)), one line on stderr with
 *    write(2), _exit(FW_EXIT_EMERGENCY).  In the force thread it runs on
 *    its own stack (a stack overflow is a SIGSEGV too); every other signal
 *    is blocked meanwhile.
 *
 * SIGPIPE never escalates: it comes from irdm-fw's own writes (a reader
 * gone), not from someone asking twice.  SIGXFSZ is ignored: a write past
 * the file-size limit then fails with EFBIG and the log's own loss path
 * (FW_EXIT_LOG) reports it, the torque off like any other end.
 *
 * Arming unblocks these signals: a parent that spawned irdm-fw with them
 * blocked would otherwise leave it deaf to them (and one already pending
 * arrives at once, during the set-up).
 *
 * What cannot be caught (SIGKILL, a power loss) is the drives' own
 * deadline's to answer (docs/canopen.md).
 */
#include <errno.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "fw.h"

#define ALT_STACK_BYTES (64u * 1024u)

static const int soft_signals[] = {
	SIGINT,
	SIGTERM,
	SIGHUP,
	SIGQUIT,
	SIGPIPE,
	SIGXCPU,
	SIGUSR1,
	SIGUSR2,
	SIGALRM,
	SIGVTALRM,
	SIGPROF,
#ifdef SIGPWR
	SIGPWR,
#endif
#ifdef SIGSTKFLT
	SIGSTKFLT,
#endif
};
static const int fatal_signals[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGSYS };

#define RT_NAME_BYTES 24u /* "SIGRTMIN+NN", room for any int */
#define RT_SIGNALS_MAX 64u

static struct fw *armed; /* the devices the emergency path turns off */
static volatile sig_atomic_t *loop_flag;
static volatile sig_atomic_t escalate; /* set while the loop runs */
static char alt_stack[ALT_STACK_BYTES];
static char rt_names[RT_SIGNALS_MAX][RT_NAME_BYTES]; /* built before arming */
static int rt_min = 1, rt_max = 0;                   /* SIGRTMIN, SIGRTMAX read once, before arming */

static const struct {
	int sig;
	const char *name;
} names[] = {
	{ SIGINT, "SIGINT" },
	{ SIGTERM, "SIGTERM" },
	{ SIGHUP, "SIGHUP" },
	{ SIGQUIT, "SIGQUIT" },
	{ SIGPIPE, "SIGPIPE" },
	{ SIGXCPU, "SIGXCPU" },
	{ SIGSEGV, "SIGSEGV" },
	{ SIGBUS, "SIGBUS" },
	{ SIGFPE, "SIGFPE" },
	{ SIGILL, "SIGILL" },
	{ SIGABRT, "SIGABRT" },
	{ SIGTRAP, "SIGTRAP" },
	{ SIGSYS, "SIGSYS" },
	{ SIGUSR1, "SIGUSR1" },
	{ SIGUSR2, "SIGUSR2" },
	{ SIGALRM, "SIGALRM" },
	{ SIGVTALRM, "SIGVTALRM" },
	{ SIGPROF, "SIGPROF" },
#ifdef SIGPWR
	{ SIGPWR, "SIGPWR" },
#endif
#ifdef SIGSTKFLT
	{ SIGSTKFLT, "SIGSTKFLT" },
#endif
};

/* Plain reads: the emergency path names the signal from a handler. */
static bool is_rt(int sig)
{
	return sig >= rt_min && sig <= rt_max && sig - rt_min < (int)RT_SIGNALS_MAX;
}

static const char *signal_name(int sig)
{
	for (size_t i = 0; i < sizeof(names) / sizeof(names[0]); i++)
		if (names[i].sig == sig)
			return names[i].name;
	if (is_rt(sig) && rt_names[sig - rt_min][0])
		return rt_names[sig - rt_min];
	return "signal";
}

/* Append s to buf at *n (async-signal-safe: no stdio). */
static void put_str(char *buf, size_t len, size_t *n, const char *s)
{
	while (*s && *n + 1 < len)
		buf[(*n)++] = *s++;
}

static void put_uint(char *buf, size_t len, size_t *n, unsigned v)
{
	char digits[12];
	int k = 0;

	do {
		digits[k++] = (char)('0' + v % 10);
		v /= 10;
	} while (v && k < (int)sizeof(digits));
	while (k > 0 && *n + 1 < len)
		buf[(*n)++] = digits[--k];
}

/* Torque off on every open device, one line, the end.  Never returns. */
static void emergency(int sig)
{
	unsigned open = 0, off = 0;
	char line[160];
	size_t n = 0;

	for (unsigned i = 0; armed && i < IRDM_BOARD_DEVICES_MAX; i++) {
		if (!armed->hal_open[i])
			continue;
		open++;
		off += irdm_hal_emergency_off(&armed->hal[i]) == IRDM_OK;
	}
	put_str(line, sizeof(line), &n, "irdm-fw: ");
	put_str(line, sizeof(line), &n, signal_name(sig));
	put_str(line, sizeof(line), &n, " (signal ");
	put_uint(line, sizeof(line), &n, (unsigned)sig);
	put_str(line, sizeof(line), &n, "): emergency torque off on ");
	put_uint(line, sizeof(line), &n, off);
	put_str(line, sizeof(line), &n, " of ");
	put_uint(line, sizeof(line), &n, open);
	put_str(line, sizeof(line), &n, open == 1 ? " device" : " devices");
	put_str(line, sizeof(line), &n, off == open ? "" : ": cut the power");
	line[n++] = '\n';
	(void)!write(STDERR_FILENO, line, n);
	_exit(FW_EXIT_EMERGENCY);
}

static void on_soft(int sig)
{
	int saved = errno;

	if (escalate && *loop_flag && sig != SIGPIPE)
		emergency(sig);
	*loop_flag = sig;
	errno = saved;
}

static void on_fatal(int sig)
{
	emergency(sig);
}

static int install_one(int sig, void (*fn)(int), int flags, sigset_t *handled)
{
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = fn;
	sa.sa_flags = flags;
	sigfillset(&sa.sa_mask); /* nothing interrupts the handler */
	sigaddset(handled, sig);
	return sigaction(sig, &sa, NULL) ? IRDM_EIO : IRDM_OK;
}

static int install(const int *sigs, size_t n, void (*fn)(int), int flags, sigset_t *handled)
{
	for (size_t i = 0; i < n; i++)
		if (install_one(sigs[i], fn, flags, handled))
			return IRDM_EIO;
	return IRDM_OK;
}

/* The real-time signals' names, then their handlers. */
static int install_rt(sigset_t *handled)
{
	rt_min = SIGRTMIN;
	rt_max = SIGRTMAX;
	for (int sig = rt_min; sig <= rt_max; sig++) {
		if (!is_rt(sig))
			return IRDM_EIO;
		snprintf(rt_names[sig - rt_min], RT_NAME_BYTES, "SIGRTMIN+%d", sig - rt_min);
		if (install_one(sig, on_soft, 0, handled))
			return IRDM_EIO;
	}
	return IRDM_OK;
}

int fw_signals_arm(struct fw *fw, volatile sig_atomic_t *flag)
{
	stack_t ss = { .ss_sp = alt_stack, .ss_size = sizeof(alt_stack), .ss_flags = 0 };
	sigset_t handled;

	armed = fw;
	loop_flag = flag;
	if (sigaltstack(&ss, NULL))
		return IRDM_EIO;
	sigemptyset(&handled);
	escalate = 0;
	if (install(soft_signals, sizeof(soft_signals) / sizeof(soft_signals[0]), on_soft, 0,
		    &handled) ||
	    install_rt(&handled))
		return IRDM_EIO;
	if (install(fatal_signals, sizeof(fatal_signals) / sizeof(fatal_signals[0]), on_fatal,
		    SA_ONSTACK, &handled))
		return IRDM_EIO;
	if (signal(SIGXFSZ, SIG_IGN) == SIG_ERR)
		return IRDM_EIO;
	return sigprocmask(SIG_UNBLOCK, &handled, NULL) ? IRDM_EIO : IRDM_OK;
}

void fw_signals_loop(bool running)
{
	escalate = running;
}

void fw_signals_disarm(void)
{
	armed = NULL;
}

const char *fw_signal_name(int sig)
{
	return signal_name(sig);
}
