# 32-bit ARM Linux (armhf: ARMv7-A, VFPv3 hard float), static, run here under qemu-arm.
#   make -f ports/arm-linux/arm.mk                      ->  ports/build/arm/pray
# which runs:
#   arm-linux-gnueabihf-g++ -std=c++98 -O2 -ffp-contract=off ... \
#     -DPRAY_USER_CONFIG='"ports/arm-linux/prayconf.h"' -DPRAY_MAIN pray.cpp -o ports/build/arm/pray -static -lm
NAME      = arm
CXX       = arm-linux-gnueabihf-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       =
RUN       = qemu-arm
CONFIG    = ports/arm-linux/prayconf.h
PACKAGES  = g++-arm-linux-gnueabihf qemu-user
include ports/rules.mk
