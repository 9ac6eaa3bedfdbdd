/* ports/tiny/prayconf.h — the smallest useful pray: single precision, no PNG, no threads, no
   light or eye buffers, no image-sequence coherence.
   Notes and measured sizes in ports/tiny/README.md. */
#ifndef PRAY_PORT_TINY_H
#define PRAY_PORT_TINY_H

#define PRAY_REAL float
#define PRAY_NO_PNG
#define PRAY_NO_THREADS
/* the mechanisms that only make some renders faster: the images are the same without them */
#define PRAY_NO_BUFFERS
#define PRAY_NO_SEQUENCES
/* The library alone (no command-line program) can also drop the interpreter:
   -DPRAY_NO_INTERP, as ports/tiny/tiny.mk does for libpray.o. */

#endif
