#!/bin/sh
# pray as a CMake and pkg-config package, seen from a program that uses it (make cmake-check).
# tests/cmake/consumer renders a tiny image through pray and checks two pixels; it is built
#   (a) with add_subdirectory of this source tree: pray's program and tests are not built, no build
#       type or compile option reaches the consumer, nothing is installed, nothing is written into
#       the source tree;
#   (b) against pray installed into a temporary prefix, through find_package(pray);
#   (c) with pkg-config from that prefix, and examples/embed.c with it as a C program.
# The README's CMake block is the consumer's CMakeLists.txt, and its pkg-config lines are the ones
# run here. Everything happens in a temporary directory; the status is non-zero on any failure.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/pray-cmake.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "cmake-check: $*" >&2; exit 1; }
# run a command quietly; its output is shown when it fails
run() { "$@" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; fail "failed: $*"; }; }
touch "$tmp/stamp"

# The README shows what is built here.
awk '/^```cmake$/ {on = 1; next} /^```$/ {on = 0} on' "$src/README.md" >"$tmp/readme.cmake"
cmp -s "$tmp/readme.cmake" "$here/consumer/CMakeLists.txt" ||
  fail "README.md's cmake block differs from tests/cmake/consumer/CMakeLists.txt"
pc_cxx='c++ main.cpp $(pkg-config --cflags --libs pray) -o main'
pc_c='cc embed.c $(pkg-config --static --cflags --libs pray) -o embed'
for l in "$pc_cxx" "$pc_c"; do
  grep -qxF "$l" "$src/README.md" || fail "README.md lacks the line: $l"
done

echo "== (a) add_subdirectory"
b=$tmp/sub
run cmake -S "$here/consumer" -B "$b" -DPRAY_SOURCE_DIR="$src" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
grep -q 'pray: the project sets no CMAKE_BUILD_TYPE' "$tmp/log" ||
  fail "no warning that pray is built without optimisation in a parent without a build type"
run cmake --build "$b"
run "$b/consumer"
cat "$tmp/log"
grep -q '^CMAKE_BUILD_TYPE:STRING=$' "$b/CMakeCache.txt" || fail "pray set the parent's build type"
grep -q 'main\.cpp' "$b/compile_commands.json" || fail "no compile command for main.cpp"
if grep 'main\.cpp' "$b/compile_commands.json" | grep -q -e '-fno-rtti' -e '-Wextra'; then
  fail "pray's compile options reached the consumer"
fi
for t in pray_program pray_tests pray_textures; do
  if cmake --build "$b" --target $t >/dev/null 2>&1; then fail "the subproject has a target $t"; fi
done
if [ -n "$(find "$b" -name 'pray_tests*' -o -type f -name pray)" ]; then fail "the subproject built tests or the program"; fi
run cmake --install "$b" --prefix "$tmp/sub-prefix"
if [ -e "$tmp/sub-prefix" ]; then fail "the subproject installed: $(find "$tmp/sub-prefix" -type f)"; fi

echo "== (b) installed, find_package(pray)"
run cmake -S "$src" -B "$tmp/pray" -DCMAKE_BUILD_TYPE=Release -DPRAY_TESTS=OFF -DPRAY_BUILD_PROGRAM=OFF
run cmake --build "$tmp/pray"
p=$tmp/prefix
run cmake --install "$tmp/pray" --prefix "$p"
for f in include/pray.hpp libpray.a prayConfig.cmake prayConfigVersion.cmake prayTargets.cmake pray.pc; do
  [ -n "$(find "$p" -path "*/$f")" ] || fail "not installed: $f"
done
run cmake -S "$here/consumer" -B "$tmp/pkg" -DCMAKE_PREFIX_PATH="$p" -DCMAKE_BUILD_TYPE=Release
run cmake --build "$tmp/pkg"
run "$tmp/pkg/consumer"
cat "$tmp/log"

echo "== (c) installed, pkg-config"
command -v pkg-config >/dev/null || fail "pkg-config is missing (Debian: apt-get install pkg-config)"
PKG_CONFIG_PATH=$(dirname "$(find "$p" -name pray.pc)")
export PKG_CONFIG_PATH
[ "$(pkg-config --variable=prefix pray)" = "$p" ] || fail "pray.pc names the prefix $(pkg-config --variable=prefix pray)"
mkdir "$tmp/pc"
cp "$here/consumer/main.cpp" "$src/examples/embed.c" "$tmp/pc/"
cd "$tmp/pc"
run sh -c "$pc_cxx"
run ./main
cat "$tmp/log"
run sh -c "$pc_c"
run ./embed embed.ppm
[ "$(head -c 15 embed.ppm)" = "$(printf 'P6\n128 128\n255')" ] || fail "embed.c wrote no 128 x 128 PPM"
echo "embed.c (C): $(cat "$tmp/log")"

changed=$(find "$src" -newer "$tmp/stamp" ! -path "$src/.git*" | head -5)
[ -z "$changed" ] || fail "written into the source tree: $changed"
echo "cmake-check: all passed"
