/* SPDX-License-Identifier: MIT */
/* Files and scratch directories for the tests (cmocka assertions inside). */
#ifndef IRDM_TESTS_TEST_FILES_H
#define IRDM_TESTS_TEST_FILES_H

#include <stddef.h>

/* The whole file at path (malloc'd; the caller frees), its size in *len;
 * fails the test if it cannot be read or is empty. */
char *tf_load(const char *path, size_t *len);

/* Up to len - 1 bytes of the text file at path, NUL-terminated ("" if it
 * cannot be read: the caller's assertions on the text then fail). */
void tf_read_text(const char *path, char *buf, size_t len);

/* Write text to path (replacing it); fails the test if it cannot. */
void tf_write_text(const char *path, const char *text);

/* mkdtemp /tmp/irdm-TAG-XXXXXX into dir; 0 or -1 (for cmocka setups). */
int tf_tmpdir(char *dir, size_t len, const char *tag);

/* rm -rf dir; 0 or -1 (for cmocka teardowns). */
int tf_rmdir(const char *dir);

#endif
