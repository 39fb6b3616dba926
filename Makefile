# monomap: the two commands of the README.
#   make demo   install missing Debian packages, build, run the demo
#   make test   install missing Debian packages, build, run all tests
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
DEMO_DIR ?= out/demo

# Debian 12 packages the build and the tests need (colmap: the test that
# reads the COLMAP export back; help2man: the man page).
DEB_PACKAGES = cmake ninja-build g++ pkg-config libopencv-dev libeigen3-dev \
  libceres-dev libtbb-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev \
  libtinygltf-dev libstb-dev libgtest-dev libgmock-dev libbenchmark-dev \
  colmap help2man \
  librosbag-dev libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev \
  libgeometry-msgs-dev libsqlite3-dev libfastcdr-dev \
  libroscpp-dev libtf2-ros-dev libstd-srvs-dev ros-core \
  libjs-three libjs-chart.js

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: deps configure build test demo bench clean

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || echo $$p; \
	done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:" $$missing; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing; \
	fi

configure: deps
	@[ -f $(BUILD_DIR)/build.ninja ] || \
	  cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

demo: build
	$(BUILD_DIR)/src/monomap/exe/monomap demo -o $(DEMO_DIR)

bench: build
	@echo "Benchmarks: see docs/benchmarks.md for the commands."

clean:
	rm -rf $(BUILD_DIR)
