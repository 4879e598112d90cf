# SPDX-License-Identifier: Apache-2.0
# Build, render the default scene, run the tests (build.sh installs packages first).
BUILD ?= build
JOBS ?= $(shell nproc)
CAMBIUM = $(BUILD)/src/app/cambium
MAKEFLAGS += --no-print-directory
DEFAULT = scenes/default

.PHONY: setup configure build render test clean

setup:
	@bash scripts/setup.sh

configure:
	@echo "build: configuring $(BUILD) (Release)"
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }

# Everything: the command, the tests and the benchmarks.
build: configure
	@echo "build: compiling with $(JOBS) jobs"
	@cmake --build $(BUILD) --parallel $(JOBS)

# Only what the first image needs: the cambium command.
render: configure
	@echo "build: compiling the cambium command with $(JOBS) jobs"
	@cmake --build $(BUILD) --parallel $(JOBS) --target cambium
	@mkdir -p out
	@echo "render: $(DEFAULT) -> out/default.png, out/default.exr"
	@cd $(DEFAULT) && $(CURDIR)/$(CAMBIUM) -M plant.mat -o $(CURDIR)/out/default.png \
		-o $(CURDIR)/out/default.exr plant.l plant.v

test: build
	@echo "test: running the ctest suite"
	@ctest --test-dir $(BUILD) --output-on-failure --parallel $(JOBS)

clean:
	rm -rf $(BUILD) $(BUILD).configure.log out
