# DOS with DJGPP (32-bit protected mode, DPMI), cross-compiled. Not built here: Debian has no
# DJGPP compiler (only binutils-djgpp). Tested through its stand-in ports/i486/i486.mk.
#   make -f ports/djgpp/djgpp.mk                        ->  ports/build/djgpp/pray.exe
# On DOS itself, without make or a Unix shell (the flags come from a GCC response file):
#   gpp @ports/djgpp/flags.rsp pray.cpp -o pray.exe
#   stubedit pray.exe minstack=4096k
# -std=gnu++98, not c++98: DJGPP's headers hide POSIX functions (isatty) under __STRICT_ANSI__.
NAME      = djgpp
CXX       = i586-pc-msdosdjgpp-g++
STD       = -std=gnu++98
PORTFLAGS = -O2 -march=i486 -ffloat-store -ffp-contract=off
LDFLAGS   =
EXE       = .exe
RUN       = -
CONFIG    = ports/djgpp/prayconf.h
PACKAGES  =
# A CSG tree near the depth limit (2000) needs 1-2 MB of stack on 32-bit x86; DJGPP gives 512 KB
# unless told otherwise (ports/i486 measures this through qemu's stack size).
POSTLINK  = i586-pc-msdosdjgpp-stubedit $@ minstack=4096k
include ports/rules.mk
