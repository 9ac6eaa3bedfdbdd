/* ports/big-endian/prayconf.h — big-endian Linux (s390x, 64-bit PowerPC, MIPS). Nothing here
   is about byte order: pray's TIFF and PPM writers set every byte explicitly, and this port
   exists to prove it (ports/big-endian/README.md). */
#ifndef PRAY_PORT_BIG_ENDIAN_H
#define PRAY_PORT_BIG_ENDIAN_H

/* A cross compiler does not see the build machine's stb_image_write: TIFF and PPM only. */
#define PRAY_NO_PNG

#endif
