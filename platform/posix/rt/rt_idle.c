/* SPDX-License-Identifier: MIT */
/*
 * Idle states a loop's wake-up does not wait for: a PM QoS request held on
 * /dev/cpu_dma_latency for as long as the loop runs.
 */
#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

#include "irdm/posix/rt.h"

#define CPU_LATENCY_DEV "/dev/cpu_dma_latency"

int irdm_rt_cpu_latency_hold(int32_t max_us)
{
	int fd = open(CPU_LATENCY_DEV, O_RDWR | O_CLOEXEC);

	if (fd < 0)
		return errno == ENOENT ? IRDM_ENOTSUP : IRDM_EPERM;
	/* the binary form: four bytes, the value in the host's byte order */
	if (write(fd, &max_us, sizeof(max_us)) != (ssize_t)sizeof(max_us)) {
		close(fd);
		return IRDM_EIO;
	}
	return fd;
}

void irdm_rt_cpu_latency_release(int hold)
{
	if (hold >= 0)
		close(hold);
}

int32_t irdm_rt_cpu_latency_us(void)
{
	int fd = open(CPU_LATENCY_DEV, O_RDONLY | O_CLOEXEC);
	int32_t us = -1;

	if (fd < 0)
		return -1;
	if (read(fd, &us, sizeof(us)) != (ssize_t)sizeof(us))
		us = -1;
	close(fd);
	return us;
}
