# pound — nonsmooth dynamics of pounding structures.
#
#   make demo     install missing packages (as root), build, run the main job
#   make test     install missing packages (as root), build, run the tests
#   make asan     the tests under AddressSanitizer + UndefinedBehaviorSanitizer
#   make bench    performance figures (pound bench; pound against Siconos numerics)
#   make figures  docs/figures/*.png (convergence, stability, energy)
#   make stress   the adversarial suite (stress/run.py): hostile flags and
#                 files, full disks, signals, hangs, libFuzzer, TSan;
#                 STRESS_ARGS="--report docs/reliability.md" rewrites its table
#   make all      library and binary only (build/libpound.a, build/pound)
#   make MPI=1    the MPI build (OpenMPI's mpicc, -DPD_MPI) in build-mpi/:
#                 mpirun -np K build-mpi/pound spectrum ...
#   make OPENMP=  without OpenMP (spectrum then runs one thread)
#
# Layers: cli -> problems -> engine -> lcp; HDF5 is used by cli/ only.

CC      ?= cc
OPT     ?= -O2
CFLAGS  ?= $(OPT) -g
WARN     = -std=c11 -Wall -Wextra -Wshadow -Wpedantic -Werror
DEFS     = -D_POSIX_C_SOURCE=200809L
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

INC      = -Icore -Ilcp -Iengine -Iproblems -Icli
ALL_CFLAGS = $(WARN) $(DEFS) $(CFLAGS) $(OPENMP) $(INC) $(PKG_CFLAGS) $(SS_CFLAGS) $(XCFLAGS)
LIBS     = $(PKG_LIBS) $(SS_LIBS) -lm

LIB_SRC  = $(wildcard core/*.c) $(wildcard lcp/*.c) $(wildcard engine/*.c) $(wildcard problems/*.c)
CLI_SRC  = $(wildcard cli/*.c)
TEST_SRC = $(wildcard tests/*.c)
LIB_OBJ  = $(LIB_SRC:%.c=$(BUILD)/%.o)
CLI_OBJ  = $(CLI_SRC:%.c=$(BUILD)/%.o)
TEST_OBJ = $(TEST_SRC:%.c=$(BUILD)/%.o)
HDRS     = $(wildcard */*.h)

.PHONY: all deps demo test check asan bench clean acceptance figures paper stress print-libs

all: $(BUILD)/pound $(BUILD)/pound_tests

$(BUILD)/%.o: %.c $(HDRS)
	@mkdir -p $(dir $@)
	@echo "  CC    $<"
	@$(CC) $(ALL_CFLAGS) -c $< -o $@

$(BUILD)/libpound.a: $(LIB_OBJ)
	@echo "  AR    $@"
	@rm -f $@ && $(AR) rcs $@ $^

$(BUILD)/pound: $(CLI_OBJ) $(BUILD)/libpound.a
	@echo "  LD    $@"
	@$(CC) $(CFLAGS) $(OPENMP) $(XCFLAGS) -o $@ $(CLI_OBJ) $(BUILD)/libpound.a $(XOBJ) $(LIBS)

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

asan: deps
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 \
	  XCFLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" check

# pound's own figures, then pound paired against Siconos numerics (when it
# can be installed or is there: bench/build.sh exits 3 without it).
bench: deps
	@sh scripts/deps.sh --bench || echo "bench: Siconos numerics not installed (the paired table is skipped)"
	@$(MAKE) --no-print-directory all
	$(BUILD)/pound bench
	@st=0; sh bench/build.sh $(BUILD) || st=$$?; \
	if [ $$st = 0 ]; then $(BUILD)/siconos_lcp --chains; elif [ $$st != 3 ]; then exit $$st; fi

figures: deps
	@$(MAKE) --no-print-directory all
	sh scripts/figures.sh $(BUILD)/pound
	sh scripts/paper.sh $(BUILD)/pound

paper: deps
	@$(MAKE) --no-print-directory all
	sh scripts/paper.sh $(BUILD)/pound

# The adversarial suite: fuzzers and a TSan binary built with clang in
# $(BUILD)/stress, then stress/run.py against $(BUILD)/pound (about 5 min).
STRESS_ARGS ?=
stress: deps
	@sh scripts/deps.sh --stress
	@$(MAKE) --no-print-directory all
	sh scripts/stress.sh $(BUILD) $(STRESS_ARGS)

print-libs:
	@echo $(LIBS)

acceptance: all
	@sh scripts/acceptance.sh $(BUILD)/pound

clean:
	rm -rf build build-asan build-mpi
