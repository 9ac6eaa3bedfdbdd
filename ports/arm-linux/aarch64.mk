# 64-bit ARM Linux (AArch64), static, run here under qemu-aarch64.
#   make -f ports/arm-linux/aarch64.mk                  ->  ports/build/aarch64/pray
# -ffp-contract=off matters here: AArch64 has fused multiply-add, and GCC fuses a*b+c by default
# (also with -std=c++98), which changes a few pixels of examples/room.ray.
NAME      = aarch64
CXX       = aarch64-linux-gnu-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-aarch64
CONFIG    = ports/arm-linux/prayconf.h
PACKAGES  = g++-aarch64-linux-gnu qemu-user
include ports/rules.mk
