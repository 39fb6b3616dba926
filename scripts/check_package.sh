#!/usr/bin/env bash
# Installs a monomap build into a temporary prefix and builds and runs the
# example consumer against it twice: through the CMake package
# (find_package(monomap)) and through pkg-config (monomap.pc).
#   scripts/check_package.sh BUILD_DIR [WORK_DIR]
set -euo pipefail
build=$(realpath "$1")
src=$(cd "$(dirname "$0")/.." && pwd)
work=${2:-$(mktemp -d)}
mkdir -p "$work"
work=$(realpath "$work")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
test -x "$prefix/bin/monomap"
"$prefix/bin/monomap" --version

cmake -S "$src/examples/consumer" -B "$work/consumer" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log"
cmake --build "$work/consumer" > "$work/build.log"
"$work/consumer/consumer"

pc_dir=$(dirname "$(find "$prefix" -name monomap.pc | head -n 1)")
flags=$(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs monomap)
# shellcheck disable=SC2086
# OpenCV 4.6 headers warn under C++20 (as in CMakeLists.txt).
${CXX:-c++} -O1 -Wno-deprecated-enum-enum-conversion \
  -Wno-deprecated-anon-enum-enum-conversion "$src/examples/consumer/main.cc" -o "$work/consumer_pc" $flags
"$work/consumer_pc"
echo "package check passed"
