# 486-class Linux: x87 arithmetic only, no CMOV/MMX/SSE in pray's code, static; the tested
# stand-in for DJGPP (same prayconf.h, same code generation flags). Run here under qemu-i386.
#   make -f ports/i486/i486.mk                          ->  ports/build/i486/pray, pray.o
# -ffloat-store makes x87 results byte-identical to SSE2/ARM/... ones (see ports/README.md).
# The program runs under `qemu-i386 -cpu pentium2`, not `-cpu 486`: the static C library of
# Debian's i686 cross toolchain uses CMOV. ports/i486/scan486 checks pray.o itself.
NAME      = i486
CXX       = i686-linux-gnu-g++
PORTFLAGS = -O2 -march=i486 -mfpmath=387 -mno-sse -ffloat-store -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-i386 -cpu pentium2
CONFIG    = ports/i486/prayconf.h
PACKAGES  = g++-i686-linux-gnu qemu-user
EXTRA     = $(OUT)/pray.o
include ports/rules.mk
