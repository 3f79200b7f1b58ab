/* SPDX-License-Identifier: MIT */
#include "run_prog.h"

#include <fcntl.h>
#include <setjmp.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "test_files.h"

extern char **environ;

pid_t rp_spawn(const char *dir, const char *prog, const char *const *args)
{
	const char *argv[40];
	char out_path[300], err_path[300];
	posix_spawn_file_actions_t fa;
	int n = 0;
	pid_t pid;

	argv[n++] = prog;
	for (; *args && n < 39; args++)
		argv[n++] = *args;
	argv[n] = NULL;
	snprintf(out_path, sizeof(out_path), "%s/stdout", dir);
	snprintf(err_path, sizeof(err_path), "%s/stderr", dir);
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	posix_spawn_file_actions_addopen(&fa, 2, err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	assert_int_equal(posix_spawn(&pid, argv[0], &fa, NULL, (char *const *)argv, environ), 0);
	posix_spawn_file_actions_destroy(&fa);
	return pid;
}

int rp_finish(const char *dir, pid_t pid, char *out, size_t outlen, char *err, size_t errlen)
{
	char path[300];
	int status = 0;

	assert_int_equal(waitpid(pid, &status, 0), pid);
	snprintf(path, sizeof(path), "%s/stdout", dir);
	if (out)
		tf_read_text(path, out, outlen);
	snprintf(path, sizeof(path), "%s/stderr", dir);
	if (err)
		tf_read_text(path, err, errlen);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int rp_run(const char *dir, const char *prog, const char *const *args, char *out,
	   size_t outlen, char *err, size_t errlen)
{
	return rp_finish(dir, rp_spawn(dir, prog, args), out, outlen, err, errlen);
}
