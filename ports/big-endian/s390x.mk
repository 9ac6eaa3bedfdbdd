# IBM Z (s390x), big-endian 64-bit, static, run here under qemu-s390x.
#   make -f ports/big-endian/s390x.mk                   ->  ports/build/s390x/pray
NAME      = s390x
CXX       = s390x-linux-gnu-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-s390x
CONFIG    = ports/big-endian/prayconf.h
PACKAGES  = g++-s390x-linux-gnu qemu-user
include ports/rules.mk
