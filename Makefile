# Thin wrapper over CMake. `make demo` and `make test` set everything up from a fresh Debian machine.
BUILD_DIR ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=

PREFIX ?= /usr/local

.PHONY: all deps configure build demo test install bench sanitize fuzz fuzz-ci clean

all: build

deps:
	@bash scripts/install-deps

configure: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# The geardiag command alone (the tests are built by `make test`), then its demo. The time is a
# clean build of the target geardiag on a 2-core machine, measured (docs/install.md).
demo: configure
	@echo "make demo: building the geardiag command only: about 8 minutes on 2 cores from a clean" \
	  "build folder (seconds when it is built already; make test builds and runs the tests too)"
	cmake --build $(BUILD_DIR) -j $(JOBS) --target geardiag
	./$(BUILD_DIR)/geardiag demo
	@echo "make demo: the command is $(CURDIR)/$(BUILD_DIR)/geardiag; to call it as geardiag:"
	@echo "  export PATH=\"$(CURDIR)/$(BUILD_DIR):\$$PATH\""

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The command, the static libraries, the headers, find_package(geardiag) and geardiag.pc under
# PREFIX (docs/install.md): make install PREFIX=$$HOME/.local
install: configure
	cmake --build $(BUILD_DIR) -j $(JOBS) --target install_targets
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

# AddressSanitizer + UndefinedBehaviorSanitizer build of the whole suite, warnings as errors.
# Without the Python module (an ASan-built extension cannot load into Debian's python3, which is
# not built with ASan) and without MPI (OpenMPI's own allocations read as leaks): both are tested
# in the plain build of `make test`. Left out under the sanitizers, and run by `make test`: the
# statistical sweeps (the same code as the closed-loop tests that do run, repeated over tens to
# hundreds of random gearboxes for their rates; the gear-baseline sweep alone took 193 s) and the manual's examples (the commands the CLI tests run),
# the slowest tests under ASan (SANITIZE_SKIP). LeakSanitizer is told to pass over what the system
# HDF5 allocates and never frees on a corrupted file's error paths (fuzz/lsan.supp, as for the
# fuzzers; leaks in geardiag's own code are still reported).
# Compiled at -O1 with line tables only (-g1: file and line in every report): GCC's UBSan at -O2
# with full debug information takes 2.6 times as long to compile (68 s against 26 s for
# analyze_file.cpp), and the build, not the run, was most of this job's time.
SANITIZE_FLAGS ?= -O1 -g1 -DNDEBUG
SANITIZE_SKIP ?= ^(GearDamageLoop\.RealisticGearsRaiseFewFalseAlarmsAndNoWrongShaft|GearDamageLoop\.AHealthyBaselineCancelsThePitchErrors|AttributionClosedLoop\.MeetsTheAttributionTargetsOverRandomGearboxesAndDefects|docs\.examples)$$
sanitize: deps
	cmake -S . -B $(BUILD_DIR)-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEARDIAG_SANITIZE=ON -DGEARDIAG_WERROR=ON \
	  -DGEARDIAG_WITH_PYTHON=OFF -DGEARDIAG_WITH_MPI=OFF \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(SANITIZE_FLAGS)" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$(SANITIZE_FLAGS)"
	cmake --build $(BUILD_DIR)-asan -j $(JOBS)
	cd $(BUILD_DIR)-asan && LSAN_OPTIONS=suppressions=$(CURDIR)/fuzz/lsan.supp \
	  ctest --output-on-failure -j $(JOBS) -E '$(SANITIZE_SKIP)'

# libFuzzer on every reader and parser (clang, ASan + UBSan): FUZZ_SECONDS per target, seeds from
# testdata/, fuzz/make_seeds.py and the bad-input corpus. Results: $(BUILD_DIR)-fuzz/fuzz-summary.txt
# (FUZZING.md); a crashing input is saved in $(BUILD_DIR)-fuzz/artifacts/.
FUZZ_SECONDS ?= 600
fuzz: build
	bash fuzz/run.sh $(BUILD_DIR)-fuzz $(FUZZ_SECONDS) $(BUILD_DIR)/geardiag

# The short run CI makes: 45 s per target at most, seed 1, at most the verified number of inputs
# per target (fuzz/ci-runs.txt), so that it gives the same answer on every run.
fuzz-ci: build
	FUZZ_RUNS_FILE=fuzz/ci-runs.txt bash fuzz/run.sh $(BUILD_DIR)-fuzz 45 $(BUILD_DIR)/geardiag

bench: deps
	cmake -S . -B $(BUILD_DIR)-bench -DCMAKE_BUILD_TYPE=Release -DGEARDIAG_BUILD_BENCH=ON -DGEARDIAG_BUILD_TESTS=OFF
	cmake --build $(BUILD_DIR)-bench -j $(JOBS)
	bash bench/run.sh $(BUILD_DIR)-bench

clean:
	rm -rf $(BUILD_DIR) $(BUILD_DIR)-asan $(BUILD_DIR)-bench $(BUILD_DIR)-fuzz

# The Python module geardiag (pybind11) into $(BUILD_DIR)/python/: PYTHONPATH=$(BUILD_DIR)/python
.PHONY: python
python: configure
	cmake --build $(BUILD_DIR) -j $(JOBS) --target python
