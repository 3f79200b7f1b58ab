# IRDM haptic controller — build.
#
#   make            host tool build/irdm and the firmware library
#   make test       build and run every test (tests/run-tests.sh)
#   make san        the same tests under AddressSanitizer + UBSan (build-san/)
#   make fuzz       libFuzzer targets, each for FUZZ_SECONDS (clang only)
#   make check      what CI runs: fuzz, clang + sanitizer tests, then the tests
#   make bench      benchmarks (print figures; never pass/fail on time)
#   make run        the main job: the built-in default scene, end to end
#
# CC=clang works too.  Sources are found by directory, so adding a file needs
# no edit here: firmware/*/*.c -> libirdmfw.a, tools/*/*.c (but tools/irdm)
# -> libirdmtools.a, tools/irdm/*.c -> irdm, tests/test_*.c -> one binary each.

CC      ?= cc
BUILD   ?= build
SAN     ?=
FUZZ_SECONDS ?= 30

CSTD     = -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
WARN     = -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wvla
OPT     ?= -O2 -g
INC      = -Ifirmware/include -Itools -I/usr/include/suitesparse
CFLAGS  += $(CSTD) $(WARN) $(OPT) $(INC) -MMD -MP
LDLIBS   = -lcholmod -larpack -lopenblas -lpthread -lm

ifneq ($(SAN),)
CFLAGS  += -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
LDFLAGS += -fsanitize=address,undefined
endif

FW_SRC    := $(wildcard firmware/*/*.c)
TOOL_SRC  := $(filter-out tools/irdm/%,$(wildcard tools/*/*.c))
CLI_SRC   := $(wildcard tools/irdm/*.c)
TEST_SRC  := $(wildcard tests/test_*.c)
TESTSUP_SRC := $(wildcard tests/support/*.c)
BENCH_SRC := $(wildcard tests/bench/*.c)
FUZZ_SRC  := $(wildcard tests/fuzz/fuzz_*.c)

obj = $(patsubst %.c,$(BUILD)/obj/%.o,$(1))

FW_LIB   := $(BUILD)/libirdmfw.a
TOOL_LIB := $(BUILD)/libirdmtools.a
IRDM     := $(BUILD)/irdm
TESTS    := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
BENCHES  := $(patsubst tests/bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))

.PHONY: all test san fuzz bench bench-precompute run check deps clean
.SECONDARY:
all: $(IRDM) $(FW_LIB)

$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c $< -o $@

$(FW_LIB): $(call obj,$(FW_SRC))
	@mkdir -p $(dir $@)
	$(AR) rcs $@ $^

$(TOOL_LIB): $(call obj,$(TOOL_SRC))
	@mkdir -p $(dir $@)
	$(AR) rcs $@ $^

$(IRDM): $(call obj,$(CLI_SRC)) $(TOOL_LIB) $(FW_LIB)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS)

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(call obj,$(TESTSUP_SRC)) $(TOOL_LIB) $(FW_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS) -lcmocka

# benches share the test fixtures, which report through cmocka
$(BUILD)/bench/%: $(BUILD)/obj/tests/bench/%.o $(call obj,$(TESTSUP_SRC)) $(TOOL_LIB) $(FW_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS) -lcmocka

test: $(TESTS) $(IRDM)
	IRDM=$(IRDM) tests/run-tests.sh $(TESTS)

san:
	$(MAKE) BUILD=build-san SAN=1 OPT="-O1 -g" test

# libFuzzer needs clang; each target gets its own seed corpus directory.
FUZZ_BUILD := build-fuzz
fuzz:
	$(MAKE) CC=clang BUILD=$(FUZZ_BUILD) OPT="-O1 -g -fsanitize=fuzzer-no-link,address,undefined" $(FUZZ_BUILD)/libirdmtools.a $(FUZZ_BUILD)/libirdmfw.a
	@set -e; for f in $(FUZZ_SRC); do \
	  n=$$(basename $$f .c); \
	  clang $(CSTD) $(WARN) -O1 -g $(INC) -fsanitize=fuzzer,address,undefined $$f \
	    $(FUZZ_BUILD)/libirdmtools.a $(FUZZ_BUILD)/libirdmfw.a -o $(FUZZ_BUILD)/$$n $(LDLIBS); \
	  mkdir -p $(FUZZ_BUILD)/corpus/$$n; \
	  seeds=tests/fuzz/seeds/$$n; [ -d $$seeds ] || seeds=; \
	  echo "fuzz: $$n for $(FUZZ_SECONDS) s"; \
	  $(FUZZ_BUILD)/$$n -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -print_final_stats=1 \
	    $(FUZZ_BUILD)/corpus/$$n $$seeds 2>&1 | tail -n 4; \
	done

bench: $(BENCHES) $(IRDM) bench-precompute
	@set -e; for b in $(BENCHES); do echo "== $$b"; IRDM=$(IRDM) $$b; done

# Paper-scale images (cuboid, bunny): time and size beside the paper's.
bench-precompute: $(IRDM) $(BUILD)/data/bunny.off
	tools/scripts/bench-precompute.sh $(IRDM)

$(BUILD)/data/bunny.off:
	@mkdir -p $(dir $@)
	tools/scripts/bunny-off.sh $@

# The gcc run comes last so its summary line closes the output.
check: deps
	$(MAKE) fuzz FUZZ_SECONDS=$(FUZZ_SECONDS)
	$(MAKE) CC=clang BUILD=build-clang test
	$(MAKE) san
	$(MAKE) test

run: deps
	$(MAKE) $(IRDM)
	tools/scripts/run-default-scene.sh $(IRDM)

deps:
	tools/scripts/install-deps.sh

clean:
	rm -rf build build-san build-fuzz

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
