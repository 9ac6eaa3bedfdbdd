/* ports/tiny/prayconf.h — the smallest useful pray: single precision, no PNG, no threads, no
   image-sequence coherence.
   Notes and measured sizes in ports/tiny/README.md. */
#ifndef PRAY_PORT_TINY_H
#define PRAY_PORT_TINY_H

#define PRAY_REAL float
#define PRAY_NO_PNG
#define PRAY_NO_THREADS
/* a mechanism that only makes some renders faster: the images are the same without it */
#define PRAY_NO_SEQUENCES
/* The library alone (no command-line program) can also drop the interpreter:
   -DPRAY_NO_INTERP, as ports/tiny/tiny.mk does for libpray.o. */

#endif
