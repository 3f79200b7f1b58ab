/* SPDX-License-Identifier: MIT */
/* Files and scratch directories for the tests (cmocka assertions inside). */
#ifndef IRDM_TESTS_TEST_FILES_H
#define IRDM_TESTS_TEST_FILES_H

#include <stddef.h>

/* The whole file at path (malloc'd; the caller frees), its size in *len;
 * fails the test if it cannot be read or is empty. */
char *tf_load(const char *path, size_t *len);

/* mkdtemp /tmp/irdm-TAG-XXXXXX into dir; 0 or -1 (for cmocka setups). */
int tf_tmpdir(char *dir, size_t len, const char *tag);

/* rm -rf dir; 0 or -1 (for cmocka teardowns). */
int tf_rmdir(const char *dir);

#endif
