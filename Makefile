# monomap: the two commands of the README.
#   make demo   install missing Debian packages, build, run the demo
#   make test   install missing Debian packages, build, run all tests
#   make test-sanitize   the test suite under ASan+UBSan (build-asan)
#   make test-sanitize-units   every module's unit tests (ctest label
#               "unit") and the bad-input catalogue ("catalogue") under
#               ASan+UBSan (build-fuzz; what CI runs)
#   make fuzz   build the libFuzzer targets (build-fuzz), run each for
#               FUZZ_SECONDS on fuzz/corpus/<target>; non-zero on a finding
#   make check-functions   no function in src/ over 80 lines without a
#               comment saying why (scripts/long_functions.py)
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
DEMO_DIR ?= out/demo

# Debian 12 packages the build and the tests need (colmap: the test that
# reads the COLMAP export back; help2man: the man page).
DEB_PACKAGES = cmake ninja-build g++ pkg-config libopencv-dev libeigen3-dev \
  libceres-dev libtbb-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev \
  libtinygltf-dev libstb-dev libgtest-dev libgmock-dev libbenchmark-dev \
  colmap help2man python3 \
  librosbag-dev libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev \
  libgeometry-msgs-dev libsqlite3-dev libfastcdr-dev \
  libroscpp-dev libtf2-ros-dev libstd-srvs-dev ros-core \
  libjs-three libjs-chart.js

# Extra packages of `make fuzz` and `make test-sanitize` (clang 14 with its
# libFuzzer and sanitizer runtimes).
SANITIZE_PACKAGES = clang libclang-rt-14-dev
ASAN_DIR ?= build-asan
FUZZ_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
# Memory limit per fuzz input (MB): more than this is an OOM finding.
FUZZ_RSS_MB ?= 2048
FUZZ_TARGETS = camera_yaml camera_mount dataset feature_table image map ply

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: deps sanitize-deps configure build test test-sanitize fuzz-configure \
  test-sanitize-units fuzz check-functions demo bench clean

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || echo $$p; \
	done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:" $$missing; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing; \
	fi

sanitize-deps: deps
	@$(MAKE) --no-print-directory deps DEB_PACKAGES="$(SANITIZE_PACKAGES)"

configure: deps
	@[ -f $(BUILD_DIR)/build.ninja ] || \
	  cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# halt_on_error: the first sanitizer report fails the test.
test-sanitize: sanitize-deps
	@[ -f $(ASAN_DIR)/build.ninja ] || \
	  cmake -S . -B $(ASAN_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	    -DMONOMAP_SANITIZE=ON -DMONOMAP_BUILD_BENCH=OFF
	cmake --build $(ASAN_DIR) -j $(JOBS)
	cd $(ASAN_DIR) && \
	  ASAN_OPTIONS=halt_on_error=1:detect_leaks=1 \
	  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	  ctest --output-on-failure -j $(JOBS)

# The clang build of `make fuzz` and `make test-sanitize-units`
# (build-fuzz): ASan+UBSan and libFuzzer's coverage instrumentation on
# everything; tests are configured too, so that one build serves both.
# Configured every time (cheap): a build-fuzz of an older Makefile had
# tests off.
fuzz-configure: sanitize-deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_DIR) -G Ninja \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMONOMAP_BUILD_FUZZERS=ON \
	  -DMONOMAP_BUILD_TESTS=ON -DMONOMAP_BUILD_BENCH=OFF >/dev/null

# The unit tests of every module (ctest label "unit": src/monomap/*, but
# not the whole-pipeline tests) and the bad-input catalogue run against the
# binary (label "catalogue") under ASan+UBSan, in the fuzz build: what CI
# runs of the sanitizers. `make test-sanitize` runs everything, the
# end-to-end tests too, in its own build: too long for CI.
test-sanitize-units: fuzz-configure
	cmake --build $(FUZZ_DIR) -j $(JOBS) --target unit_tests catalogue_tests
	cd $(FUZZ_DIR) && \
	  ASAN_OPTIONS=halt_on_error=1:detect_leaks=1 \
	  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	  ctest -L 'unit|catalogue' --output-on-failure -j $(JOBS)

# Each target first runs every file of its checked-in corpus (so a
# regression of a past finding fails at once), then FUZZ_SECONDS of new
# inputs on a copy of it (new inputs land in $(FUZZ_DIR)/corpus, not in
# the source tree); crash files go to $(FUZZ_DIR)/findings, the log to
# $(FUZZ_DIR)/<target>.log (its tail is printed on a finding).
fuzz: fuzz-configure
	cmake --build $(FUZZ_DIR) -j $(JOBS) --target \
	  $(addsuffix _fuzzer,$(FUZZ_TARGETS))
	@mkdir -p $(FUZZ_DIR)/findings; status=0; \
	for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FUZZ_DIR)/corpus/$$t; \
	  echo "== $${t}_fuzzer: $(FUZZ_SECONDS) s"; \
	  if $(FUZZ_DIR)/fuzz/$${t}_fuzzer -max_total_time=$(FUZZ_SECONDS) \
	      -timeout=10 -rss_limit_mb=$(FUZZ_RSS_MB) -print_final_stats=1 \
	      -artifact_prefix=$(FUZZ_DIR)/findings/$${t}- \
	      $(FUZZ_DIR)/corpus/$$t fuzz/corpus/$$t >$(FUZZ_DIR)/$$t.log 2>&1; \
	  then grep -E "INITED|DONE|number_of_executed_units" $(FUZZ_DIR)/$$t.log; \
	  else status=1; tail -n 80 $(FUZZ_DIR)/$$t.log; fi; \
	done; exit $$status

check-functions: deps
	python3 scripts/long_functions.py 80 --check

demo: build
	$(BUILD_DIR)/src/monomap/exe/monomap demo -o $(DEMO_DIR)

bench: build
	@echo "Benchmarks: see docs/benchmarks.md for the commands."

clean:
	rm -rf $(BUILD_DIR)
