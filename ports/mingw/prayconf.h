/* ports/mingw/prayconf.h — Windows, built with mingw-w64. Notes in ports/mingw/README.md. */
#ifndef PRAY_PORT_MINGW_H
#define PRAY_PORT_MINGW_H

/* Threads stay: pray uses Win32 threads (CreateThread) directly, so no winpthreads DLL and
   either flavour of the mingw-w64 compiler (-win32 or -posix) will do. Define PRAY_NO_THREADS
   for a single-threaded build. */

/* mingw-w64 does not see the build machine's stb_image_write: TIFF and PPM only. */
#define PRAY_NO_PNG

#endif
