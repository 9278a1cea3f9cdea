# The two entry points of the README. Each installs missing Debian packages first,
# so either can be the first command on a fresh Debian 12 machine.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps build demo test bench fuzz clean

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/build.ninja:
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_FLAGS)

build: deps $(BUILD)/build.ninja
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD)

# The fuzzers run first and briefly (5 s per target, two at a time: a smoke run; `make fuzz` runs 120 s each); ctest's summary closes the run.
# Real-time tests (DDS processes, SITL firmware, the browser) share two cores with each
# other, so a failed test runs once more; one that fails twice fails the run, and the first
# failure stays in the log.
test: build
	@bash scripts/fuzz.sh $(BUILD)-fuzz 5
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --repeat until-pass:2

bench: build
	@bash scripts/bench.sh $(BUILD)

fuzz: deps
	@bash scripts/fuzz.sh $(BUILD)-fuzz 120

clean:
	rm -rf $(BUILD) $(BUILD)-fuzz out
