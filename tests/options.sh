#!/bin/sh
# The options as the documentation presents them: every option of the table in pray.cpp
# (section 6) is named under a heading of `pray --help` and has a row in section 11 of docs/pray-language.md; the
# diagnostic options are the same in the three places that set them apart: the heading of
# --help, the table "Diagnostic options" of the manual and the paragraph of pray.hpp; and no
# other option of the manual is in the diagnostic table. Run from the repository's root:
#
#   sh tests/options.sh [PRAY]       (./pray by default; RUN is put before it)

PRAY=${1:-./pray}
RUN=${RUN:-}
fail=0
bad() {
    echo "options.sh: $*" >&2
    fail=1
}

# the names of the option table, in pray.cpp between "const OptDef OPTS" and its "};"
all=$(sed -n '/^const OptDef OPTS\[/,/^};/s/^ *{"\([a-z]*\)",.*/\1/p' pray.cpp)
[ -n "$all" ] || { echo "options.sh: no option table found in pray.cpp" >&2; exit 2; }
help=$($RUN "$PRAY" --help) || { echo "options.sh: $PRAY --help failed" >&2; exit 2; }

# the diagnostic options of --help: the lines after its heading, up to the next empty line
dhelp=$(printf '%s\n' "$help" | sed -n '/^Diagnostic options/,/^$/p' |
    sed -n -e 's/^  --brute .*/brute/p' -e 's/^  -D \([a-z]*\)=.*/\1/p' | sort)
[ -n "$dhelp" ] || bad "pray --help has no heading 'Diagnostic options' with -D lines"

# the other options of --help: the lines under "Options of the language", up to an empty line
lhelp=$(printf '%s\n' "$help" | sed -n '/^Options of the language/,/^$/p' | sed 1d)
[ -n "$lhelp" ] || bad "pray --help has no heading 'Options of the language'"

# the manual, section 11: the rows of all its tables, and those of the diagnostic one
sec11=$(sed -n '/^## 11\. Options/,/^## 12\./p' docs/pray-language.md)
rows=$(printf '%s\n' "$sec11" | sed -n 's/^| `\([a-z]*\)` |.*/\1/p' | sort)
dman=$(printf '%s\n' "$sec11" | sed -n '/^### Diagnostic options/,/^### /p' |
    sed -n 's/^| `\([a-z]*\)` |.*/\1/p' | sort)
[ -n "$dman" ] || bad "docs/pray-language.md has no table under '### Diagnostic options'"

# pray.hpp: the paragraph that starts "Diagnostic options"
dhpp=$(sed -n '/^   Diagnostic options/,/^ *$/p' pray.hpp)
[ -n "$dhpp" ] || bad "pray.hpp has no paragraph 'Diagnostic options'"

for o in $all; do
    printf '%s\n' "$lhelp" "$dhelp" | grep -q -w -e "$o" ||
        bad "pray --help names the option $o neither under 'Options of the language' nor as diagnostic"
    printf '%s\n' "$rows" | grep -q -x -e "$o" || bad "docs/pray-language.md, section 11, has no row for the option $o"
done
for o in $dhelp; do
    printf '%s\n' "$all" | grep -q -x -e "$o" || bad "pray --help lists $o as diagnostic, but there is no such option"
    printf '%s\n' "$dhpp" | grep -q -w -e "$o" || bad "pray.hpp's paragraph of diagnostic options does not name $o"
done
[ "$dhelp" = "$dman" ] || bad "the diagnostic options differ: pray --help:" $dhelp "; docs/pray-language.md:" $dman

if [ $fail != 0 ]; then
    echo "options.sh: FAILED" >&2
    exit 1
fi
echo "options.sh: $(echo $all | wc -w) options documented; diagnostic:" $dhelp
