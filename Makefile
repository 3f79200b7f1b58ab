# IRDM haptic controller — build.
#
#   make            host tool build/irdm and the firmware library
#   make test       build and run every test (tests/run-tests.sh)
#   make san        the same tests under AddressSanitizer + UBSan (build-san/)
#   make fuzz       libFuzzer targets, each for FUZZ_SECONDS (clang only);
#                   any finding fails the build and keeps the input
#   make test-variants  the stability suite with OPENBLAS_NUM_THREADS=1, then
#                   with the portable history sums forced
#   make check      what CI runs: docs-check, format-check, fuzz, clang + sanitizer tests, the
#                   variants, then the tests
#   make bench      benchmarks (print figures; never pass/fail on time), each
#                   into docs/measurements/NAME.md (make bench_tick: one)
#   make head-tick  the hybrid tick timed and its instructions counted
#                   (callgrind), beside an earlier one: BEFORE=its bench_tick
#   make bench-mpi  the precompute of a 100k-node model, serial and over MPI ranks
#   make stability  the stability suite's long run (10^7-tick soak): a Markdown
#                   table and a plot of the worst cases in out/stability/
#   (the measuring targets write docs/measurements/NAME.md: the figures with
#   the command, date, machine and load; tools/scripts/measure.sh)
#   make report     docs/report.md and its plots: every representation against
#                   the exact model (irdm report; REPORT_CONFIGS, <= 10 min)
#   make run        the main job: the built-in default scene, end to end
#   make view-shots after make run: its run in the browser view, docs/view/*.png
#   make run-vs-exact after make run: its press replayed on its image and on
#                   the all-modes image (docs/measurements/run-vs-exact.md)
#   make jitter     irdm-fw's wake-up latency beside cyclictest's, alternating
#                   (JITTER_ROUNDS x JITTER_SECONDS; docs/measurements/jitter.md)
#   make jitter-view the same loop with and without a browser on its live view
#   make hil        the CAN back-end end to end in a PREEMPT_RT VM (docs/hil.md)
#   make docs       every generated document (GEN_DOCS: scene-format.md, the
#                   board keys in boards.md, the test index in testing.md);
#                   make docs-check: fails if one is stale
#   make sizes      irdm-fw built with each configs/*.config (CONFIG=FILE: one)
#   make material-grid  the precompute over a grid of materials, ticks and
#                   precisions: each image certified and within max_error or
#                   refused (docs/measurements/material-grid.md)
#   make error-targets  for max_error 1e-2, 1e-3, 1e-4: what auto chooses,
#                   its error, tick, bytes and precompute time, on the small
#                   cuboid's materials (PAPER=1: and the paper's cuboid;
#                   docs/measurements/error-targets.md)
#   make scale      the default scene at the paper's mesh and at 11,340
#                   nodes, its every-mode eigensolve split by symmetry,
#                   then with the head from Chebyshev series at the
#                   paper's mesh and at 20,812 nodes
#                   (docs/measurements/scale.md)
#   make format-check  every C source and header against .clang-format
#                   (clang-format 14); make format rewrites them
#
# CC=clang works too.  The layers point one way and the include paths
# enforce it (docs/architecture.md, "Layers"); each folder's objects see
# only the include paths of the layers they use:
#
#   firmware/*/*.c        -> libirdmfw.a     the tick's portable core: firmware/include
#   platform/posix/*/*.c  -> libirdmposix.a  Linux services: + platform/posix/include
#   hal/*/*.c             -> libirdmhal.a    core + hal/include
#   sim/*/*.c             -> libirdmsim.a    core + hal + sim/include (+ posix: the
#                                            virtual user's script file)
#   tools/*/*.c           -> libirdmtools.a  core + posix + tools/
#   apps/irdm/*.c         -> irdm            (the host tool: tools, posix, core)
#   apps/irdm-fw/*.c      -> irdm-fw         (the controller: hal, posix, core; only
#                                            its simulated back-ends' files see sim)
#   apps/irdm-candrives/*.c -> irdm-candrives (the CAN drive emulator: sim, hal, posix, core)
#   tests/test_*.c        -> one binary each, every library
#   tests/core/test_*.c   -> the core library alone, libm and cmocka (no
#                            platform service: tests/test_layers.c checks it)
#   tests/apps/irdm-fw/test_*.c -> irdm-fw's objects but its main's
#
# Adding a file needs no edit here.

SHELL   := bash
.SHELLFLAGS := -o pipefail -ec

# Build configuration (docs/build-config.md): CONFIG=configs/NAME.config
# leaves out of the firmware each feature whose CONFIG_IRDM_X is not y, and
# builds the firmware alone (irdm-fw and its libraries) into build/cfg-NAME.
CONFIG  ?=
FEATURES := MODAL FIR FLOATING DEFORM
# irdm-fw's HAL back-ends (apps/irdm-fw/fw_backend_<name>.c); one a config
# file leaves unsaid is built.  Without SIM and CANEMU, irdm-fw does not
# link the simulator.
HAL_BACKENDS := SIM CANEMU SOCKETCAN
ifneq ($(CONFIG),)
include $(CONFIG)
BUILD   ?= build/cfg-$(basename $(notdir $(CONFIG)))
$(foreach f,$(FEATURES),$(if $(filter y n,$(CONFIG_IRDM_$(f))),,\
  $(error $(CONFIG): CONFIG_IRDM_$(f) must be y or n, got '$(CONFIG_IRDM_$(f))')))
$(if $(filter y,$(CONFIG_IRDM_MODAL) $(CONFIG_IRDM_FIR)),,\
  $(error $(CONFIG): CONFIG_IRDM_MODAL and CONFIG_IRDM_FIR are both n: the engine needs one))
$(foreach b,$(HAL_BACKENDS),$(if $(filter y n,$(or $(CONFIG_IRDM_HAL_$(b)),y)),,\
  $(error $(CONFIG): CONFIG_IRDM_HAL_$(b) must be y or n, got '$(CONFIG_IRDM_HAL_$(b))')))
endif
feature = $(if $(CONFIG),$(filter y,$(CONFIG_IRDM_$(1))),y)
FEATURE_SRC_MODAL    = firmware/engine/engine_modal.c firmware/engine/engine_modal_avx2.c
FEATURE_SRC_FIR      = firmware/engine/engine_fir.c firmware/engine/fir_sum.c firmware/engine/fir_sum_avx2.c
FEATURE_SRC_FLOATING = firmware/engine/floating.c $(wildcard firmware/rigid/*.c)
FEATURE_SRC_DEFORM   = $(wildcard firmware/deform/*.c platform/posix/deform/*.c) \
  platform/posix/session/session_deform.c
FEATURE_OFF_SRC := $(foreach f,$(FEATURES),$(if $(call feature,$(f)),,$(FEATURE_SRC_$(f))))
hal_backend = $(if $(CONFIG),$(filter y,$(or $(CONFIG_IRDM_HAL_$(1)),y)),y)
FW_SIM := $(or $(call hal_backend,SIM),$(call hal_backend,CANEMU))
HAL_OFF_SRC := $(foreach b,$(HAL_BACKENDS),$(if $(call hal_backend,$(b)),,\
  apps/irdm-fw/fw_backend_$(subst SIM,sim,$(subst CANEMU,canemu,$(subst SOCKETCAN,socketcan,$(b)))).c)) \
  apps/irdm-fw/$(if $(FW_SIM),fw_user_none.c,fw_user.c)

CC      ?= cc
BUILD   ?= build
SAN     ?=
FUZZ_SECONDS ?= 30

CSTD     = -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
WARN     = -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wvla -Wundef
OPT     ?= -O2 -g
CFLAGS  += $(CSTD) $(WARN) $(OPT) -MMD -MP
CFLAGS  += $(foreach f,$(FEATURES),-DIRDM_CONFIG_$(f)=$(if $(call feature,$(f)),1,0))
CFLAGS  += $(foreach b,$(HAL_BACKENDS),-DIRDM_CONFIG_HAL_$(b)=$(if $(call hal_backend,$(b)),1,0))
LDLIBS   = -lcholmod -larpack -lopenblas -lpthread -ldl -lm

# The distributed eigensolver (eigensolver = slepc, tools/dist/): PETSc and
# SLEPc over MPI in a plugin, $(BUILD)/irdm-slepc.so beside irdm, built when
# pkg-config finds them (Debian: petsc-dev slepc-dev libopenmpi-dev);
# SLEPC=0 leaves it out (the option then says it is not built in).  irdm
# itself never links them: it loads the plugin when a scene asks for it.
# Their headers are -isystem: our warnings are not theirs to pass.
MPI_PC  ?= ompi
ifeq ($(origin SLEPC),undefined)
SLEPC   := $(shell pkg-config --exists slepc PETSc $(MPI_PC) 2>/dev/null && echo 1 || echo 0)
endif
SLEPC_PLUGIN := $(if $(filter 1,$(SLEPC)),$(BUILD)/irdm-slepc.so)
PLUGIN_INC = $(patsubst -I%,-isystem %,$(filter -I%,$(shell pkg-config --cflags slepc PETSc $(MPI_PC))))
PLUGIN_LIBS = $(shell pkg-config --libs slepc PETSc $(MPI_PC)) -lopenblas -lm

# Include paths, one set per layer (target-specific: an object sees only its own).
FW_INC    = -Ifirmware/include
POSIX_INC = $(FW_INC) -Iplatform/posix/include
HAL_INC   = $(FW_INC) -Ihal/include
# the virtual user's script is read through the platform's text files
SIM_INC   = $(HAL_INC) -Iplatform/posix/include -Isim/include
TOOL_INC  = $(POSIX_INC) -Itools -I/usr/include/suitesparse
FWAPP_INC = $(HAL_INC) -Iplatform/posix/include
TEST_INC  = $(SIM_INC) -Itools -I/usr/include/suitesparse
CORE_TEST_INC = $(FW_INC) -Itests

ifneq ($(SAN),)
CFLAGS  += -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
LDFLAGS += -fsanitize=address,undefined
endif

FW_SRC    := $(filter-out $(FEATURE_OFF_SRC),$(wildcard firmware/*/*.c))
POSIX_SRC := $(filter-out $(FEATURE_OFF_SRC),$(wildcard platform/posix/*/*.c))
# The live view (docs/view.md): its server and page in tools/view/, linked
# into irdm-fw (fw_view.c) and irdm; the trimmed builds leave it out
# (fw_view_none.c) and need no libwebsockets.
VIEW    := $(if $(CONFIG),,1)
FWMAIN_SRC := $(filter-out apps/irdm-fw/$(if $(VIEW),fw_view_none.c,fw_view.c) $(HAL_OFF_SRC),\
  $(wildcard apps/irdm-fw/*.c))
HAL_SRC   := $(wildcard hal/*/*.c)
SIM_SRC   := $(wildcard sim/*/*.c)
CDMAIN_SRC := $(wildcard apps/irdm-candrives/*.c)
TOOL_SRC  := $(wildcard tools/*/*.c)
VIEW_PAGE := $(wildcard tools/view/page/*)
VIEW_OBJ   = $(call obj,tools/view/view_server.c tools/view/view_msg.c) $(BUILD)/obj/gen/view_page.o
VIEW_LIBS := -lwebsockets
CLI_SRC   := $(wildcard apps/irdm/*.c)
PLUGIN_SRC := $(wildcard tools/dist/plugin/*.c)
CORE_TEST_SRC := $(wildcard tests/core/test_*.c)
FWAPP_TEST_SRC := $(wildcard tests/apps/irdm-fw/test_*.c)
TEST_SRC  := $(wildcard tests/test_*.c) $(CORE_TEST_SRC) $(FWAPP_TEST_SRC)
TESTSUP_SRC := $(wildcard tests/support/*.c)
BENCH_SRC := $(wildcard tests/bench/*.c)
FUZZ_SRC  := $(wildcard tests/fuzz/fuzz_*.c)

obj = $(patsubst %.c,$(BUILD)/obj/%.o,$(1))

# A measurement's figures go to docs/measurements/NAME.md with the command,
# the date, the machine and its load (tools/scripts/measure.sh).
MEASURE := tools/scripts/measure.sh

FW_LIB   := $(BUILD)/libirdmfw.a
POSIX_LIB := $(BUILD)/libirdmposix.a
HAL_LIB  := $(BUILD)/libirdmhal.a
SIM_LIB  := $(BUILD)/libirdmsim.a
TOOL_LIB := $(BUILD)/libirdmtools.a
IRDM     := $(BUILD)/irdm
IRDM_FW  := $(BUILD)/irdm-fw
IRDM_CD  := $(BUILD)/irdm-candrives
TESTS    := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
CORE_TESTS := $(patsubst tests/%.c,$(BUILD)/tests/%,$(CORE_TEST_SRC))
FWAPP_TESTS := $(patsubst tests/%.c,$(BUILD)/tests/%,$(FWAPP_TEST_SRC))
BENCHES  := $(patsubst tests/bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))

.PHONY: all test test-variants san fuzz material-grid error-targets scale run-vs-exact bench bench-precompute bench-mpi run render view-shots jitter-view stability report jitter check deps clean docs docs-check cfg-fws sizes hil format format-check head-tick
.SECONDARY:
all: $(if $(CONFIG),,$(IRDM) $(SLEPC_PLUGIN)) $(FW_LIB) $(POSIX_LIB) $(HAL_LIB) $(SIM_LIB) $(if $(FWMAIN_SRC),$(IRDM_FW)) \
  $(if $(CDMAIN_SRC),$(IRDM_CD))

$(BUILD)/obj/firmware/%.o: LAYER_INC = $(FW_INC)
$(BUILD)/obj/platform/posix/%.o: LAYER_INC = $(POSIX_INC)
# irdm-fw sees the core, the platform and the HAL; its simulated back-ends'
# files alone also see the simulator's headers (the loop cannot include them)
$(BUILD)/obj/apps/irdm-fw/%.o: LAYER_INC = $(FWAPP_INC)
$(addprefix $(BUILD)/obj/apps/irdm-fw/,fw_backend_sim.o fw_backend_canemu.o fw_user.o): \
  LAYER_INC = $(SIM_INC)
# its publisher alone also sees the view's server (tools/view/)
$(BUILD)/obj/apps/irdm-fw/fw_view.o: LAYER_INC = $(FWAPP_INC) -Itools
$(BUILD)/obj/apps/irdm-candrives/%.o: LAYER_INC = $(SIM_INC)
$(BUILD)/obj/apps/irdm/%.o: LAYER_INC = $(TOOL_INC)
$(BUILD)/obj/hal/%.o:      LAYER_INC = $(HAL_INC)
$(BUILD)/obj/sim/%.o:      LAYER_INC = $(SIM_INC)
$(BUILD)/obj/tools/%.o:    LAYER_INC = $(TOOL_INC)
$(BUILD)/obj/tests/%.o:    LAYER_INC = $(TEST_INC)
$(BUILD)/obj/tests/core/%.o: LAYER_INC = $(CORE_TEST_INC)
$(BUILD)/obj/tests/apps/irdm-fw/%.o: LAYER_INC = $(SIM_INC) -Iapps/irdm-fw

$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(LAYER_INC) -c $< -o $@

# An empty layer still gets its (empty) archive, so links need no special case.
# A library also depends on its source folders, so that a file removed
# from one leaves the archive too.
$(BUILD)/lib%.a:
	@mkdir -p $(dir $@)
	rm -f $@
	$(AR) rcs $@ $(filter %.o,$^)

$(FW_LIB):   $(call obj,$(FW_SRC)) $(wildcard firmware/*/)
$(POSIX_LIB): $(call obj,$(POSIX_SRC)) $(wildcard platform/posix/*/)
$(HAL_LIB):  $(call obj,$(HAL_SRC)) $(wildcard hal/*/)
$(SIM_LIB):  $(call obj,$(SIM_SRC)) $(wildcard sim/*/)
$(TOOL_LIB): $(call obj,$(TOOL_SRC)) $(BUILD)/obj/gen/view_page.o $(wildcard tools/*/)

# The page's files as byte arrays (tools/view/embed.sh)
$(BUILD)/gen/view_page.c: $(VIEW_PAGE) tools/view/embed.sh
	@mkdir -p $(dir $@)
	tools/view/embed.sh $(VIEW_PAGE) > $@.tmp
	mv $@.tmp $@
$(BUILD)/obj/gen/view_page.o: $(BUILD)/gen/view_page.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(TOOL_INC) -c $< -o $@

$(IRDM): $(call obj,$(CLI_SRC)) $(TOOL_LIB) $(POSIX_LIB) $(FW_LIB) | $(SLEPC_PLUGIN)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS) $(VIEW_LIBS)

# The slepc plugin: position-independent, only its entry point exported.
$(BUILD)/obj/tools/dist/plugin/%.o: tools/dist/plugin/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fPIC -fvisibility=hidden $(TOOL_INC) $(PLUGIN_INC) -c $< -o $@

$(BUILD)/irdm-slepc.so: $(call obj,$(PLUGIN_SRC))
	$(CC) $(LDFLAGS) -shared $^ -o $@ $(PLUGIN_LIBS)

TEST_LIBS := $(TOOL_LIB) $(SIM_LIB) $(HAL_LIB) $(POSIX_LIB) $(FW_LIB)

# BLAS only for the deformation worker; the simulator only with a simulated back-end
$(IRDM_FW): $(call obj,$(FWMAIN_SRC)) $(if $(VIEW),$(VIEW_OBJ)) $(if $(FW_SIM),$(SIM_LIB)) \
  $(HAL_LIB) $(POSIX_LIB) $(FW_LIB)
	$(CC) $(LDFLAGS) $^ -o $@ $(if $(call feature,DEFORM),-lopenblas) $(if $(VIEW),$(VIEW_LIBS)) \
	  -lpthread -lm

# The drive emulator: the simulator, the HAL's CAN code, the firmware's arm.
$(IRDM_CD): $(call obj,$(CDMAIN_SRC)) $(SIM_LIB) $(HAL_LIB) $(POSIX_LIB) $(FW_LIB)
	$(CC) $(LDFLAGS) $^ -o $@ -lm

# The tick's core alone: the core library, libm and cmocka, nothing else.
$(CORE_TESTS): $(BUILD)/tests/core/%: $(BUILD)/obj/tests/core/%.o $(FW_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ -lcmocka -lm

# irdm-fw's parts: every object of the program but the one with its main()
FWAPP_MAIN := apps/irdm-fw/irdm_fw.c
$(FWAPP_TESTS): $(BUILD)/tests/apps/irdm-fw/%: $(BUILD)/obj/tests/apps/irdm-fw/%.o \
  $(call obj,$(filter-out $(FWAPP_MAIN),$(FWMAIN_SRC))) $(if $(VIEW),$(VIEW_OBJ)) \
  $(SIM_LIB) $(HAL_LIB) $(POSIX_LIB) $(FW_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ $(if $(call feature,DEFORM),-lopenblas) $(if $(VIEW),$(VIEW_LIBS)) \
	  -lpthread -lm -lcmocka

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(call obj,$(TESTSUP_SRC)) $(TEST_LIBS) | $(SLEPC_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS) -lcmocka

# the board table's defaults: every caller in the library gets the test's table
$(BUILD)/tests/test_board_defaults: LDFLAGS += -Wl,--wrap=irdm_board_options

# the view's test drives its server and decodes the browser's screenshots
$(BUILD)/tests/test_view: LDLIBS += $(VIEW_LIBS) -lpng

# benches share the test fixtures, which report through cmocka
$(BUILD)/bench/%: $(BUILD)/obj/tests/bench/%.o $(call obj,$(TESTSUP_SRC)) $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $^ -o $@ $(LDLIBS) -lcmocka

# The image the core tests run on (they cannot make one: no tools).
TICK_IMAGE := $(BUILD)/data/tick.img
$(TICK_IMAGE): $(IRDM)
	@mkdir -p $(dir $@)
	$(IRDM) precompute -q --mesh box:0.04,0.04,0.08 --resolution 2,2,4 --fixed 'z<=0' \
	  --touch 'z>=0.08' --display surface --representation modal:all -o $@

test: $(TESTS) $(IRDM) $(IRDM_FW) $(IRDM_CD) $(TICK_IMAGE) $(BUILD)/data/bunny.off cfg-fws
	IRDM=$(IRDM) IRDM_FW=$(IRDM_FW) IRDM_BUILD=$(BUILD) IRDM_TICK_IMAGE=$(TICK_IMAGE) \
	  tests/run-tests.sh $(TESTS)

# The stability suite again with what changes the rounding of its images
# and sums: OpenBLAS on one thread (the precompute's eigensolve and
# products), then the portable history sums where AVX2 would run.  A limit
# that only one rounding meets fails here, not on the next machine.
STAB_TESTS := $(filter $(BUILD)/tests/test_stability%,$(TESTS))
test-variants: $(STAB_TESTS) $(IRDM) $(TICK_IMAGE)
	OPENBLAS_NUM_THREADS=1 IRDM=$(IRDM) IRDM_BUILD=$(BUILD) IRDM_TICK_IMAGE=$(TICK_IMAGE) \
	  tests/run-tests.sh $(STAB_TESTS)
	IRDM_TEST_PORTABLE_SUM=1 IRDM=$(IRDM) IRDM_BUILD=$(BUILD) IRDM_TICK_IMAGE=$(TICK_IMAGE) \
	  tests/run-tests.sh $(STAB_TESTS)

# The firmware built with the shipped trimmed configurations, beside the
# full one (test_build_config checks what they leave out and refuse).
CFG_NAMES := default minimal can
cfg-fws:
	$(foreach c,$(CFG_NAMES),$(MAKE) --no-print-directory CONFIG=configs/$(c).config \
	  BUILD=$(BUILD)/cfg-$(c) all;)

# What each configuration costs: irdm-fw's sections and its libraries (the
# core's and the platform's; docs/measurements/sizes.md).
sizes: all cfg-fws
	$(MEASURE) sizes 'make sizes' -- $(MAKE) --no-print-directory sizes-run
sizes-run:
	@size $(IRDM_FW) | head -n 1
	@for b in $(IRDM_FW) $(foreach c,$(CFG_NAMES),$(BUILD)/cfg-$(c)/irdm-fw); do \
	  size $$b | tail -n 1; \
	  echo "  firmware core library text: $$(size -t $$(dirname $$b)/libirdmfw.a | tail -n 1 | awk '{print $$1}') bytes"; \
	  echo "  platform library text: $$(size -t $$(dirname $$b)/libirdmposix.a | tail -n 1 | awk '{print $$1}') bytes"; \
	  echo "  needs: $$(readelf -d $$b | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' | tr '\n' ' ')"; \
	done

# Every generated document, named by its file in docs/; gen-doc-FILE writes
# it into the directory $(1).  A new one: add its name and its gen-doc- line.
# Whole files come from a --help-markdown; a block inside a hand-written
# page is spliced between its markers (tools/scripts/splice-doc.sh).
GEN_DOCS := scene-format.md boards.md hal-options.md testing.md
gen-doc-scene-format.md = $(IRDM) precompute --help-markdown > $(1)/scene-format.md
gen-doc-hal-options.md = $(IRDM_FW) --doc hal-options > $(1)/hal-options.md
gen-doc-boards.md = $(IRDM_FW) --doc boards | \
  tools/scripts/splice-doc.sh docs/boards.md 'board keys' > $(1)/boards.md
gen-doc-testing.md = tools/scripts/test-index.sh tests | \
  tools/scripts/splice-doc.sh docs/testing.md 'test index' > $(1)/testing.md
GEN_DOCS_TOOLS := $(IRDM) $(IRDM_FW)
gen-docs = $(foreach d,$(GEN_DOCS),$(call gen-doc-$(d),$(1));)

# make docs rewrites what changed; make docs-check (in make check) fails
# naming each stale file.
docs: $(GEN_DOCS_TOOLS)
	@tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(call gen-docs,$$tmp) \
	for d in $(GEN_DOCS); do \
	  cmp -s "$$tmp/$$d" docs/$$d || { cp "$$tmp/$$d" docs/$$d; echo "docs: docs/$$d rewritten"; }; \
	done
docs-check: $(GEN_DOCS_TOOLS)
	@tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(call gen-docs,$$tmp) \
	stale=; for d in $(GEN_DOCS); do \
	  diff -u docs/$$d "$$tmp/$$d" > "$$tmp/$$d.diff" || { head -n 40 "$$tmp/$$d.diff"; stale="$$stale docs/$$d"; }; \
	done; \
	if [ -n "$$stale" ]; then echo "docs-check: stale:$$stale (run make docs)"; exit 1; fi; \
	echo "docs-check: $(GEN_DOCS) current"

# The style (.clang-format, clang-format 14: other versions lay some lines
# out differently).  Every C source and header but the build trees and the
# generated ones (crc32c.c's tables).
CLANG_FORMAT ?= $(or $(shell command -v clang-format-14 2>/dev/null),clang-format)
FORMAT_SRC = $(filter-out %/crc32c.c,$(shell find . \( -type d \( -name 'build*' -o -name out \
  -o -name .git \) \) -prune -o \( -name '*.c' -o -name '*.h' \) -print | sed 's|^\./||' | sort))
format-check:
	$(CLANG_FORMAT) --dry-run -Werror $(FORMAT_SRC)
format:
	$(CLANG_FORMAT) -i $(FORMAT_SRC)

san:
	$(MAKE) BUILD=build-san SAN=1 OPT="-O1 -g" IRDM_SOAK_SECONDS=10 IRDM_TORUS=small test

# libFuzzer needs clang.  Each target gets its own corpus directory; a
# finding (crash, leak, sanitizer report: none recovers) stops the build and
# leaves the input in $(FUZZ_BUILD)/findings/ to replay with
#   $(FUZZ_BUILD)/TARGET $(FUZZ_BUILD)/findings/TARGET-crash-...
FUZZ_BUILD := build-fuzz
FUZZ_CFLAGS := -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
fuzz:
	$(MAKE) CC=clang BUILD=$(FUZZ_BUILD) OPT="$(FUZZ_CFLAGS)" \
	  $(FUZZ_BUILD)/libirdmtools.a $(FUZZ_BUILD)/libirdmsim.a $(FUZZ_BUILD)/libirdmhal.a \
	  $(FUZZ_BUILD)/libirdmposix.a $(FUZZ_BUILD)/libirdmfw.a
	mkdir -p $(FUZZ_BUILD)/findings
	for f in $(FUZZ_SRC); do \
	  n=$$(basename $$f .c); \
	  clang $(CSTD) $(WARN) -O1 -g $(TEST_INC) \
	    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all $$f \
	    $(FUZZ_BUILD)/libirdmtools.a $(FUZZ_BUILD)/libirdmsim.a $(FUZZ_BUILD)/libirdmhal.a \
	    $(FUZZ_BUILD)/libirdmposix.a $(FUZZ_BUILD)/libirdmfw.a -o $(FUZZ_BUILD)/$$n $(LDLIBS); \
	  mkdir -p $(FUZZ_BUILD)/corpus/$$n; \
	  seeds=tests/fuzz/seeds/$$n; [ -d $$seeds ] || seeds=; \
	  echo "fuzz: $$n for $(FUZZ_SECONDS) s"; \
	  if ! $(FUZZ_BUILD)/$$n -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -print_final_stats=1 \
	      -artifact_prefix=$(FUZZ_BUILD)/findings/$$n- \
	      $(FUZZ_BUILD)/corpus/$$n $$seeds > $(FUZZ_BUILD)/$$n.log 2>&1; then \
	    tail -n 60 $(FUZZ_BUILD)/$$n.log; \
	    echo "fuzz: $$n FOUND A BUG; input kept in $(FUZZ_BUILD)/findings/ (replay: $(FUZZ_BUILD)/$$n FILE)"; \
	    exit 1; \
	  fi; \
	  tail -n 4 $(FUZZ_BUILD)/$$n.log; \
	done

# The stability cases as the tests run them, and the soak at STAB_SOAK_SECONDS
# of simulated time (10^4 s: 10^7 ticks at 1 ms); table and plot of the worst.
STAB_OUT ?= out/stability
STAB_SOAK_SECONDS ?= 10000
stability: $(BUILD)/tests/test_stability_cases $(BUILD)/tests/test_stability_soak \
  $(BUILD)/tests/test_stability_spin
	$(MEASURE) -f $(STAB_OUT)/table.md stability \
	  'make stability STAB_SOAK_SECONDS=$(STAB_SOAK_SECONDS)' -- \
	  $(MAKE) --no-print-directory stability-run
stability-run:
	rm -rf $(STAB_OUT)
	mkdir -p $(STAB_OUT)
	IRDM_STAB_OUT=$(STAB_OUT) $(BUILD)/tests/test_stability_cases
	IRDM_STAB_OUT=$(STAB_OUT) $(BUILD)/tests/test_stability_spin
	IRDM_STAB_OUT=$(STAB_OUT) IRDM_SOAK_SECONDS=$(STAB_SOAK_SECONDS) $(BUILD)/tests/test_stability_soak
	/usr/bin/python3 tools/scripts/stability-report.py $(STAB_OUT)

# make run's press replayed on the default image and on the exact model's.
run-vs-exact: $(IRDM)
	$(MEASURE) -m run-vs-exact 'make run-vs-exact' -- tools/scripts/run-vs-exact.sh $(IRDM)

# Every case written within max_error and certified, or refused with a
# message (tools/scripts/material-grid.sh); GRID_JOBS precomputes at once.
GRID_JOBS ?= 2
material-grid: $(IRDM)
	$(MEASURE) -m material-grid 'make material-grid GRID_JOBS=$(GRID_JOBS)' -- \
	  tools/scripts/material-grid.sh $(IRDM) $(GRID_JOBS)

# For each max_error of 1e-2, 1e-3 and 1e-4, what representation = auto
# chooses, its measured error, its tick timed by bench_ctrl, its bytes and
# its precompute time (tools/scripts/error-targets.sh): material-grid's
# small cuboid over its materials at 1 and 2 ms; PAPER=1 adds the paper's
# cuboid (the default scene, minutes a precompute).  GRID_JOBS precomputes
# at once (the ticks are timed one at a time after them).
PAPER ?=
error-targets: $(IRDM) $(BUILD)/bench/bench_ctrl
	$(MEASURE) -m error-targets 'make error-targets GRID_JOBS=$(GRID_JOBS)$(if $(filter 1,$(PAPER)), PAPER=1)' -- \
	  env ERROR_TARGETS_PAPER=$(if $(filter 1,$(PAPER)),1,0) \
	  tools/scripts/error-targets.sh $(IRDM) $(BUILD)/bench/bench_ctrl $(GRID_JOBS)

# Each benchmark alone: make bench_tick, make bench_ctrl, ... (the names of
# tests/bench/*.c), each writing docs/measurements/NAME.md.
BENCH_NAMES := $(patsubst tests/bench/%.c,%,$(BENCH_SRC))
.PHONY: $(BENCH_NAMES) sizes-run stability-run
$(BENCH_NAMES): %: $(BUILD)/bench/% $(IRDM)
	$(MEASURE) $@ 'make $@' -- env IRDM=$(IRDM) $<

bench: $(BENCHES) $(IRDM) bench-precompute
	for b in $(BENCH_NAMES); do $(MAKE) --no-print-directory $$b; done
	@echo "== ticks paced at 1 kHz, deformation thread running (make jitter, 5 x 2 s)"
	$(MAKE) --no-print-directory jitter JITTER_ROUNDS=5 JITTER_SECONDS=2

# The hybrid tick (bench_tick's hybrid cases) timed and its instructions
# per tick counted under callgrind, with where they went; beside a
# bench_tick built earlier when BEFORE names it (make head-tick
# BEFORE=path/to/bench_tick): docs/measurements/head-tick.md.
BEFORE ?=
head-tick: $(BUILD)/bench/bench_tick
	$(MEASURE) -m head-tick 'make head-tick$(if $(BEFORE), BEFORE=$(BEFORE))' -- \
	  tools/scripts/head-tick.sh $< $(BEFORE)

# Accuracy, tick time and image size of every representation against the
# exact full model (irdm report --help); CSVs in out/report/, the report
# and its Pareto plots in docs/ (committed).
# The paper's cuboid at full resolution (its all-mode reference takes the
# 9504-mode eigensolve, minutes): make report REPORT_CONFIGS=paper
# REPORT_MD=docs/report-paper.md.  floating: the floating cube's swing and
# tap (10 to 20 s).
REPORT_CONFIGS ?= sweep floating
REPORT_MD ?= docs/report.md
report: $(IRDM)
	@mkdir -p out docs/report
	$(IRDM) report $(foreach c,$(REPORT_CONFIGS),--config $(c)) -o out/report \
	  --md $(REPORT_MD) --plots report/report
	for c in $(REPORT_CONFIGS); do \
	  /usr/bin/python3 tools/scripts/plot-report.py out/report/report-$$c.csv docs/report/report-$$c; \
	done

# The default scene at finer meshes (tools/scripts/scale.sh): how far the
# symmetric split of the every-mode eigensolve carries the default target,
# and the head from Chebyshev series past it; figures to
# docs/measurements/scale.md.
scale: $(IRDM)
	$(MEASURE) -m scale 'make scale' -- tools/scripts/scale.sh $(IRDM)

# Paper-scale images (cuboid, bunny): time and size beside the paper's.
bench-precompute: $(IRDM) $(BUILD)/data/bunny.off
	$(MEASURE) -m bench-precompute 'make bench-precompute' -- tools/scripts/bench-precompute.sh $(IRDM)

# The precompute over MPI ranks: a 100k-node cuboid, serial and slepc on
# np = 1, 2 (docs/mpi.md); bounded by TIMEOUT per run; figures to
# docs/measurements/bench-mpi.md.
bench-mpi: $(IRDM) $(SLEPC_PLUGIN)
	$(MEASURE) bench-mpi 'make bench-mpi' -- tools/scripts/bench-mpi.sh $(IRDM)

$(BUILD)/data/bunny.off:
	@mkdir -p $(dir $@)
	tools/scripts/bunny-off.sh $@

# The gcc run comes last of the tests so its summary line closes them; then
# the CAN back-end end to end in the VM (make hil).
# The fuzzers get CHECK_FUZZ_SECONDS each here (make fuzz: FUZZ_SECONDS) and
# the builds every CPU, so that the whole stays near 15 minutes.
CHECK_FUZZ_SECONDS ?= 15
CHECK_JOBS ?= $(shell nproc)
check: deps
	$(MAKE) docs-check
	$(MAKE) format-check
	$(MAKE) -j$(CHECK_JOBS) fuzz FUZZ_SECONDS=$(CHECK_FUZZ_SECONDS)
	$(MAKE) -j$(CHECK_JOBS) CC=clang BUILD=build-clang test
	$(MAKE) -j$(CHECK_JOBS) san
	$(MAKE) -j$(CHECK_JOBS) test-variants
	$(MAKE) -j$(CHECK_JOBS) test
	$(MAKE) -j$(CHECK_JOBS) hil

run: deps
	$(MAKE) $(IRDM) $(IRDM_FW)
	tools/scripts/run-default-scene.sh $(IRDM) $(IRDM_FW)

# The recorded run of make run in the view's page (irdm view) at three
# moments: pressing, holding, ringing after the release (docs/view.md)
VIEW_SHOT_TIMES ?= 1.1 2.5 3.4
view-shots: $(IRDM)
	@test -f out/run.log -a -f out/default.img || { echo "view-shots: needs out/run.log: make run first"; exit 1; }
	/usr/bin/python3 tools/scripts/view-shots.py $(IRDM) out/run.log boards/sim-phantom.board \
	  out/default.img docs/view/run-playback.png $(VIEW_SHOT_TIMES)

# The default scene's deformed surface as VTK frames, PNGs and force plots
# (irdm render; out/render-*; after make run it also renders that run's log)
render: deps
	$(MAKE) $(IRDM)
	tools/scripts/render-default-scene.sh $(IRDM)

# irdm-fw's wake-up latency beside cyclictest's, alternating in JITTER_ROUNDS
# rounds of JITTER_SECONDS each (default 10 x 3 s); docs/measurements/jitter.md
JITTER_IMAGE := $(BUILD)/data/jitter.img
$(JITTER_IMAGE): $(IRDM) scenes/cuboid-top.scene
	@mkdir -p $(dir $@)
	$(IRDM) precompute -q --scene scenes/cuboid-top.scene -o $@
# (jitter.sh writes the file, with the host's conditions, itself)
jitter: deps $(IRDM) $(IRDM_FW) $(JITTER_IMAGE)
	tools/scripts/jitter.sh $(IRDM) $(IRDM_FW) $(JITTER_IMAGE)

# The same loop with and without a browser on its live view, alternating
# (JITTER_ROUNDS pairs of JITTER_SECONDS, default 3 x 20 s; docs/view.md)
jitter-view: deps $(IRDM) $(IRDM_FW) $(JITTER_IMAGE)
	$(MEASURE) jitter-view \
	  'make jitter-view JITTER_SECONDS=$(or $(JITTER_SECONDS),20) JITTER_ROUNDS=$(or $(JITTER_ROUNDS),3)' -- \
	  env JITTER_SECONDS=$(or $(JITTER_SECONDS),20) JITTER_ROUNDS=$(or $(JITTER_ROUNDS),3) \
	  tools/scripts/jitter-view.sh $(IRDM) $(IRDM_FW) $(JITTER_IMAGE)

# Hardware in the loop without the hardware: Debian's PREEMPT_RT kernel
# under qemu (TCG), vcan0, irdm-candrives and irdm-fw (the minimal build)
# on it, candump's log checked on the host (tools/scripts/hil/, docs/hil.md)
hil: deps $(IRDM) $(IRDM_FW) $(BUILD)/tests/test_socketcan
	$(MAKE) --no-print-directory CONFIG=configs/minimal.config BUILD=$(BUILD)/cfg-minimal all
	$(MEASURE) hil 'make hil' -- tools/scripts/hil/hil.sh $(BUILD) $(IRDM) $(BUILD)/cfg-minimal/irdm-fw \
	  $(BUILD)/cfg-minimal/irdm-candrives $(BUILD)/tests/test_socketcan $(IRDM_FW)

deps:
	tools/scripts/install-deps.sh

clean:
	rm -rf build build-san build-fuzz build-clang

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
