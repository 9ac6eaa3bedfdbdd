/* ports/djgpp/prayconf.h — pray on DOS, built with DJGPP. Named by PRAY_USER_CONFIG
   (ports/djgpp/djgpp.mk, ports/djgpp/flags.rsp); notes in ports/djgpp/README.md.
   Also the configuration of the 486-class stand-in that is tested here (ports/i486). */
#ifndef PRAY_PORT_DJGPP_H
#define PRAY_PORT_DJGPP_H

/* DOS has no threads (DJGPP's <unistd.h> has no _POSIX_THREADS either; this says it plainly). */
#define PRAY_NO_THREADS

/* No stb_image_write on DOS: pray writes TIFF and PPM, both in binary mode. */
#define PRAY_NO_PNG

/* 8.3 file names. While an image is written it has a unique temporary name, by default
   .CSG.TIF.XXXXXX + PRAY_TEMP_SUFFIX, which only a DOS with long file names (LFN=y: Windows
   9x/XP DOS boxes, DOSLFN) can hold; and frames after the first are named NAME_0001.TIF, which is
   8.3 only for names of 3 characters. PRAY_8_3_NAMES asks for CSXXXXXX.$$$ (two characters of
   the name, six unique ones, the suffix as extension) and FRA_0001.TIF (the name shortened). */
#define PRAY_TEMP_SUFFIX ".$$$"
#define PRAY_8_3_NAMES

#endif
