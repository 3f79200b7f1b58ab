/* SPDX-License-Identifier: MIT */
/*
 * The fuzzers' input as a file: a memfd holding the bytes, opened by path
 * (/proc/self/fd/N), so the readers that take a path read it through
 * their own open, regular-file check and size bound.  Header-only: each
 * fuzzer is one file.
 */
#ifndef IRDM_FUZZ_MEMFILE_H
#define IRDM_FUZZ_MEMFILE_H

#include <stdint.h>
#include <stdio.h>
#include <sys/mman.h>
#include <unistd.h>

/* The bytes in a fresh memfd, its path into path; the fd, or -1. */
static inline int memfile(const uint8_t *data, size_t size, char *path, size_t len)
{
	int fd = memfd_create("fuzz", MFD_CLOEXEC);

	if (fd < 0)
		return -1;
	if (size && write(fd, data, size) != (ssize_t)size) {
		close(fd);
		return -1;
	}
	snprintf(path, len, "/proc/self/fd/%d", fd);
	return fd;
}

#endif
