/* SPDX-License-Identifier: MIT */
/* Temporaries removed and children stopped on SIGINT/SIGTERM/SIGHUP (util/interrupt.h). */
#include <signal.h>
#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

#include "irdm/posix/outdir.h"
#include "util/interrupt.h"

enum { FREE,
       FILLING,
       ACTIVE };

struct slot {
	atomic_int state;
	int kind;
	pid_t pgid;
	char path[IRDM_OUTDIR_PATH_MAX + 64];
};

static struct slot slots[IRDM_INTERRUPT_SLOTS];
static atomic_flag installed = ATOMIC_FLAG_INIT;
static const int signals[] = { SIGINT, SIGTERM, SIGHUP };

static void clean(struct slot *s)
{
	switch (s->kind) {
	case IRDM_INTERRUPT_FILE:
		unlink(s->path);
		break;
	case IRDM_INTERRUPT_DIR:
		irdm_outdir_remove_files(s->path);
		break;
	case IRDM_INTERRUPT_PGROUP:
		kill(-s->pgid, SIGTERM);
		break;
	default:
		break;
	}
}

static void on_signal(int sig)
{
	struct sigaction dfl;

	for (int i = 0; i < IRDM_INTERRUPT_SLOTS; i++)
		if (atomic_load(&slots[i].state) == ACTIVE)
			clean(&slots[i]);
	/* die of the signal itself: the exit status says which */
	memset(&dfl, 0, sizeof(dfl));
	dfl.sa_handler = SIG_DFL;
	sigaction(sig, &dfl, NULL);
	raise(sig);
}

static void install(void)
{
	struct sigaction sa, old;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	for (size_t i = 0; i < sizeof(signals) / sizeof(signals[0]); i++)
		sigaddset(&sa.sa_mask, signals[i]);
	for (size_t i = 0; i < sizeof(signals) / sizeof(signals[0]); i++)
		if (!sigaction(signals[i], NULL, &old) && old.sa_handler != SIG_IGN)
			sigaction(signals[i], &sa, NULL);
}

int irdm_interrupt_add(enum irdm_interrupt_kind kind, const char *path, pid_t pgid)
{
	if (path && strlen(path) >= sizeof(slots[0].path))
		return -1;
	if (!atomic_flag_test_and_set(&installed))
		install();
	for (int i = 0; i < IRDM_INTERRUPT_SLOTS; i++) {
		int expect = FREE;

		if (!atomic_compare_exchange_strong(&slots[i].state, &expect, FILLING))
			continue;
		slots[i].kind = kind;
		slots[i].pgid = pgid;
		strcpy(slots[i].path, path ? path : "");
		atomic_store(&slots[i].state, ACTIVE);
		return i;
	}
	return -1;
}

void irdm_interrupt_del(int slot)
{
	if (slot >= 0 && slot < IRDM_INTERRUPT_SLOTS)
		atomic_store(&slots[slot].state, FREE);
}
