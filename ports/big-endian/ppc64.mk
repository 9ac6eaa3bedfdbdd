# 64-bit PowerPC, big-endian (ELFv1), static, run here under qemu-ppc64.
#   make -f ports/big-endian/ppc64.mk                   ->  ports/build/ppc64/pray
NAME      = ppc64
CXX       = powerpc64-linux-gnu-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-ppc64
CONFIG    = ports/big-endian/prayconf.h
PACKAGES  = g++-powerpc64-linux-gnu qemu-user
include ports/rules.mk
