# Entry points: `make demo`, `make test`, `make bench`. Each installs missing Debian packages
# first (as root, with apt-get), then builds in Release with CMake.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
DEMO_SCENE ?= examples/torus-bite.json
DEMO_OUT ?= out/demo.png

PACKAGES := cmake make g++ pkg-config libembree-dev libtbb-dev libpng-dev nlohmann-json3-dev \
            libcli11-dev libopenexr-dev libgtest-dev libgmock-dev libbenchmark-dev python3
# Only `make bench` plots (bench/plot_complexity.py): a target-specific value, inherited by its
# prerequisites (build -> configure -> deps), so `make test` and `make demo` do not install it.
bench: PACKAGES += python3-matplotlib

.PHONY: all deps configure build demo test bench clean format

all: build

deps:
	@missing=""; for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing missing packages:$$missing"; \
	  if [ "$$(id -u)" != 0 ]; then echo "error: run as root (or install:$$missing)" >&2; exit 1; fi; \
	  export DEBIAN_FRONTEND=noninteractive; \
	  apt-get install -y --no-install-recommends $$missing || \
	    { apt-get update && apt-get install -y --no-install-recommends $$missing; }; \
	fi

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) > /dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

demo: build
	@mkdir -p $(dir $(DEMO_OUT))
	@$(BUILD_DIR)/bin/lattice render $(DEMO_SCENE) -o $(DEMO_OUT)
	@echo "demo image: $(abspath $(DEMO_OUT))"

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	@bench/run.sh $(BUILD_DIR)

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	@rm -rf $(BUILD_DIR)
