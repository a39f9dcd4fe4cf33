# pound — nonsmooth dynamics of pounding structures.
#
#   make demo     install missing packages (as root), build, run the main job
#   make test     install missing packages (as root), build, run the tests
#   make asan     the tests under AddressSanitizer + UndefinedBehaviorSanitizer
#   make bench    performance figures (pound bench; pound against Siconos numerics);
#                 SHARED=DIR names the shared data's folder (default ../shared: the
#                 Siconos LCP set and the record study, each said skipped when absent)
#   make figures  the figures (convergence, work-precision, stability, energy)
#                 and the paper's (make paper alone) into build/figures/;
#                 DOCS=1 (or make figures-docs, paper-docs) refreshes the
#                 tracked docs/figures/ instead
#   make stress   the adversarial suite (stress/run.py): hostile flags and
#                 files, full disks, signals, hangs, libFuzzer, TSan;
#                 STRESS_ARGS="--report docs/reliability.md" rewrites its table
#   make all      library and binary only (build/libpound.a, build/pound)
#   make install  PREFIX=/usr/local DESTDIR=: bin/pound, lib/libpound.so.0 and
#                 libpound.a, include/pound/, lib/pkgconfig/pound.pc, the man
#                 page and the bash completion (docs/api.md); make uninstall
#   make install-check  the examples/api/ programs built against an installed
#                 copy (scripts/api-check.sh; part of make check)
#   make formats-check  every output file read back with h5py and xarray (docs/formats.md)
#   make flags-check    every command's --help against the man page, the bash
#                 completion and the parser (scripts/flags-check.py)
#   make python-check   the Python package (python/) tested against the CLI, mypy, its notebook
#   make MPI=1    the MPI build (OpenMPI's mpicc, -DPD_MPI) in build-mpi/:
#                 mpirun -np K build-mpi/pound spectrum ...
#   make OPENMP=  without OpenMP (spectrum then runs one thread)
#   make format / format-check   the layout of .clang-format (clang-format 14)
#   make house    function lengths and comments inside them (scripts/house.py)
#   make mutate   mutation testing of the numerical core (scripts/mutate.py)
#
# Layers: cli -> problems -> engine -> lcp -> core, each compiled with the
# include paths of its layer and those below (INC_*); HDF5 is used by cli/
# only; bench/ holds `pound bench` (cmd_bench.c and its drivers).

CC      ?= cc
OPT     ?= -O2
CFLAGS  ?= $(OPT) -g
WARN     = -std=c11 -Wall -Wextra -Wshadow -Wpedantic -Werror
DEFS     = -D_POSIX_C_SOURCE=200809L
# IEEE arithmetic as written: no fused multiply-adds, so that every build
# (and every vector width of engine/mj_batch.c) computes the same numbers
FPFLAGS  = -ffp-contract=off
OPENMP  ?= -fopenmp

# The MPI build: a separate binary, so that the plain build never runs as
# several copies that would each write the whole sweep.
ifeq ($(MPI),1)
ifeq ($(shell command -v mpicc 2>/dev/null),)
$(error MPI=1 needs OpenMPI's mpicc: apt-get install libopenmpi-dev openmpi-bin)
endif
CC       = mpicc
BUILD   ?= build-mpi
DEFS    += -DPD_MPI
endif
BUILD   ?= build

# Dependencies through pkg-config (Debian's SuiteSparse 5 ships no .pc file;
# its headers live in the documented suitesparse/ subfolder of the include path).
PKGS         = gsl hdf5 jansson
PKG_CFLAGS  := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS    := $(shell pkg-config --libs $(PKGS) 2>/dev/null)
SS_CFLAGS   := $(shell pkg-config --cflags cholmod 2>/dev/null || echo -I/usr/include/suitesparse)
SS_LIBS     := $(shell pkg-config --libs cholmod cxsparse 2>/dev/null || echo -lcholmod -lcxsparse)

# Start-up (cli/lazy.c): the pound binary loads HDF5 and CHOLMOD when a run
# first calls them, by the sonames of the libraries found here, instead of
# linking them: a process that writes no HDF5 and factors nothing sparse
# starts in a few ms, not 30.  LAZY=0 (or a library not found) links them.
LAZY    ?= 1
# the soname of -l$(2) in the -L folders of $(1), else where $(CC) finds it
lib_soname = $(shell for d in $(patsubst -L%,%,$(filter -L%,$(1))) \
    "$$(dirname "$$($(CC) -print-file-name=lib$(2).so)")"; do \
    if [ -e "$$d/lib$(2).so" ]; then \
    objdump -p "$$d/lib$(2).so" 2>/dev/null | awk '/SONAME/ {print $$2; exit}'; break; fi; done)
# HDF5's high-level library (the dimension scales, H5DS) sits beside HDF5
# as lib<hdf5>_hl: libhdf5_hl.so, whose soname is libhdf5_serial_hl.so.100
# on Debian.
H5_LIBS        := $(shell pkg-config --libs hdf5 2>/dev/null)
H5_NAME        := $(patsubst -l%,%,$(firstword $(filter -l%,$(H5_LIBS))))
H5HL_LIBS      := $(if $(H5_NAME),-l$(H5_NAME)_hl,-lhdf5_hl)
ifeq ($(LAZY),1)
H5_SONAME      := $(call lib_soname,$(H5_LIBS),$(H5_NAME))
H5HL_SONAME    := $(call lib_soname,$(H5_LIBS),$(H5_NAME)_hl)
CHOLMOD_SONAME := $(call lib_soname,,cholmod)
endif
ifneq ($(and $(H5_SONAME),$(H5HL_SONAME),$(CHOLMOD_SONAME)),)
LAZY_DEFS = -DPD_LAZY_HDF5='"$(H5_SONAME)"' -DPD_LAZY_HDF5_HL='"$(H5HL_SONAME)"' \
            -DPD_LAZY_CHOLMOD='"$(CHOLMOD_SONAME)"'
CLI_LIBS  = $(shell pkg-config --libs gsl jansson 2>/dev/null) \
            $(shell pkg-config --libs cxsparse 2>/dev/null || echo -lcxsparse) -ldl -lm
else
CLI_LIBS  = $(LIBS)
endif

# Layers the compiler enforces: a folder sees its own headers and those of
# the layers below it (cli -> problems -> engine -> lcp -> core; bench and
# tests on top), nothing above.
INC_core     = -Icore
INC_lcp      = $(INC_core) -Ilcp
INC_engine   = $(INC_lcp) -Iengine
INC_problems = $(INC_engine) -Iproblems
INC_cli      = $(INC_problems) -Icli
INC_bench    = $(INC_cli) -Ibench
INC_tests    = $(INC_bench) -Itests
INC          = $(INC_$(firstword $(subst /, ,$<)))
ALL_CFLAGS = $(WARN) $(DEFS) $(LAZY_DEFS) $(FPFLAGS) $(CFLAGS) $(OPENMP) $(INC) $(PKG_CFLAGS) $(SS_CFLAGS) $(LANES_CFLAGS) $(XCFLAGS)
LIBS     = $(H5HL_LIBS) $(PKG_LIBS) $(SS_LIBS) -lm

LIB_SRC  = $(wildcard core/*.c) $(wildcard lcp/*.c) $(wildcard engine/*.c) $(wildcard problems/*.c)
# the benchmarks' drivers (bench/) are part of the pound binary; bench/siconos_lcp.c
# is a program of its own (bench/build.sh, make bench)
BENCH_SRC = $(filter-out bench/siconos_lcp.c,$(wildcard bench/*.c))
CLI_SRC  = $(wildcard cli/*.c) $(BENCH_SRC)
TEST_SRC = $(wildcard tests/*.c)
LIB_OBJ  = $(LIB_SRC:%.c=$(BUILD)/%.o)
CLI_OBJ  = $(CLI_SRC:%.c=$(BUILD)/%.o)
TEST_OBJ = $(TEST_SRC:%.c=$(BUILD)/%.o)
HDRS     = $(wildcard */*.h)

# The installed library: libpound.so from -fPIC objects of their own
# ($(BUILD)/pic/) compiled with hidden visibility, so that only the PD_API
# declarations of the public headers are exported; the static library and
# the binaries are built as before.  The library needs GSL, jansson,
# CHOLMOD, CXSparse, libm and OpenMP; HDF5 is the command line's only.
VERSION    := $(shell sed -n 's/^\#define PD_VERSION "\(.*\)"/\1/p' core/pd_core.h)
SOMAJOR    := $(firstword $(subst ., ,$(VERSION)))
SONAME      = libpound.so.$(SOMAJOR)
SOREAL      = libpound.so.$(VERSION)
PREFIX     ?= /usr/local
DESTDIR    ?=
bindir     ?= $(PREFIX)/bin
libdir     ?= $(PREFIX)/lib
includedir ?= $(PREFIX)/include
mandir     ?= $(PREFIX)/share/man
bashcompdir ?= $(PREFIX)/share/bash-completion/completions
PUB_HDRS    = include/pound/pound.h core/pd_core.h lcp/pd_lcp.h engine/pd_engine.h \
              problems/pd_problems.h
PIC_OBJ     = $(LIB_SRC:%.c=$(BUILD)/pic/%.o)
SS_PC      := $(shell pkg-config --exists cholmod cxsparse 2>/dev/null && echo cholmod cxsparse)
SO_LIBS    := $(shell pkg-config --libs gsl jansson 2>/dev/null) $(SS_LIBS) -lm
INSTALLED   = $(bindir)/pound $(libdir)/libpound.a $(libdir)/$(SOREAL) $(libdir)/$(SONAME) \
              $(libdir)/libpound.so $(addprefix $(includedir)/pound/,$(notdir $(PUB_HDRS))) \
              $(libdir)/pkgconfig/pound.pc $(mandir)/man1/pound.1 $(bashcompdir)/pound
# make check ends with scripts/api-check.sh (not under the sanitizers)
API_CHECK  ?= 1

.PHONY: docs-check all deps demo test check asan bench mutate format format-check house clean acceptance figures paper figures-docs \
        paper-docs stress print-libs \
        shared install uninstall install-check formats-check flags-check python-check

all: $(BUILD)/pound $(BUILD)/pound_tests

# The batched kernels' files: GCC's first instruction-scheduling pass, aware of
# register pressure (off by default on x86), interleaves their vectors' chains
# with fewer spills (the paper sweep 10-15 % faster on AVX2 and the baseline;
# docs/spectrum.md); compilers without it leave it out.
LANES_SRC   = $(wildcard problems/osc_batch*.c) $(wildcard engine/mj_batch*.c)
flag_if_ok  = $(shell $(CC) -Werror $(1) -x c -c /dev/null -o /dev/null 2>/dev/null && echo $(1))
LANES_SCHED := $(call flag_if_ok,-fschedule-insns -fsched-pressure)
$(LANES_SRC:%.c=$(BUILD)/%.o) $(LANES_SRC:%.c=$(BUILD)/pic/%.o): LANES_CFLAGS = $(LANES_SCHED)

$(BUILD)/%.o: %.c $(HDRS)
	@mkdir -p $(dir $@)
	@echo "  CC    $<"
	@$(CC) $(ALL_CFLAGS) -c $< -o $@

$(BUILD)/libpound.a: $(LIB_OBJ)
	@echo "  AR    $@"
	@rm -f $@ && $(AR) rcs $@ $^

$(BUILD)/pic/%.o: %.c $(HDRS)
	@mkdir -p $(dir $@)
	@echo "  CC    $< (pic)"
	@$(CC) $(ALL_CFLAGS) -fPIC -fvisibility=hidden -c $< -o $@

# The version script keeps what the compiler exports whatever the
# visibility (OpenMP's named critical sections) local: pd_* only.
$(BUILD)/$(SOREAL): $(PIC_OBJ)
	@echo "  LD    $@"
	@printf '{\n  global: pd_*;\n  local: *;\n};\n' > $(BUILD)/pic/libpound.map
	@$(CC) -shared -Wl,-soname,$(SONAME) -Wl,-z,defs -Wl,--as-needed \
	    -Wl,--version-script,$(BUILD)/pic/libpound.map $(CFLAGS) $(OPENMP) $(XCFLAGS) \
	    -o $@ $(PIC_OBJ) $(SO_LIBS)
	@ln -sf $(SOREAL) $(BUILD)/$(SONAME) && ln -sf $(SONAME) $(BUILD)/libpound.so

shared: $(BUILD)/$(SOREAL)

$(BUILD)/pound: $(CLI_OBJ) $(BUILD)/libpound.a
	@echo "  LD    $@"
	@$(CC) $(CFLAGS) $(OPENMP) $(XCFLAGS) -o $@ $(CLI_OBJ) $(BUILD)/libpound.a $(XOBJ) $(CLI_LIBS)

$(BUILD)/pound_tests: $(TEST_OBJ) $(BUILD)/libpound.a
	@echo "  LD    $@"
	@$(CC) $(CFLAGS) $(OPENMP) $(XCFLAGS) -o $@ $(TEST_OBJ) $(BUILD)/libpound.a $(XOBJ) $(LIBS) \
	    -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc

deps:
	@sh scripts/deps.sh

# The main job: the paper's Fig. 9 case, normal and reverse pulse.
demo: deps
	@$(MAKE) --no-print-directory all
	$(BUILD)/pound simulate --pulse sine --dir normal  --Tp 0.3 --T0 3 --ap 4 --gap 0.004 --eps 0.6
	$(BUILD)/pound simulate --pulse sine --dir reverse --Tp 0.3 --T0 3 --ap 4 --gap 0.004 --eps 0.6

test: deps
	@$(MAKE) --no-print-directory check

check: all
	$(BUILD)/pound_tests --pound $(BUILD)/pound
	@sh scripts/layers-check.sh
	@$(if $(API_CHECK),$(MAKE) --no-print-directory install-check)
	@$(if $(API_CHECK),$(MAKE) --no-print-directory formats-check)
	@$(if $(API_CHECK),$(MAKE) --no-print-directory flags-check)
	@$(if $(API_CHECK),$(MAKE) --no-print-directory docs-check)

# Every pound command of the README's and the docs' code blocks, run as
# written from a folder that sees only the repository (no ../shared).
docs-check: all
	@python3 scripts/docs-commands.py $(BUILD)/pound > $(BUILD)/docs-commands.log || \
	  { cat $(BUILD)/docs-commands.log; exit 1; }
	@tail -1 $(BUILD)/docs-commands.log

# Every command's flags (its --help) against the man page, the bash
# completion and the parser (scripts/flags-check.py; Python's standard library).
flags-check: all
	@py=$$(command -v /usr/bin/python3 || command -v python3); \
	if [ -n "$$py" ]; then "$$py" scripts/flags-check.py $(BUILD)/pound; \
	else echo "flags: skipped (no python3)"; fi

# Every output file read back with h5py against docs/formats.md (Debian's
# python3-h5py; skipped without it: scripts/deps.sh --python installs it).
formats-check: all
	@if /usr/bin/python3 -c 'import h5py, numpy' 2>/dev/null; then \
	  /usr/bin/python3 tests/formats_check.py $(BUILD)/pound; \
	else echo "formats: skipped (python3-h5py not installed; scripts/deps.sh --python)"; fi

# The Python package (python/): built against this tree, installed offline
# into a temporary venv, tested with pytest (bit-identical to the CLI).
python-check: deps
	@sh scripts/deps.sh --python
	PY_BUILD=$(BUILD) sh python/check.sh

asan: deps
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 API_CHECK= \
	  XCFLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" check

# pound's own figures, then pound paired against Siconos numerics (when it
# can be installed or is there: bench/build.sh exits 3 without it).
bench: deps
	@sh scripts/deps.sh --bench || echo "bench: Siconos numerics not installed (the paired table is skipped)"
	@$(MAKE) --no-print-directory all
	$(BUILD)/pound bench $(if $(SHARED),--shared $(SHARED))
	@st=0; sh bench/build.sh $(BUILD) || st=$$?; \
	if [ $$st = 0 ]; then $(BUILD)/siconos_lcp --chains; elif [ $$st != 3 ]; then exit $$st; fi

# Figures go to $(BUILD)/figures/ (untracked); DOCS=1 writes the tracked
# docs/figures/ that the docs show.
FIG_OUT = $(if $(DOCS),docs/figures,$(BUILD)/figures)

figures: deps
	@$(MAKE) --no-print-directory all
	sh scripts/figures.sh $(BUILD)/pound $(FIG_OUT)
	sh scripts/paper.sh $(BUILD)/pound $(FIG_OUT)

paper: deps
	@$(MAKE) --no-print-directory all
	sh scripts/paper.sh $(BUILD)/pound $(FIG_OUT)

figures-docs:
	@$(MAKE) --no-print-directory figures DOCS=1

paper-docs:
	@$(MAKE) --no-print-directory paper DOCS=1

# The layout (.clang-format, clang-format 14) and the house's measures
# (scripts/house.py: no function over 150 lines in core/ lcp/ engine/
# problems/, comment lines inside engine/ and lcp/ bodies >= 10 %).
FORMAT_FILES = $(filter-out tests/test_api_null.c,$(shell git ls-files '*.c' '*.h' 2>/dev/null))
format:
	clang-format -i --style=file $(FORMAT_FILES)
format-check:
	@clang-format --dry-run --Werror --style=file $(FORMAT_FILES) && \
	  echo "format-check: $(words $(FORMAT_FILES)) files as .clang-format lays them out"
house:
	@python3 scripts/house.py

# Mutation testing of the numerical core (scripts/mutate.py; minutes, not
# part of CI): MUTATE_ARGS="--files lcp/lemke.c --n 30 --seed 1 --report F".
MUTATE_ARGS ?=
mutate: deps
	@$(MAKE) --no-print-directory all
	python3 scripts/mutate.py $(MUTATE_ARGS)

# The adversarial suite: fuzzers and a TSan binary built with clang in
# $(BUILD)/stress, then stress/run.py against $(BUILD)/pound (about 5 min).
STRESS_ARGS ?=
stress: deps
	@sh scripts/deps.sh --stress
	@$(MAKE) --no-print-directory all
	sh scripts/stress.sh $(BUILD) $(STRESS_ARGS)

# Everything install puts, under DESTDIR (staging) and PREFIX; uninstall
# removes exactly that (and include/pound/ when empty).
install: $(BUILD)/pound $(BUILD)/libpound.a $(BUILD)/$(SOREAL)
	install -d $(DESTDIR)$(bindir) $(DESTDIR)$(libdir)/pkgconfig $(DESTDIR)$(includedir)/pound \
	    $(DESTDIR)$(mandir)/man1 $(DESTDIR)$(bashcompdir)
	install -m 755 $(BUILD)/pound $(DESTDIR)$(bindir)/pound
	install -m 644 $(BUILD)/libpound.a $(DESTDIR)$(libdir)/libpound.a
	install -m 755 $(BUILD)/$(SOREAL) $(DESTDIR)$(libdir)/$(SOREAL)
	ln -sf $(SOREAL) $(DESTDIR)$(libdir)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(libdir)/libpound.so
	install -m 644 $(PUB_HDRS) $(DESTDIR)$(includedir)/pound/
	printf '%s\n' 'prefix=$(PREFIX)' 'libdir=$(patsubst $(PREFIX)%,$${prefix}%,$(libdir))' \
	    'includedir=$(patsubst $(PREFIX)%,$${prefix}%,$(includedir))' '' 'Name: pound' \
	    'Description: nonsmooth dynamics of pounding structures (Moreau-Jean, event-driven, penalty; LCP solvers)' \
	    'Version: $(VERSION)' 'Requires.private: $(strip gsl jansson $(SS_PC))' \
	    'Cflags: -I$${includedir}' 'Libs: -L$${libdir} -lpound' \
	    'Libs.private: $(if $(SS_PC),,-lcholmod -lcxsparse )-lm $(OPENMP)' \
	    > $(DESTDIR)$(libdir)/pkgconfig/pound.pc
	install -m 644 docs/pound.1 $(DESTDIR)$(mandir)/man1/pound.1
	install -m 644 scripts/pound.bash-completion $(DESTDIR)$(bashcompdir)/pound
	@if [ -z "$(DESTDIR)" ] && [ "$$(id -u)" = 0 ] && command -v ldconfig >/dev/null; then \
	    ldconfig; fi

uninstall:
	rm -f $(addprefix $(DESTDIR),$(INSTALLED))
	@rmdir $(DESTDIR)$(includedir)/pound 2>/dev/null || true

# The examples/api/ programs against a staged install (scripts/api-check.sh).
install-check: all $(BUILD)/$(SOREAL)
	@MAKE='$(MAKE)' sh scripts/api-check.sh $(BUILD)

print-libs:
	@echo $(LIBS)

acceptance: all
	@sh scripts/acceptance.sh $(BUILD)/pound

clean:
	rm -rf build build-asan build-mpi
