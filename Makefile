# MPEG-4 facial animation toolkit: mesh + FDPs -> builder -> AFM -> player -> frames.
#
#   make                 build every library and tool (tools in build/bin/)
#   make deps            install the Debian packages that are missing
#   make test            run every test (installs what is missing first)
#   make demo            generate the reference head and run the main job on it
#   make bench           print benchmark figures
#   make install PREFIX=/usr/local
#   make clean
#
# config=release (default, into build/) | debug (build/debug/) | sanitize
# (ASan + UBSan, build/sanitize/). WERROR=1 turns warnings into errors (CI).

config ?= release
PREFIX ?= /usr/local

ifeq ($(config),release)
  B := build
  OPT := -O2 -DNDEBUG
else ifeq ($(config),debug)
  B := build/debug
  OPT := -O0 -g
else ifeq ($(config),sanitize)
  B := build/sanitize
  OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
  SAN_LDFLAGS := -fsanitize=address,undefined
else
  $(error config must be release, debug or sanitize)
endif

CC ?= cc
CXX ?= g++
AR ?= ar

WARN_C := -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wvla
WARN_CXX := -Wall -Wextra -Wpedantic -Wshadow -Wno-deprecated-copy
ifeq ($(WERROR),1)
  WARN_C += -Werror
  WARN_CXX += -Werror
endif

INCLUDES := -Iformats/include -Ibuilder -Iports/osmesa/include -Iplayer_c/include
SYS_INCLUDES := -isystem /usr/include/eigen3

CFLAGS := -std=c99 $(OPT) $(WARN_C) $(INCLUDES) -MMD -MP
CXXFLAGS := -std=c++17 $(OPT) $(WARN_CXX) $(INCLUDES) $(SYS_INCLUDES) -MMD -MP \
  -DAFM_SOURCE_DIR='"$(CURDIR)"'
LDFLAGS := $(SAN_LDFLAGS)

# ---- sources ---------------------------------------------------------------
FORMAT_SRC := $(wildcard formats/src/*.c)
DRACO_SRC := $(wildcard formats/draco/*.cpp)
BUILDER_SRC := $(filter-out builder/tools/%,$(wildcard builder/*/*.cpp))
PLAYER_SRC := $(wildcard player_c/src/*.c)
# The OSMesa context and the GL drawing it needs, built as a shared object
# that render.c loads on the first picture (ports/osmesa/src/osmesa_plugin.h):
# programs that draw nothing never map libOSMesa and libLLVM.
OSMESA_ONLY_SRC := ports/osmesa/src/osmesa_plugin.c
OSMESA_PLUGIN_SRC := $(OSMESA_ONLY_SRC) $(addprefix ports/osmesa/src/,gl_draw.c render_view.c render_error.c)
RENDER_SRC := $(filter-out $(OSMESA_ONLY_SRC),$(wildcard ports/osmesa/src/*.c ports/osmesa/src/*.cpp))

FORMAT_LIB := $(B)/lib/libafm_format.a
DRACO_LIB := $(B)/lib/libafm_draco.a
BUILDER_LIB := $(B)/lib/libafm_builder.a
PLAYER_LIB := $(B)/lib/libafm_player.a
RENDER_LIB := $(B)/lib/libafm_render.a
OSMESA_PLUGIN := $(B)/lib/libafm_osmesa.so

obj = $(patsubst %,$(B)/obj/%.o,$(1))

LIBS := $(FORMAT_LIB) $(DRACO_LIB) $(BUILDER_LIB) \
  $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(if $(RENDER_SRC),$(RENDER_LIB) $(OSMESA_PLUGIN))

# Link order: dependants first.
CXX_LINK_LIBS := $(BUILDER_LIB) $(if $(RENDER_SRC),$(RENDER_LIB)) \
  $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(DRACO_LIB) $(FORMAT_LIB) \
  -lOpenMeshTools -lOpenMeshCore -ldraco -lpng -lpthread -lm
# C tools link as plain C programs: the Draco codec only needs libdraco and
# libstdc++ beside it.
C_LINK_LIBS := $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(DRACO_LIB) $(FORMAT_LIB) -ldraco -lstdc++ -lm
# The desktop preview draws through GLFW's libGL, never libOSMesa: both define
# the gl* functions. From libafm_render it takes the GL drawing (gl_draw.c),
# the face scene and the PNG writer; not render.c, whose renderer is OSMesa's.
GLFW_LIBS := $(RENDER_LIB) $(PLAYER_LIB) $(DRACO_LIB) $(FORMAT_LIB)
GLFW_LINK_LIBS := $(GLFW_LIBS) -ldraco -lglfw -lGL -lpng -lm

# ---- tools -----------------------------------------------------------------
C_TOOLS := $(patsubst formats/tools/%.c,$(B)/bin/%,$(wildcard formats/tools/*.c)) \
  $(patsubst player_c/tools/%.c,$(B)/bin/%,$(wildcard player_c/tools/*.c))
CXX_TOOLS := $(patsubst builder/tools/%.cpp,$(B)/bin/%,$(wildcard builder/tools/*.cpp)) \
  $(patsubst ports/osmesa/tools/%.cpp,$(B)/bin/%,$(wildcard ports/osmesa/tools/*.cpp))
GLFW_TOOLS := $(patsubst ports/glfw/tools/%.cpp,$(B)/bin/%,$(wildcard ports/glfw/tools/*.cpp))
TOOLS := $(C_TOOLS) $(CXX_TOOLS) $(GLFW_TOOLS)

# ---- tests and benchmarks --------------------------------------------------
TEST_DIRS := $(patsubst tests/%/,%,$(filter-out tests/cli/ tests/common/ tests/data/,$(sort $(dir $(wildcard tests/*/*.cpp)))))
TEST_BINS := $(patsubst %,$(B)/tests/test_%,$(TEST_DIRS))
BENCH_BINS := $(patsubst bench/%.cpp,$(B)/bench/%,$(wildcard bench/*.cpp))

.PHONY: all deps test demo bench install clean fuzz
.SECONDARY:
all: $(LIBS) $(TOOLS)

$(FORMAT_LIB): $(call obj,$(FORMAT_SRC))
$(DRACO_LIB): $(call obj,$(DRACO_SRC))
$(BUILDER_LIB): $(call obj,$(BUILDER_SRC))
$(PLAYER_LIB): $(call obj,$(PLAYER_SRC))
$(RENDER_LIB): $(call obj,$(RENDER_SRC))
$(B)/lib/%.a:
	@mkdir -p $(@D)
	@rm -f $@
	$(AR) rcs $@ $^

# Position-independent, hidden but for the plugin's entry; -z defs: every
# symbol resolved at link time, not at the first picture.
$(OSMESA_PLUGIN): $(patsubst %,$(B)/pic/%.o,$(OSMESA_PLUGIN_SRC))
	@mkdir -p $(@D)
	$(CC) -shared $^ -o $@ $(LDFLAGS) -Wl,-z,defs -lOSMesa -lm

$(B)/pic/%.c.o: %.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -fPIC -fvisibility=hidden -c $< -o $@

$(B)/obj/%.c.o: %.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -c $< -o $@

# The player's blend loops vectorise at -O3 (GCC 12's -O2 skips loops with a
# remainder). Integer arithmetic: the results are the same at any level, which
# the ARM/x86 hash comparison checks.
ifeq ($(config),release)
$(B)/obj/player_c/src/%.c.o: CFLAGS += -O3
# Benchmarks at the same level, so their float reference loops vectorise too.
$(B)/obj/bench/%.cpp.o: CXXFLAGS += -O3
# The solver's kernels (factorisation, block products, Hessians): about a
# tenth less time on Song's AFM, and the same bytes (no -ffast-math, no FMA
# on the baseline x86-64 target).
$(B)/obj/builder/anatomy/%.cpp.o: CXXFLAGS += -O3
endif

$(B)/obj/%.cpp.o: %.cpp
	@mkdir -p $(@D)
	$(CXX) $(CXXFLAGS) -c $< -o $@

$(B)/bin/%: $(B)/obj/formats/tools/%.c.o $(LIBS)
	@mkdir -p $(@D)
	$(CC) $< -o $@ $(LDFLAGS) $(C_LINK_LIBS)

$(B)/bin/%: $(B)/obj/player_c/tools/%.c.o $(LIBS)
	@mkdir -p $(@D)
	$(CC) $< -o $@ $(LDFLAGS) $(C_LINK_LIBS)

$(B)/bin/%: $(B)/obj/builder/tools/%.cpp.o $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $< -o $@ $(LDFLAGS) $(CXX_LINK_LIBS)

$(B)/bin/%: $(B)/obj/ports/osmesa/tools/%.cpp.o $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $< -o $@ $(LDFLAGS) $(CXX_LINK_LIBS)

$(B)/bin/%: $(B)/obj/ports/glfw/tools/%.cpp.o $(GLFW_LIBS)
	@mkdir -p $(@D)
	$(CXX) $< -o $@ $(LDFLAGS) $(GLFW_LINK_LIBS)

# One gtest binary per tests/<dir>/.
.SECONDEXPANSION:
$(B)/tests/test_%: $$(call obj,$$(wildcard tests/$$*/*.cpp)) $(call obj,$(wildcard tests/common/*.cpp)) $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $(filter %.o,$^) -o $@ $(LDFLAGS) $(CXX_LINK_LIBS) -lgtest -lgtest_main

# zlib: the compressed baseline of bench_afm_size.
$(B)/bench/%: $(B)/obj/bench/%.cpp.o $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $< -o $@ $(LDFLAGS) $(CXX_LINK_LIBS) -lz

deps:
	@tools/deps.sh

test: deps
	@$(MAKE) --no-print-directory all tests config=$(config)
	@AFM_BUILD=$(B) AFM_CONFIG=$(config) tools/run-tests.sh $(TEST_BINS)

.PHONY: tests
tests: $(TEST_BINS) $(B)/tests/png_diff

# The picture comparison of the command-line tests (tests/cli/png_diff.c).
$(B)/tests/png_diff: $(B)/obj/tests/cli/png_diff.c.o $(RENDER_LIB) $(FORMAT_LIB)
	@mkdir -p $(@D)
	$(CC) $< -o $@ $(LDFLAGS) $(RENDER_LIB) $(FORMAT_LIB) -lpng -lm

demo: deps
	@$(MAKE) --no-print-directory all config=$(config)
	@AFM_BUILD=$(B) tools/demo.sh

bench: deps
	@$(MAKE) --no-print-directory all $(BENCH_BINS) config=$(config)
	@for b in $(BENCH_BINS); do echo "== $$b"; $$b || exit 1; done

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/include/afm
	install -m 755 $(TOOLS) $(DESTDIR)$(PREFIX)/bin/
	install -m 644 $(LIBS) $(DESTDIR)$(PREFIX)/lib/
	install -m 644 formats/include/afm/*.h $(wildcard player_c/include/afm/*.h) $(DESTDIR)$(PREFIX)/include/afm/
	sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@LIBS@|$(if $(PLAYER_SRC),-lafm_player) -lafm_format|' \
	  tools/afm-player.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/afm-player.pc

clean:
	rm -rf build

# ==== ARM cross build, ARM/x86 comparison, code size and fuzzing =============
# The player core (formats/src + player_c/src, C99) with the hash driver
# tests/arm/afm_hash.c, built four ways into $(B)/arm/<variant>/:
#   arm-O0, arm-O2   ARMv5TE soft-float (arm-linux-gnueabi-gcc), run under
#                    qemu-arm by tests/cli/test_arm.sh (part of `make test`)
#   host-O0, host-O2, host-O3 (vectorised, as release builds player_c)
#                    the host compiler; sanitized in config=sanitize
# Every build must print the same per-frame hashes. arm-Os and arm-Os-thumb
# are built for the code-size figures of `make bench` (bench/arm_size.sh).
# $(B)/arm/afm_synth gives the test's reference head synthetic morph targets.
# `make fuzz` builds the libFuzzer targets of fuzz/ with clang and runs each
# for FUZZ_SECONDS (fuzz/run.sh); crash inputs stay in $(FUZZ_DIR)/crashes/.
CORE_SRC := $(FORMAT_SRC) $(PLAYER_SRC)
ARM_DIR := $(B)/arm
ARM_CC := arm-linux-gnueabi-gcc
ARM_TARGET := -march=armv5te -mfloat-abi=soft
ARM_COMMON := -std=c99 $(WARN_C) $(INCLUDES) -MMD -MP
ifeq ($(config),sanitize)
  ARM_HOST_SAN := -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
endif
ARM_FLAGS_arm-O0 := $(ARM_CC) $(ARM_TARGET) -O0 -fstack-usage $(ARM_COMMON)
ARM_FLAGS_arm-O2 := $(ARM_CC) $(ARM_TARGET) -O2 -DNDEBUG -fstack-usage $(ARM_COMMON)
ARM_FLAGS_arm-Os := $(ARM_CC) $(ARM_TARGET) -Os -DNDEBUG -fstack-usage $(ARM_COMMON)
ARM_FLAGS_arm-Os-thumb := $(ARM_CC) $(ARM_TARGET) -mthumb -Os -DNDEBUG -fstack-usage $(ARM_COMMON)
ARM_FLAGS_host-O0 := $(CC) -O0 $(ARM_HOST_SAN) $(ARM_COMMON)
ARM_FLAGS_host-O2 := $(CC) -O2 -DNDEBUG $(ARM_HOST_SAN) $(ARM_COMMON)
ARM_FLAGS_host-O3 := $(CC) -O3 -DNDEBUG $(ARM_HOST_SAN) $(ARM_COMMON)
ARM_VARIANTS := arm-O0 arm-O2 arm-Os arm-Os-thumb host-O0 host-O2 host-O3
ARM_TEST_VARIANTS := arm-O0 arm-O2 host-O0 host-O2 host-O3

# $(1): variant. Objects under $(ARM_DIR)/$(1)/obj/, the driver beside them.
define ARM_VARIANT_RULES
$(ARM_DIR)/$(1)/obj/%.c.o: %.c
	@mkdir -p $$(@D)
	$$(ARM_FLAGS_$(1)) -c $$< -o $$@
$(ARM_DIR)/$(1)/afm_hash: $(patsubst %,$(ARM_DIR)/$(1)/obj/%.o,$(CORE_SRC) tests/arm/afm_hash.c)
	$$(ARM_FLAGS_$(1)) $$^ -o $$@
endef
$(foreach v,$(ARM_VARIANTS),$(eval $(call ARM_VARIANT_RULES,$(v))))

$(ARM_DIR)/afm_synth: $(B)/obj/tests/arm/afm_synth.c.o $(FORMAT_LIB)
	@mkdir -p $(@D)
	$(CC) $< -o $@ $(LDFLAGS) $(FORMAT_LIB) -lm

.PHONY: arm-bins arm-bench
arm-bins: $(patsubst %,$(ARM_DIR)/%/afm_hash,$(ARM_TEST_VARIANTS)) $(ARM_DIR)/afm_synth
tests: arm-bins

arm-bench: deps
	@$(MAKE) --no-print-directory all arm-bins $(ARM_DIR)/arm-Os/afm_hash \
	  $(ARM_DIR)/arm-Os-thumb/afm_hash config=$(config)
	@AFM_BUILD=$(B) sh bench/arm_size.sh
bench: arm-bench

FUZZ_SECONDS ?= 60
FUZZ_DIR ?= $(B)/fuzz
FUZZ_CC := clang
FUZZ_CXX := clang++
FUZZ_SAN := -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
FUZZ_CFLAGS := -std=c99 $(FUZZ_SAN) -fsanitize=fuzzer-no-link $(INCLUDES) -MMD -MP
FUZZ_CXXFLAGS := -std=c++17 $(FUZZ_SAN) -fsanitize=fuzzer-no-link $(INCLUDES) -MMD -MP
FUZZ_CORE_OBJ := $(patsubst %,$(FUZZ_DIR)/obj/%.o,$(CORE_SRC))
FUZZ_DRACO_OBJ := $(patsubst %,$(FUZZ_DIR)/obj/%.o,$(DRACO_SRC))
FUZZ_TARGETS := $(FUZZ_DIR)/fuzz_afm $(FUZZ_DIR)/fuzz_afm_draco $(FUZZ_DIR)/fuzz_fap

$(FUZZ_DIR)/obj/%.c.o: %.c
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -c $< -o $@
$(FUZZ_DIR)/obj/%.cpp.o: %.cpp
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(FUZZ_CXXFLAGS) -c $< -o $@
$(FUZZ_DIR)/fuzz_afm: $(FUZZ_DIR)/obj/fuzz/fuzz_afm.c.o $(FUZZ_CORE_OBJ)
	$(FUZZ_CC) $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@
$(FUZZ_DIR)/fuzz_afm_draco: $(FUZZ_DIR)/obj/fuzz/fuzz_afm_draco.c.o $(FUZZ_DRACO_OBJ) $(FUZZ_CORE_OBJ)
	$(FUZZ_CXX) $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@ -ldraco
$(FUZZ_DIR)/fuzz_fap: $(FUZZ_DIR)/obj/fuzz/fuzz_fap.c.o $(FUZZ_CORE_OBJ)
	$(FUZZ_CC) $(FUZZ_SAN) -fsanitize=fuzzer $^ -o $@
$(FUZZ_DIR)/afm_seed: $(B)/obj/fuzz/afm_seed.c.o $(LIBS)
	@mkdir -p $(@D)
	$(CC) $< -o $@ $(LDFLAGS) $(C_LINK_LIBS)

fuzz: deps
	@$(MAKE) --no-print-directory all $(ARM_DIR)/afm_synth $(FUZZ_DIR)/afm_seed $(FUZZ_TARGETS) config=$(config)
	@AFM_BUILD=$(B) FUZZ_DIR=$(FUZZ_DIR) FUZZ_SECONDS=$(FUZZ_SECONDS) sh fuzz/run.sh $(FUZZ_TARGETS)

-include $(shell find $(ARM_DIR) $(FUZZ_DIR)/obj -name '*.d' 2>/dev/null)
# ==== end of the ARM, size and fuzzing block ==================================

-include $(shell find $(B)/obj $(B)/pic -name '*.d' 2>/dev/null)
