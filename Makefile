# The two entry points of the README. Each installs missing Debian packages first,
# so either can be the first command on a fresh Debian 12 machine.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps build demo test sanitize bench fuzz clean

all: build

deps:
	@bash scripts/install-deps.sh

# A unity build (CMake's UNITY_BUILD: up to 8 sources of a target compiled as one) compiles the
# project in about 60 % of the CPU time of one object per source (docs/performance.md, "Build
# flags"); `make CMAKE_FLAGS=-DCMAKE_UNITY_BUILD=OFF` gives one object per source, as an
# editor's compile_commands.json wants.
$(BUILD)/build.ninja:
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON $(CMAKE_FLAGS)

build: deps $(BUILD)/build.ninja
	cmake --build $(BUILD) -j $(JOBS)

# Only what the demo runs: the `eamos` command (no tests, benchmarks or fuzzers, no npm), and
# only the Debian packages it needs (scripts/install-deps.sh demo).
demo:
	@bash scripts/install-deps.sh demo
	@$(MAKE) --no-print-directory $(BUILD)/build.ninja
	cmake --build $(BUILD) -j $(JOBS) --target eamos
	@bash scripts/demo.sh $(BUILD)

# The real-time tests (SITL firmware, DDS processes, the browser) run at normal priority;
# beside them, at low priority, the fuzzers (built, then 5 s per target: a smoke run; `make
# fuzz` runs 120 s each) and every other test (scripts/test.sh). A failed real-time test
# runs once more (one that fails twice fails the run); any other test fails the run at once.
test: build
	@bash scripts/test.sh $(BUILD) $(BUILD)-fuzz 5

# The suites under AddressSanitizer + UBSan and under ThreadSanitizer, each sanitizer in a
# build tree of its own ($(BUILD)-asan, $(BUILD)-tsan; scripts/sanitize.sh); .ci/run
# runs it after make test (docs/performance.md, "The sanitizer runs").
sanitize: deps
	@bash scripts/sanitize.sh all $(BUILD)

bench: build
	@bash scripts/bench.sh $(BUILD)

fuzz: deps
	@bash scripts/fuzz.sh $(BUILD)-fuzz 120

clean:
	rm -rf $(BUILD) $(BUILD)-fuzz $(BUILD)-asan $(BUILD)-tsan out
