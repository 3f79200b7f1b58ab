/* SPDX-License-Identifier: MIT */
/* The back-end table and instance binding (irdm/hal.h says why a table
 * filled at start rather than one that names the back-ends). */
#include <stdalign.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "irdm/error.h"
#include "irdm/hal/hal.h"

static const struct irdm_hal_backend *table[IRDM_HAL_BACKENDS_MAX];

static int complete(const struct irdm_hal_backend *b)
{
	const struct irdm_hal_ops *o = b->ops;

	return b->name && b->name[0] && o && o->open && o->start && o->read && o->write &&
	       o->safe_off && o->poll && o->close;
}

const struct irdm_hal_backend *irdm_hal_find(const char *name)
{
	for (unsigned i = 0; name && i < IRDM_HAL_BACKENDS_MAX && table[i]; i++)
		if (strcmp(table[i]->name, name) == 0)
			return table[i];
	return NULL;
}

const struct irdm_hal_backend *irdm_hal_backend_at(unsigned i)
{
	return i < IRDM_HAL_BACKENDS_MAX ? table[i] : NULL;
}

int irdm_hal_register(const struct irdm_hal_backend *b)
{
	const struct irdm_hal_backend *same;
	unsigned i;

	if (!b || !complete(b))
		return IRDM_EINVAL;
	same = irdm_hal_find(b->name);
	if (same)
		return same == b ? IRDM_OK : IRDM_EBUSY;
	for (i = 0; i < IRDM_HAL_BACKENDS_MAX && table[i]; i++)
		;
	if (i == IRDM_HAL_BACKENDS_MAX)
		return IRDM_ENOMEM;
	table[i] = b;
	return IRDM_OK;
}

int irdm_hal_init(struct irdm_hal_dev *dev, const char *name, const struct irdm_hal_config *cfg,
		  void *mem, size_t mem_size)
{
	const struct irdm_hal_backend *b = irdm_hal_find(name);

	if (!b)
		return IRDM_ENOTSUP;
	if (!cfg || !mem || (uintptr_t)mem % alignof(max_align_t) != 0)
		return IRDM_EINVAL;
	if (mem_size < b->data_size)
		return IRDM_ENOMEM;
	memset(mem, 0, b->data_size);
	dev->backend = b;
	dev->config = cfg;
	dev->data = mem;
	dev->why[0] = '\0';
	dev->info[0] = '\0';
	return IRDM_OK;
}
