# SPDX-License-Identifier: Apache-2.0
# Build, render the default scene, run the tests (build.sh installs packages first).
BUILD ?= build
JOBS ?= $(shell nproc)
CAMBIUM = $(BUILD)/src/app/cambium
MAKEFLAGS += --no-print-directory
DEFAULT = scenes/default
# The default scene staged as a still: on a soil-coloured ground under the daylight sky,
# seen in perspective from a little below the view file's viewpoint, denoised.
STAGE = --sky --background sky --ground 0.42,0.38,0.3 --perspective --fit --orbit 25 -12 \
	--denoise
# ccache, when a developer has it, makes rebuilds in fresh clones cheap (optional; the
# paths it hashes are made relative to this folder so clones share the cache).
CCACHE := $(shell command -v ccache 2>/dev/null)
LAUNCHER = $(if $(CCACHE),-DCMAKE_CXX_COMPILER_LAUNCHER=$(CCACHE))
export CCACHE_BASEDIR := $(CURDIR)

.PHONY: setup configure build render test sanitize clean

setup:
	@bash scripts/setup.sh

configure:
	@echo "build: configuring $(BUILD) (Release)"
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(LAUNCHER) > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }

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
	@cd $(DEFAULT) && $(CURDIR)/$(CAMBIUM) -M plant.mat $(STAGE) -o $(CURDIR)/out/default.png \
		-o $(CURDIR)/out/default.exr plant.l plant.v

# The README's second command does what the first does (the default scene rendered too),
# then builds and runs everything. The glTF sweep's validator comes from npm where npm
# and its registry answer (scripts/gltf-validator.sh never fails: the sweep skips it).
test: render build
	@bash scripts/gltf-validator.sh $(BUILD) || true
	@echo "test: running the ctest suite"
	@ctest --test-dir $(BUILD) --output-on-failure --parallel $(JOBS)

# The quick tests under AddressSanitizer and UndefinedBehaviorSanitizer, in their own
# build folder (docs/security.md). OpenImageIO 2.4 frees some objects with a sized
# delete of a different size than it allocated (in the library itself, not in Cambium):
# ASan's new_delete_type_mismatch check is off for that reason only; leaks inside the
# third-party libraries are suppressed (scripts/lsan-suppressions.txt). GCC 12's runtime
# misreads some dynamic TLS blocks as glibc 2.19's (by their address alone) and its leak
# checker then crashes scanning a bogus range: intercept_tls_get_addr=0 (docs/security.md).
ASAN_BUILD ?= build-asan
sanitize: export ASAN_OPTIONS = new_delete_type_mismatch=0:detect_leaks=1:abort_on_error=0:intercept_tls_get_addr=0
sanitize: export UBSAN_OPTIONS = print_stacktrace=1:halt_on_error=1
sanitize: export LSAN_OPTIONS = suppressions=$(CURDIR)/scripts/lsan-suppressions.txt
sanitize:
	@echo "sanitize: configuring $(ASAN_BUILD) (address,undefined)"
	@cmake -S . -B $(ASAN_BUILD) $(LAUNCHER) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCAMBIUM_SANITIZE=address,undefined \
		-DCAMBIUM_BUILD_BENCHMARKS=OFF > $(ASAN_BUILD).configure.log 2>&1 || { cat $(ASAN_BUILD).configure.log; exit 1; }
	@echo "sanitize: compiling with $(JOBS) jobs"
	@cmake --build $(ASAN_BUILD) --parallel $(JOBS)
	@echo "sanitize: running the quick tests"
	@ctest --test-dir $(ASAN_BUILD) -L quick --output-on-failure --parallel $(JOBS)

clean:
	rm -rf $(BUILD) $(BUILD).configure.log $(ASAN_BUILD) $(ASAN_BUILD).configure.log out
