/* ports/wasm/prayconf.h — pray for wasm32-wasi (WebAssembly with the WASI system interface):
   one thread, and no PNG: the toolchain has no setjmp, with which pray's PNG encoder stops on an
   allocation that fails. Notes and measured sizes in ports/wasm/README.md. */
#ifndef PRAY_PORT_WASM_H
#define PRAY_PORT_WASM_H

#define PRAY_NO_THREADS
#define PRAY_NO_PNG

#endif
