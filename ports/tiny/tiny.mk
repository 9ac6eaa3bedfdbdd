# The smallest useful build: the program in single precision, no PNG, no threads, -Os, unused
# sections dropped; linked against the system's C library (dynamic). Native; runs as it is.
#   make -f ports/tiny/tiny.mk      ->  ports/build/tiny/pray, and libpray.o: the library alone
#                                       without the interpreter (PRAY_NO_INTERP), for hosts that
#                                       build scenes through the API
NAME      = tiny
CXX       = g++
PORTFLAGS = -Os -ffunction-sections -fdata-sections -ffp-contract=off -fno-asynchronous-unwind-tables -fno-unwind-tables
LDFLAGS   = -Wl,--gc-sections -s
EXE       =
RUN       =
CONFIG    = ports/tiny/prayconf.h
PACKAGES  =
REFERENCE = float
EXTRA     = $(OUT)/libpray.o
include ports/rules.mk

$(OUT)/libpray.o: pray.cpp pray.hpp $(CONFIG)
	@mkdir -p $(OUT)
	$(CXX) $(FLAGS) -DPRAY_NO_INTERP -c pray.cpp -o $@
