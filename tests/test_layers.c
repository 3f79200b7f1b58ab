/* SPDX-License-Identifier: MIT */
/*
 * The layers keep their direction (docs/architecture.md, "Layers"), checked
 * by folder, so that a new file is checked without anyone editing a list:
 *  - the firmware core (every object built from a firmware/ source), linked
 *    together, needs no symbol from outside but ISO C library functions
 *    the tick's code may call (string and memory, formatting into buffers,
 *    strto*, ctype, libm, allocation for initialisation, errno): no POSIX
 *    call (open, read, clock_gettime, mmap, ...), no pthread_* or sem_*,
 *    no BLAS, no stdio FILE.  A failure names the symbol and the object;
 *  - libirdmfw.a holds exactly those objects, and the test binaries of
 *    tests/core/ link it alone (no BLAS, thread or solver library);
 *  - no source of a library layer (firmware/, platform/posix/, hal/, sim/,
 *    tools/) includes a header outside the include paths of its layer (an
 *    app's header among them) or reaches out by a relative "../" path.
 * Needs IRDM_BUILD (the build directory; `make test` sets it) and runs from
 * the repository root.
 */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

static const char *build_dir(void)
{
	const char *b = getenv("IRDM_BUILD");

	return b ? b : "build";
}

/* What the core may call: ISO C functions that touch neither a file, a
 * clock nor a thread (and glibc's names for ctype and errno). */
static const char *const allowed[] = {
	/* string and memory */
	"memcpy",
	"memmove",
	"memset",
	"memcmp",
	"memchr",
	"strlen",
	"strnlen",
	"strcmp",
	"strncmp",
	"strchr",
	"strrchr",
	"strstr",
	"strcspn",
	"strspn",
	"strpbrk",
	"strcpy",
	"strncpy",
	"strcat",
	"strncat",
	/* formatting into a buffer */
	"snprintf",
	"vsnprintf",
	/* numbers from text */
	"strtod",
	"strtof",
	"strtold",
	"strtol",
	"strtoll",
	"strtoul",
	"strtoull",
	"__isoc23_strtol",
	"__isoc23_strtoll",
	"__isoc23_strtoul",
	"__isoc23_strtoull",
	/* ctype */
	"__ctype_b_loc",
	"__ctype_tolower_loc",
	"__ctype_toupper_loc",
	"isalnum",
	"isalpha",
	"isdigit",
	"isspace",
	"isxdigit",
	"isupper",
	"islower",
	"isprint",
	"ispunct",
	"tolower",
	"toupper",
	/* libm */
	"sqrt",
	"sqrtf",
	"cbrt",
	"hypot",
	"pow",
	"exp",
	"exp2",
	"expm1",
	"log",
	"log2",
	"log10",
	"log1p",
	"sin",
	"cos",
	"tan",
	"sincos",
	"sinf",
	"cosf",
	"asin",
	"acos",
	"atan",
	"atan2",
	"sinh",
	"cosh",
	"tanh",
	"fabs",
	"fabsf",
	"floor",
	"ceil",
	"round",
	"lround",
	"llround",
	"trunc",
	"rint",
	"nearbyint",
	"fmod",
	"fmin",
	"fmax",
	"fma",
	"copysign",
	"frexp",
	"ldexp",
	"modf",
	/* allocation, at initialisation */
	"calloc",
	"malloc",
	"aligned_alloc",
	"free",
	/* errno */
	"__errno_location",
	/* the compiler's, not the library's (clang turns memcmp() == 0 into bcmp) */
	"_GLOBAL_OFFSET_TABLE_",
	"__stack_chk_fail",
	"bcmp",
	"__memcpy_chk",
	"__memmove_chk",
	"__memset_chk",
	"__snprintf_chk",
	"__vsnprintf_chk",
	"__strncpy_chk",
	"__strcpy_chk",
	NULL,
};

/* Instrumentation runtimes of make san and make fuzz. */
static const char *const allowed_prefix[] = { "__asan_", "__ubsan_", "__sanitizer_", "__sancov_",
					      "__lsan_", NULL };

static int is_allowed(const char *sym)
{
	for (const char *const *a = allowed; *a; a++)
		if (!strcmp(sym, *a))
			return 1;
	for (const char *const *a = allowed_prefix; *a; a++)
		if (!strncmp(sym, *a, strlen(*a)))
			return 1;
	return 0;
}

/* Run cmd; every output line goes through fn(line, ctx); returns the
 * number of lines read and fails on a non-zero exit. */
static size_t each_line(const char *cmd, void (*fn)(const char *line, void *ctx), void *ctx)
{
	char line[1024];
	size_t n = 0;
	FILE *p = popen(cmd, "r");

	assert_non_null(p);
	while (fgets(line, sizeof(line), p)) {
		line[strcspn(line, "\n")] = 0;
		fn(line, ctx);
		n++;
	}
	if (pclose(p) != 0)
		fail_msg("command failed: %s", cmd);
	return n;
}

static void count_line(const char *line, void *ctx)
{
	(void)line;
	(*(size_t *)ctx)++;
}

/* The objects of the sources under dir, one a line (shell). */
static void objects_of(char *buf, size_t len, const char *dir)
{
	snprintf(buf, len, "find %s -name '*.c' | sort | sed 's|^|%s/obj/|; s|\\.c$|.o|'", dir,
		 build_dir());
}

struct layer_scan {
	const char *dir;
	size_t bad; /* symbols outside the allow-list */
	int seen_pthread_create, seen_open;
	int quiet; /* the control: count, do not report */
};

static void name_culprits(const char *sym, const char *dir)
{
	char list[512], cmd[1024];

	objects_of(list, sizeof(list), dir);
	snprintf(cmd, sizeof(cmd),
		 "%s | while read o; do nm -u \"$o\" | awk '{print $2}' | grep -qxF '%s' && echo \"$o\"; done; true",
		 list, sym);
	{
		FILE *p = popen(cmd, "r");
		char line[512];

		assert_non_null(p);
		while (fgets(line, sizeof(line), p)) {
			line[strcspn(line, "\n")] = 0;
			print_error("  %s needs '%s'\n", line, sym);
		}
		pclose(p);
	}
}

static void check_symbol(const char *line, void *ctx)
{
	struct layer_scan *s = ctx;
	const char *sym = strrchr(line, ' ');

	sym = sym ? sym + 1 : line;
	if (!strcmp(sym, "pthread_create"))
		s->seen_pthread_create = 1;
	if (!strcmp(sym, "open") || !strcmp(sym, "open64"))
		s->seen_open = 1;
	if (is_allowed(sym))
		return;
	s->bad++;
	if (!s->quiet) {
		print_error("%s: the core needs '%s', not an ISO C library function it may call "
			    "(POSIX, threads, BLAS or stdio belong in platform/posix/):\n",
			    s->dir, sym);
		name_culprits(sym, s->dir);
	}
}

/* Link every object built from dir's sources into one and look at what
 * it still needs from outside. */
static void scan_layer(struct layer_scan *s)
{
	char list[512], cmd[2048];
	size_t n = 0, missing = 0;

	objects_of(list, sizeof(list), s->dir);
	snprintf(cmd, sizeof(cmd), "%s", list);
	each_line(cmd, count_line, &n);
	if (n < 10)
		fail_msg("%s: only %zu sources found: run from the repository root", s->dir, n);
	snprintf(cmd, sizeof(cmd), "%s | while read o; do [ -f \"$o\" ] || echo \"$o\"; done", list);
	each_line(cmd, count_line, &missing);
	if (missing)
		fail_msg("%s: %zu of its objects are not in %s/obj: build first", s->dir, missing,
			 build_dir());
	snprintf(cmd, sizeof(cmd),
		 "t=$(mktemp) && %s | xargs ld -r -o \"$t\" && nm -u \"$t\"; rc=$?; rm -f \"$t\"; exit $rc",
		 list);
	each_line(cmd, check_symbol, s);
}

static void test_core_needs_only_iso_c(void **state)
{
	struct layer_scan s = { .dir = "firmware" };

	(void)state;
	scan_layer(&s);
	if (s.bad)
		fail_msg("the firmware core needs %zu symbol(s) outside ISO C (listed above)", s.bad);
}

/* Control: the same scan over the platform's objects sees the services
 * they are there for, so the scan above can see such a symbol. */
static void test_control_platform_needs_services(void **state)
{
	struct layer_scan s = { .dir = "platform/posix", .quiet = 1 };

	(void)state;
	scan_layer(&s);
	assert_true(s.bad >= 10);
	assert_true(s.seen_pthread_create);
	assert_true(s.seen_open);
}

/* The core library is the folder: one member per firmware/ source. */
static void test_core_library_is_the_folder(void **state)
{
	char cmd[512];
	size_t sources = 0, members = 0;

	(void)state;
	each_line("find firmware -name '*.c'", count_line, &sources);
	snprintf(cmd, sizeof(cmd), "ar t %s/libirdmfw.a", build_dir());
	each_line(cmd, count_line, &members);
	assert_true(sources >= 10);
	assert_int_equal(members, sources);
}

static void no_service_library(const char *line, void *ctx)
{
	(void)ctx;
	if (strstr(line, "openblas") || strstr(line, "libblas") || strstr(line, "pthread") ||
	    strstr(line, "cholmod") || strstr(line, "arpack") || strstr(line, "websockets"))
		fail_msg("a tests/core binary depends on %s", line);
}

static void test_core_tests_link_the_core_alone(void **state)
{
	char cmd[512];
	size_t n = 0, needed;

	(void)state;
	snprintf(cmd, sizeof(cmd),
		 "for s in tests/core/test_*.c; do b=%s/tests/core/$(basename $s .c); "
		 "[ -x $b ] || { echo \"$b: build it first\" >&2; exit 1; }; echo $b; done",
		 build_dir());
	each_line(cmd, count_line, &n);
	assert_true(n >= 1);
	snprintf(cmd, sizeof(cmd),
		 "for s in tests/core/test_*.c; do readelf -d %s/tests/core/$(basename $s .c) | grep NEEDED; done",
		 build_dir());
	needed = each_line(cmd, no_service_library, NULL);
	assert_true(needed >= n); /* libc at least: the check saw the lists */
}

static void report_include(const char *line, void *ctx)
{
	size_t *n = ctx;

	if (n) {
		(*n)++;
		return;
	}
	fail_msg("include outside its layer: %s", line);
}

/* Every #include "..." under dir must resolve beside the file or under one
 * of roots (the layer's include paths), without "../". */
static void scan_includes(const char *dir, const char *roots, size_t *count)
{
	char cmd[2048];

	snprintf(cmd, sizeof(cmd),
		 "grep -rnoE '^#[[:space:]]*include[[:space:]]*\"[^\"]+\"' %s --include='*.c' --include='*.h' |"
		 " while IFS=: read f n inc; do p=${inc#*\\\"}; p=${p%%\\\"}; ok=;"
		 " case \"$p\" in ../*|*/../*) ;; *) [ -f \"$(dirname \"$f\")/$p\" ] && ok=1;"
		 " for r in %s; do [ -f \"$r/$p\" ] && ok=1; done;; esac;"
		 " [ -n \"$ok\" ] || echo \"$f:$n: $p\"; done",
		 dir, roots);
	each_line(cmd, report_include, count);
}

static void test_libraries_include_within_their_layer(void **state)
{
	(void)state;
	scan_includes("firmware", "firmware/include", NULL);
	scan_includes("platform/posix", "firmware/include platform/posix/include", NULL);
	scan_includes("hal", "firmware/include hal/include", NULL);
	scan_includes("sim", "firmware/include hal/include platform/posix/include sim/include",
		      NULL);
	scan_includes("tools", "firmware/include platform/posix/include tools", NULL);
}

/* Control: the controller program does reach past the core, and the scan
 * sees it when given the core's path alone. */
static void test_control_app_reaches_other_layers(void **state)
{
	size_t n = 0;

	(void)state;
	scan_includes("apps/irdm-fw", "firmware/include", &n);
	assert_true(n >= 3);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_core_needs_only_iso_c),
		cmocka_unit_test(test_control_platform_needs_services),
		cmocka_unit_test(test_core_library_is_the_folder),
		cmocka_unit_test(test_core_tests_link_the_core_alone),
		cmocka_unit_test(test_libraries_include_within_their_layer),
		cmocka_unit_test(test_control_app_reaches_other_layers),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
