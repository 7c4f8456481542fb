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
RENDER_SRC := $(wildcard ports/osmesa/src/*.c ports/osmesa/src/*.cpp)

FORMAT_LIB := $(B)/lib/libafm_format.a
DRACO_LIB := $(B)/lib/libafm_draco.a
BUILDER_LIB := $(B)/lib/libafm_builder.a
PLAYER_LIB := $(B)/lib/libafm_player.a
RENDER_LIB := $(B)/lib/libafm_render.a

obj = $(patsubst %,$(B)/obj/%.o,$(1))

LIBS := $(FORMAT_LIB) $(DRACO_LIB) $(BUILDER_LIB) \
  $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(if $(RENDER_SRC),$(RENDER_LIB))

# Link order: dependants first.
CXX_LINK_LIBS := $(BUILDER_LIB) $(if $(RENDER_SRC),$(RENDER_LIB)) \
  $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(DRACO_LIB) $(FORMAT_LIB) \
  -lOpenMeshTools -lOpenMeshCore -ldraco -lOSMesa -lpng -lpthread -lm
# C tools link as plain C programs: the Draco codec only needs libdraco and
# libstdc++ beside it.
C_LINK_LIBS := $(if $(PLAYER_SRC),$(PLAYER_LIB)) $(DRACO_LIB) $(FORMAT_LIB) -ldraco -lstdc++ -lm

# ---- tools -----------------------------------------------------------------
C_TOOLS := $(patsubst formats/tools/%.c,$(B)/bin/%,$(wildcard formats/tools/*.c)) \
  $(patsubst player_c/tools/%.c,$(B)/bin/%,$(wildcard player_c/tools/*.c))
CXX_TOOLS := $(patsubst builder/tools/%.cpp,$(B)/bin/%,$(wildcard builder/tools/*.cpp)) \
  $(patsubst ports/osmesa/tools/%.cpp,$(B)/bin/%,$(wildcard ports/osmesa/tools/*.cpp))
TOOLS := $(C_TOOLS) $(CXX_TOOLS)

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

$(B)/obj/%.c.o: %.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -c $< -o $@

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

# One gtest binary per tests/<dir>/.
.SECONDEXPANSION:
$(B)/tests/test_%: $$(call obj,$$(wildcard tests/$$*/*.cpp)) $(call obj,$(wildcard tests/common/*.cpp)) $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $(filter %.o,$^) -o $@ $(LDFLAGS) $(CXX_LINK_LIBS) -lgtest -lgtest_main

$(B)/bench/%: $(B)/obj/bench/%.cpp.o $(LIBS)
	@mkdir -p $(@D)
	$(CXX) $< -o $@ $(LDFLAGS) $(CXX_LINK_LIBS)

deps:
	@tools/deps.sh

test: deps
	@$(MAKE) --no-print-directory all tests config=$(config)
	@AFM_BUILD=$(B) tools/run-tests.sh $(TEST_BINS)

.PHONY: tests
tests: $(TEST_BINS)

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

-include $(shell find $(B)/obj -name '*.d' 2>/dev/null)
