#!/bin/sh
# The line budgets of pray.cpp: every [SECTION] of the file against the budget that the index
# comment at the top of the file gives it, and the whole file against its total budget.
#
#   tests/sections.sh              check pray.cpp, print each section's size and budget
#   tests/sections.sh FILE         check another copy of the file
#   tests/sections.sh -q [FILE]    print the table only when a budget is broken (make test, check)
#
# A section runs from its banner line "// [SECTION] N ..." to the line before the next banner;
# the last one runs to the end of the file. The lines above the first banner (the index) count
# only towards the total. The budgets are read from the index, the lines
#   [SECTION] N   BUDGET  title...
# and the line "whole file: at most TOTAL lines". The check fails when a section is over its
# budget, when the file is over its total, or when a banner has no budget in the index (or a
# budget no banner), and when a function is longer than 150 lines. Budgets are lowered as
# sections shrink; raising one is a decision, made in the index. Needs only a POSIX shell and awk.

quiet=0
if [ "${1:-}" = -q ]; then
    quiet=1
    shift
fi
if [ $# -gt 0 ]; then
    file=$1
else
    cd "$(dirname "$0")/.." || exit 2
    file=pray.cpp
fi
if [ ! -f "$file" ]; then
    echo "sections.sh: no file $file" >&2
    exit 2
fi

awk -v quiet=$quiet '
    # the index: budget lines before the first banner
    !banner && /^[ \t]*\[SECTION\][ \t]+[0-9]+[a-z]?[ \t]+[0-9]+[ \t]/ {
        name = $2
        if (name in budget) { printf "sections.sh: section %s has two budgets in the index\n", name; bad = 1 }
        budget[name] = $3 + 0
        order[++nb] = name
        next
    }
    !banner && /whole file: at most [0-9]+ lines/ {
        s = $0
        sub(/.*whole file: at most /, "", s)
        sub(/ lines.*/, "", s)
        total = s + 0
        next
    }
    /^\/\/ \[SECTION\] / {
        if (cur != "") size[cur] = NR - start
        cur = $3
        start = NR
        banner++
        if (cur in seen) { printf "sections.sh: two banners of section %s (line %d)\n", cur, NR; bad = 1 }
        seen[cur] = NR
        found[++nf] = cur
    }
    END {
        if (cur != "") size[cur] = NR + 1 - start
        if (nf == 0) { print "sections.sh: no \"// [SECTION] N\" banner lines in the file"; exit 1 }
        if (nb == 0) { print "sections.sh: no budgets in the index comment (lines \"[SECTION] N  BUDGET  title\")"; exit 1 }
        if (total == 0) { print "sections.sh: no total budget in the index comment (\"whole file: at most N lines\")"; exit 1 }
        table = sprintf("%-8s %6s %7s\n", "section", "lines", "budget")
        for (i = 1; i <= nf; i++) {
            n = found[i]
            if (!(n in budget)) {
                table = table sprintf("%-8s %6d %7s  FAIL: no budget in the index for this section (line %d)\n", n, size[n], "-", seen[n])
                bad = 1
                continue
            }
            mark = ""
            if (size[n] > budget[n]) {
                mark = sprintf("  FAIL: %d lines over the budget", size[n] - budget[n])
                over = over " " n
                bad = 1
            }
            table = table sprintf("%-8s %6d %7d%s\n", n, size[n], budget[n], mark)
        }
        for (i = 1; i <= nb; i++)
            if (!(order[i] in seen)) {
                printf "sections.sh: the index gives section %s a budget, but the file has no banner for it\n", order[i]
                bad = 1
            }
        mark = ""
        if (NR > total) { mark = sprintf("  FAIL: %d lines over the budget", NR - total); bad = 1 }
        table = table sprintf("%-8s %6d %7d%s\n", "total", NR, total, mark)
        if (bad || !quiet) printf "%s", table
        if (over != "") printf "sections.sh: over budget:%s (shorten the section, or raise its budget in the index of pray.cpp as a decision)\n", over
        if (bad) { print "sections.sh: FAILED"; exit 1 }
        printf "sections.sh: %s, %d lines in %d sections, each within its budget\n", FILENAME, NR, nf
    }
' "$file" || st=1

# No function of more than 150 lines, from the line that opens its body to the one that closes
# it (a block at the top level of the file that is not a namespace); comments, strings and
# character literals are left out of the count of braces.
awk '
    /^(namespace|} *\/\/ namespace|extern "C" *\{)/ { next }
    {
        line = $0
        gsub(/\/\/.*/, "", line)
        gsub(/"(\\.|[^"\\])*"/, "\"\"", line)
        gsub(/\047(\\.|[^\047\\])*\047/, "\047\047", line)
        for (i = 1; i <= length(line); i++) {
            ch = substr(line, i, 1)
            if (ch == "{") { if (depth == 0) { start = NR; name = $0 } depth++ }
            else if (ch == "}") {
                depth--
                if (depth == 0 && start && NR - start + 1 > 150) {
                    printf "sections.sh: %d lines in the function at line %d (150 at most): %s\n", NR - start + 1, start, name
                    bad = 1
                }
            }
        }
    }
    END { if (bad) { print "sections.sh: FAILED"; exit 1 } }
' "$file" || st=1
exit ${st:-0}
