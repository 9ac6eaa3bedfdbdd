#!/bin/sh
# The whole programs of the manual at the end of pray.hpp and the C blocks of README.md and
# docs/*.md, compiled as C and as C++ (warnings as errors), linked with pray.cpp and run. In
# pray.hpp a program is a block of lines indented by 7 spaces whose first line is an #include
# (the block ends at the first line not indented so); in Markdown, a block fenced as ```c.
# Run from the repository's root:  sh tests/manual_examples.sh   (CC and CXX pick the compilers,
# RUN is put before each program: an emulator)
set -e
CC=${CC:-cc}
CXX=${CXX:-c++}
root=$(pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT INT TERM
awk -v dir="$dir" '
    inside && /^       / { sub(/^       /, ""); print > file; next }
    inside { inside = 0; close(file) }
    /^       #include/ { n++; inside = 1; file = dir "/example" n ".c"; sub(/^       /, ""); print > file }
' pray.hpp
awk -v dir="$dir" '
    inside && /^```/ { inside = 0; close(file); next }
    inside { print > file; next }
    /^```c$/ { n++; inside = 1; file = dir "/doc" n ".c" }
' README.md docs/*.md
n=$(ls "$dir" | wc -l)
if [ "$n" -eq 0 ]; then
    echo "manual_examples.sh: no program found in pray.hpp, README.md or docs/" >&2
    exit 1
fi
$CXX -O1 -c pray.cpp -o "$dir/pray.o"
for f in "$dir"/*.c; do
    e=${f%.c}
    $CC -std=c89 -pedantic -Wall -Wextra -Werror -I"$root" -c "$f" -o "$e.c.o"
    $CXX -std=c++98 -pedantic -Wall -Wextra -Werror -I"$root" -x c++ -c "$f" -o "$e.cpp.o"
    for o in "$e.c.o" "$e.cpp.o"; do
        $CXX "$o" "$dir/pray.o" -o "$e.run" -lm -lpthread
        (cd "$dir" && ${RUN:-} "$e.run") || { echo "manual_examples.sh: $(basename "$f") ($o) failed" >&2; exit 1; }
    done
done
echo "manual examples: $n programs of pray.hpp, README.md and docs/ compiled as C and C++ and run"
