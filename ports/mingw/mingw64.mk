# 64-bit Windows with mingw-w64, static (no DLLs beyond Windows' own), run here under wine.
#   make -f ports/mingw/mingw64.mk                      ->  ports/build/mingw64/pray.exe
NAME      = mingw64
CXX       = x86_64-w64-mingw32-g++
PORTFLAGS = -O2 -ffp-contract=off
LDFLAGS   = -static
EXE       = .exe
RUN       = wine
CONFIG    = ports/mingw/prayconf.h
PACKAGES  = g++-mingw-w64-x86-64 wine wine64
include ports/rules.mk
