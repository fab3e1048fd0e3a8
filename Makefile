# Entry points: `make demo`, `make test`, `make bench`, `make test-sanitize`, `make fuzz`. Each
# installs missing Debian packages first (as root, with apt-get), then builds with CMake.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
# The demo is the product's point: fur grown over a scanned mesh, traced through lattices.
DEMO_SCENE ?= examples/furry-bunny.json
DEMO_FLAGS ?= --mode lattice
DEMO_OUT ?= out/demo.png

# Sanitizer build (`make test-sanitize`): its own directory; SANITIZE_TESTS passes ctest a
# selection (e.g. -R or -E); empty runs every test.
SANITIZE_DIR ?= build-sanitize
SANITIZE_TESTS ?=
# Fuzzing (`make fuzz`): libFuzzer from Debian's clang; each harness runs FUZZ_SECONDS.
FUZZ_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_HARNESSES := $(patsubst fuzz/%_fuzz.cpp,%,$(wildcard fuzz/*_fuzz.cpp))

# g++ brings libasan and libubsan (through libgcc-12-dev). Open MPI: `lattice` under mpirun
# (docs/distributed.md); the build works without it too. The Python module (docs/python.md):
# pybind11 and numpy for Debian's python3, pytest for its tests.
PACKAGES := cmake make g++ pkg-config libembree-dev libtbb-dev libpng-dev nlohmann-json3-dev \
            libcli11-dev libopenexr-dev libgtest-dev libgmock-dev libbenchmark-dev python3 \
            libopenmpi-dev openmpi-bin python3-dev pybind11-dev python3-numpy python3-pytest
# Only `make bench` plots (bench/plot_complexity.py): a target-specific value, inherited by its
# prerequisites (build -> configure -> deps), so `make test` and `make demo` do not install it.
bench: PACKAGES += python3-matplotlib
# Only for `make fuzz`: bookworm's clang (14) and the runtime that holds libFuzzer, same version.
FUZZ_PACKAGES := clang-14 libclang-rt-14-dev

# Any sanitizer report fails the test that caused it. Suppressions (with the reason for each)
# cover only Debian's uninstrumented Embree and oneTBB.
SANITIZER_ENV := ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

.PHONY: all deps fuzz-deps configure build python-module demo test test-sanitize fuzz bench clean format

all: build

# $(call install,PACKAGES): installs those not yet installed (as root, with apt-get).
define install
	@missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing missing packages:$$missing"; \
	  if [ "$$(id -u)" != 0 ]; then echo "error: run as root (or install:$$missing)" >&2; exit 1; fi; \
	  export DEBIAN_FRONTEND=noninteractive; \
	  apt-get install -y --no-install-recommends $$missing || \
	    { apt-get update && apt-get install -y --no-install-recommends $$missing; }; \
	fi
endef

deps:
	$(call install,$(PACKAGES))

fuzz-deps: deps
	$(call install,$(FUZZ_PACKAGES))

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) > /dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The Python module installed where Debian's python3 finds it (under /usr/local), so that
# `python3 -c "import lattice"` works after `make demo` or `make test` (docs/python.md); without
# root it stays in the build tree (PYTHONPATH=$(BUILD_DIR)/python).
python-module: build
	@if [ -d $(BUILD_DIR)/python ]; then \
	  if [ "$$(id -u)" = 0 ]; then cmake --install $(BUILD_DIR) --component python > /dev/null; \
	  else echo "note: not root: the Python module stays in $(BUILD_DIR)/python (PYTHONPATH)"; fi; \
	fi

demo: python-module
	@mkdir -p $(dir $(DEMO_OUT))
	@$(BUILD_DIR)/bin/lattice render $(DEMO_SCENE) $(DEMO_FLAGS) -o $(DEMO_OUT)
	@echo "demo image: $(abspath $(DEMO_OUT))"

test: python-module
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# ASan + UBSan over the unit, CLI and corpus-replay tests (no benchmarks).
test-sanitize: deps
	@cmake -S . -B $(SANITIZE_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLATTICE_SANITIZE=ON \
	  -DLATTICE_BUILD_BENCH=OFF $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(SANITIZE_DIR) -j $(JOBS)
	@cd $(SANITIZE_DIR) && $(SANITIZER_ENV) ctest --output-on-failure -j $(JOBS) $(SANITIZE_TESTS)

# Builds the libFuzzer harnesses (clang, ASan + UBSan) and runs each for FUZZ_SECONDS on a working
# corpus in $(FUZZ_DIR) seeded from fuzz/corpus; findings go to $(FUZZ_DIR)/artifacts.
fuzz: fuzz-deps
	@# No -Werror here: clang warns where g++ does not (-Wdouble-promotion in src/lattice); the
	@# normal build, with g++, is the one held to no warnings.
	@CC=clang-14 CXX=clang++-14 cmake -S . -B $(FUZZ_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DLATTICE_FUZZ=ON -DLATTICE_WERROR=OFF -DLATTICE_BUILD_TESTS=OFF -DLATTICE_BUILD_BENCH=OFF \
	  $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(FUZZ_DIR) -j $(JOBS) --target $(addprefix fuzz_,$(FUZZ_HARNESSES))
	@mkdir -p $(FUZZ_DIR)/artifacts
	@set -e; for h in $(FUZZ_HARNESSES); do \
	  mkdir -p $(FUZZ_DIR)/corpus/$$h; \
	  dict=""; [ -f fuzz/$$h.dict ] && dict="-dict=fuzz/$$h.dict"; \
	  echo "fuzz: $$h for $(FUZZ_SECONDS) s"; \
	  $(SANITIZER_ENV) $(FUZZ_DIR)/bin/fuzz_$$h $$dict -max_total_time=$(FUZZ_SECONDS) \
	    -timeout=20 -rss_limit_mb=4096 -malloc_limit_mb=4096 -print_final_stats=1 \
	    -artifact_prefix=$(FUZZ_DIR)/artifacts/$$h- $(FUZZ_DIR)/corpus/$$h fuzz/corpus/$$h; \
	done

bench: build
	@bench/run.sh $(BUILD_DIR)

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	@rm -rf $(BUILD_DIR)
