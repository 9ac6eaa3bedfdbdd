#!/bin/sh
# Seeds of long operator chains for `make fuzz-long`, written into the directory $1 (made if
# missing; nothing under tests/ is written). Each is a statement of N terms of one operator
# (N = ${N:-20000}; 20000 short terms stay within maxline), on one line or continued over lines
# of 1000 terms: left-associative chains of every operator on numbers, objects, vectors and
# strings, right-associative `^`, unary minus, and nested parentheses. Before chains were
# evaluated in a loop, 12000 terms overflowed the stack. They are generated, not kept, because
# they are large.
set -e
dir=$1
n=${N:-20000}
[ -n "$dir" ] || { echo "usage: $0 DIR" >&2; exit 2; }
mkdir -p "$dir"
# chain FILE HEAD TERM TAIL PER: HEAD, then TERM n times (PER to a line, 0 = one line), then TAIL
chain() {
    awk -v head="$2" -v term="$3" -v tail="$4" -v per="$5" -v n="$n" 'BEGIN {
        printf "M = color({1})\nS = sphere(M, [0, 0, 0], 1)\nV = <1, 0, 0>\n%s", head
        for (i = 1; i <= n; i++) {
            printf "%s", term
            if (per > 0 && i % per == 0 && i < n) printf " \\\n"
        }
        printf "%s\nprint X\n", tail
    }' >"$dir/$1"
}
i=0
for op in + - '*' / % '<' '>' '<=' '>=' = == '#' '&' '|' '\\' '^'; do
    i=$((i + 1))
    chain "num-$i.ray" "X = 1" "$op""1" "" 0
    chain "num-cont-$i.ray" "X = 1" " $op 1" "" 1000
done
chain obj-union.ray "X = S" "|S" "" 0
chain obj-plus.ray "X = S" " + S" "" 1000
chain obj-inter.ray "X = S" "&S" "" 0
chain obj-diff.ray "X = S" "\\\\S" "" 0
chain vec-dot.ray "X = V" ".V" "" 0
chain vec-add.ray "X = V" " + V" "" 1000
chain str-add.ray 'X = "a"' '+""' "" 0
chain neg.ray "X = " "-" "1" 0
chain paren.ray "X = " "(" "1" 0
