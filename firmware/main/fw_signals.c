/* SPDX-License-Identifier: MIT */
/*
 * Every way out of irdm-fw turns the torque off.  Two kinds of signal:
 *
 *  - the ones asking the process to end (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
 *    SIGPIPE, SIGXCPU): the handler only sets the loop's flag; the next
 *    tick shuts down (torque zero, state off, logged) and irdm-fw exits
 *    FW_EXIT_SIGNAL.  A second one before the loop has ended it means the
 *    loop is not listening: the emergency path below.
 *  - the ones after which the process cannot go on (SIGSEGV, SIGBUS,
 *    SIGFPE, SIGILL, SIGABRT): the handler may not return to the code that
 *    faulted, so it takes the emergency path at once: every open device's
 *    emergency_off (irdm/hal.h: async-signal-safe, for SocketCAN frames
 *    built at open and written with write(2)), one line on stderr with
 *    write(2), _exit(FW_EXIT_EMERGENCY).  In the force thread it runs on
 *    its own stack (a stack overflow is a SIGSEGV too); every other signal
 *    is blocked meanwhile.
 *
 * SIGPIPE never escalates: it comes from irdm-fw's own writes (a reader
 * gone), not from someone asking twice.
 *
 * What cannot be caught (SIGKILL, a power loss) is the drives' own
 * deadline's to answer (docs/canopen.md).
 */
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "fw.h"

#define ALT_STACK_BYTES (64u * 1024u)

static const int soft_signals[] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXCPU };
static const int fatal_signals[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT };

static struct fw *armed;                /* the devices the emergency path turns off */
static volatile sig_atomic_t *loop_flag;
static char alt_stack[ALT_STACK_BYTES];

static const struct {
	int sig;
	const char *name;
} names[] = {
	{ SIGINT, "SIGINT" }, { SIGTERM, "SIGTERM" }, { SIGHUP, "SIGHUP" },
	{ SIGQUIT, "SIGQUIT" }, { SIGPIPE, "SIGPIPE" }, { SIGXCPU, "SIGXCPU" },
	{ SIGSEGV, "SIGSEGV" }, { SIGBUS, "SIGBUS" }, { SIGFPE, "SIGFPE" },
	{ SIGILL, "SIGILL" }, { SIGABRT, "SIGABRT" },
};

static const char *signal_name(int sig)
{
	for (size_t i = 0; i < sizeof(names) / sizeof(names[0]); i++)
		if (names[i].sig == sig)
			return names[i].name;
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

	if (*loop_flag && sig != SIGPIPE)
		emergency(sig);
	*loop_flag = sig;
	errno = saved;
}

static void on_fatal(int sig)
{
	emergency(sig);
}

static int install(const int *sigs, size_t n, void (*fn)(int), int flags)
{
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = fn;
	sa.sa_flags = flags;
	sigfillset(&sa.sa_mask);        /* nothing interrupts the handler */
	for (size_t i = 0; i < n; i++)
		if (sigaction(sigs[i], &sa, NULL))
			return IRDM_EIO;
	return IRDM_OK;
}

int fw_signals_arm(struct fw *fw, volatile sig_atomic_t *flag)
{
	stack_t ss = { .ss_sp = alt_stack, .ss_size = sizeof(alt_stack), .ss_flags = 0 };

	armed = fw;
	loop_flag = flag;
	if (sigaltstack(&ss, NULL))
		return IRDM_EIO;
	if (install(soft_signals, sizeof(soft_signals) / sizeof(soft_signals[0]), on_soft, 0))
		return IRDM_EIO;
	return install(fatal_signals, sizeof(fatal_signals) / sizeof(fatal_signals[0]), on_fatal,
		       SA_ONSTACK);
}

void fw_signals_disarm(void)
{
	armed = NULL;
}

const char *fw_signal_name(int sig)
{
	return signal_name(sig);
}
