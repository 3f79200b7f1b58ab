/* SPDX-License-Identifier: MIT */
/*
 * No circles between the files of a module (a folder of firmware/, hal/ or
 * sim/) nor between the folders of tools/: tools/scripts/include-cycles.py
 * over the repository finds none.  So that a pass means something, the same
 * script runs on small planted trees: a circle between two files through
 * one shared header, and one between two tools folders, must be found; the
 * same trees without the back edge must pass.  Runs from the repository
 * root (make test does).
 */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#define SCRIPT "tools/scripts/include-cycles.py"

/* Run the script on root (NULL: the repository); its exit status, its
 * output in out. */
static int run_script(const char *root, char *out, size_t len)
{
	char cmd[1024];
	size_t n = 0;
	FILE *p;
	int st;

	snprintf(cmd, sizeof(cmd), "python3 %s%s%s 2>&1", SCRIPT, root ? " --root " : "",
		 root ? root : "");
	p = popen(cmd, "r");
	assert_non_null(p);
	while (n + 1 < len && fgets(out + n, (int)(len - n), p))
		n += strlen(out + n);
	out[n] = '\0';
	st = pclose(p);
	assert_true(WIFEXITED(st));
	printf("%s", out);
	return WEXITSTATUS(st);
}

static void put(const char *root, const char *rel, const char *text)
{
	char path[512], *slash;
	FILE *f;

	snprintf(path, sizeof(path), "%s/%s", root, rel);
	for (slash = strchr(path + strlen(root) + 1, '/'); slash; slash = strchr(slash + 1, '/')) {
		*slash = '\0';
		mkdir(path, 0755);
		*slash = '/';
	}
	f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	assert_int_equal(fclose(f), 0);
}

static void remove_tree(const char *root)
{
	char cmd[512];

	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", root);
	assert_int_equal(system(cmd), 0);
}

static void test_repository_has_no_circle(void **state)
{
	char out[16384];

	(void)state;
	assert_int_equal(run_script(NULL, out, sizeof(out)), 0);
	assert_non_null(strstr(out, "no circle"));
}

/*
 * firmware/mod: a.c calls b(), b.c calls a() back, both declared in one
 * private header: the include lines alone show no circle (each file
 * includes only mod_priv.h), the calls through it do.
 */
static void plant_module(const char *root, bool back_edge)
{
	put(root, "firmware/mod/mod_priv.h", "int a(void);\nint b(void);\n");
	put(root, "firmware/mod/a.c", "#include \"mod_priv.h\"\nint a(void)\n{\n\treturn b();\n}\n");
	put(root, "firmware/mod/b.c", back_edge ? "#include \"mod_priv.h\"\nint b(void)\n{\n\treturn a() + 1;\n}\n" : "#include \"mod_priv.h\"\nint b(void)\n{\n\treturn 1;\n}\n");
}

static void test_planted_module_circle_is_found(void **state)
{
	char root[] = "/tmp/irdm-includes-XXXXXX", out[4096];

	(void)state;
	assert_non_null(mkdtemp(root));
	plant_module(root, true);
	assert_int_equal(run_script(root, out, sizeof(out)), 1);
	assert_non_null(strstr(out, "firmware/mod: circle: a.c -> b.c -> a.c"));
	assert_non_null(strstr(out, "calls a() of"));
	plant_module(root, false);
	assert_int_equal(run_script(root, out, sizeof(out)), 0);
	remove_tree(root);
}

/* tools/low and tools/high: high includes low's header; low including
 * high's back makes the circle. */
static void plant_tools(const char *root, bool back_edge)
{
	put(root, "tools/low/low.h", "int low(void);\n");
	put(root, "tools/high/high.h", "int high(void);\n");
	put(root, "tools/high/high.c", "#include \"high/high.h\"\n#include \"low/low.h\"\n"
				       "int high(void)\n{\n\treturn low();\n}\n");
	put(root, "tools/low/low.c", back_edge ? "#include \"high/high.h\"\n#include \"low/low.h\"\nint low(void)\n{\n\treturn 1;\n}\n" : "#include \"low/low.h\"\nint low(void)\n{\n\treturn 1;\n}\n");
}

static void test_planted_tools_circle_is_found(void **state)
{
	char root[] = "/tmp/irdm-includes-XXXXXX", out[4096];

	(void)state;
	assert_non_null(mkdtemp(root));
	plant_tools(root, true);
	assert_int_equal(run_script(root, out, sizeof(out)), 1);
	assert_non_null(strstr(out, "tools: circle: tools/high -> tools/low -> tools/high"));
	plant_tools(root, false);
	assert_int_equal(run_script(root, out, sizeof(out)), 0);
	remove_tree(root);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_repository_has_no_circle),
		cmocka_unit_test(test_planted_module_circle_is_found),
		cmocka_unit_test(test_planted_tools_circle_is_found),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
