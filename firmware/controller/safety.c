/* SPDX-License-Identifier: MIT */
/* The safety state machine (irdm/safety.h holds the diagram). */
#include <string.h>

#include "irdm/safety.h"

void irdm_safety_init(struct irdm_safety *s)
{
	memset(s, 0, sizeof(*s));
	s->state = IRDM_SAFETY_INIT;
}

int irdm_safety_calibrated(struct irdm_safety *s)
{
	if (s->state != IRDM_SAFETY_INIT)
		return IRDM_EINVAL;
	s->calibrated = true;
	s->state = IRDM_SAFETY_READY;
	return IRDM_OK;
}

int irdm_safety_enable(struct irdm_safety *s)
{
	if (s->state != IRDM_SAFETY_READY && s->state != IRDM_SAFETY_ENABLED)
		return IRDM_EINVAL;
	s->state = IRDM_SAFETY_ENABLED;
	return IRDM_OK;
}

int irdm_safety_disable(struct irdm_safety *s)
{
	if (s->state != IRDM_SAFETY_READY && s->state != IRDM_SAFETY_ENABLED)
		return IRDM_EINVAL;
	s->state = IRDM_SAFETY_READY;
	return IRDM_OK;
}

static uint32_t lowest_bit(uint32_t v)
{
	return v & (~v + 1u);
}

int irdm_safety_fault(struct irdm_safety *s, uint32_t faults)
{
	uint32_t fatal = faults & IRDM_FAULT_FATAL;

	if (!fatal)
		return IRDM_EINVAL;
	if (s->state == IRDM_SAFETY_OFF)
		return IRDM_OK;
	if (s->state != IRDM_SAFETY_FAULT) {
		s->cause = lowest_bit(fatal);
		s->n_faults++;
		s->state = IRDM_SAFETY_FAULT;
	}
	s->faults |= fatal;
	return IRDM_OK;
}

int irdm_safety_reset(struct irdm_safety *s, uint32_t active)
{
	if (s->state != IRDM_SAFETY_FAULT)
		return IRDM_EINVAL;
	/* a signal means the process is being stopped: it never goes away */
	if ((active & IRDM_FAULT_FATAL) || (s->faults & IRDM_FAULT_SIGNAL))
		return IRDM_EFAULT;
	s->faults = 0;
	s->cause = 0;
	s->state = s->calibrated ? IRDM_SAFETY_READY : IRDM_SAFETY_INIT;
	return IRDM_OK;
}

void irdm_safety_shutdown(struct irdm_safety *s)
{
	s->state = IRDM_SAFETY_OFF;
}

bool irdm_safety_torque_allowed(const struct irdm_safety *s)
{
	return s->state == IRDM_SAFETY_ENABLED;
}

static const char *const fault_names[IRDM_FAULT_BITS] = {
	"clamp",
	"workspace",
	"velocity",
	"watchdog",
	"overrun",
	"encoder-nan",
	"encoder-range",
	"signal",
	"hal-read",
	"hal-write",
	"hal-fault",
	"engine",
};

const char *irdm_safety_fault_name(uint32_t faults)
{
	if (!faults)
		return "none";
	for (unsigned b = 0; b < IRDM_FAULT_BITS; b++)
		if (faults & (1u << b))
			return fault_names[b];
	return "unknown";
}

const char *irdm_safety_state_name(int state)
{
	static const char *const names[] = { "init", "ready", "enabled", "fault", "off" };

	if (state < IRDM_SAFETY_INIT || state > IRDM_SAFETY_OFF)
		return "unknown";
	return names[state];
}
