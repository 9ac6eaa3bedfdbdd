/* ports/arm-linux/prayconf.h — embedded Linux on ARM (armhf and AArch64). Notes in
   ports/arm-linux/README.md. */
#ifndef PRAY_PORT_ARM_LINUX_H
#define PRAY_PORT_ARM_LINUX_H

/* Threads stay: the C library's POSIX threads (glibc, musl, uClibc-ng) are used. */

/* A cross compiler does not see the build machine's <stb/stb_image_write.h>; say so rather than
   depend on what the sysroot happens to hold. TIFF and PPM are written. */
#define PRAY_NO_PNG

/* On an ARM without a double-precision FPU (ARMv5 armel, Cortex-M class), add
   #define PRAY_REAL float: the renderer then works in single precision (the API stays double). */

#endif
