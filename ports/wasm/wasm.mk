# WebAssembly (wasm32-wasi) with Debian's clang, lld and wasi-libc; run here under Node's WASI
# (ports/wasm/run.mjs). One thread, no PNG, C++11 (wasi-libc declares errno thread_local).
#   make -f ports/wasm/wasm.mk          ->  ports/build/wasm/pray.wasm (the command-line program)
#                                           and ports/build/wasm/libpray.wasm (the playground's)
NAME      = wasm
CXX       = clang++ --target=wasm32-wasi --sysroot=/usr
STD       = -std=c++11
PORTFLAGS = -O2 -ffp-contract=off -fno-math-errno
# The stack first in memory, so that running out of it traps instead of overwriting data; 8 MB
# for the deepest CSG trees (2000 levels; wasm-ld's default is 64 KB).
STACK     = -Wl,--stack-first -Wl,-z,stack-size=8388608
LDFLAGS   = -nostdlib++ -Wl,--strip-all $(STACK) -lwasi-emulated-signal
EXE       = .wasm
RUN       = node --no-warnings --experimental-wasi-unstable-preview1 ports/wasm/run.mjs
CONFIG    = ports/wasm/prayconf.h
PACKAGES  = clang lld wasi-libc libclang-rt-14-dev-wasm32 nodejs
EXTRA     = $(OUT)/libpray.wasm
include ports/rules.mk

# The library for the playground (ports/wasm/playground): pray.cpp without files
# (PRAY_NO_STDIO: textures come from the page) and the functions the page calls
# (ports/wasm/glue.cpp), a WASI reactor whose memory grows to at most PLAYGROUND_MEMORY bytes.
PLAYGROUND_MEMORY = 1073741824
$(OUT)/libpray.wasm: pray.cpp pray.hpp $(CONFIG) ports/wasm/glue.cpp
	@mkdir -p $(OUT)
	$(CXX) $(FLAGS) -DPRAY_NO_STDIO -mexec-model=reactor pray.cpp ports/wasm/glue.cpp -o $@ \
	  -nostdlib++ -Wl,--strip-all $(STACK) -Wl,--max-memory=$(PLAYGROUND_MEMORY) -lm
