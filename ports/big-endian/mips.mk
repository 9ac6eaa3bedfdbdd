# 32-bit MIPS (MIPS32r2), big-endian, hard float, static, run here under qemu-mips.
#   make -f ports/big-endian/mips.mk                    ->  ports/build/mips/pray
NAME      = mips
CXX       = mips-linux-gnu-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-mips
CONFIG    = ports/big-endian/prayconf.h
PACKAGES  = g++-mips-linux-gnu qemu-user
include ports/rules.mk
