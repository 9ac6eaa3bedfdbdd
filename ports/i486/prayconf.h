/* ports/i486/prayconf.h — the 486-class Linux stand-in for DOS: exactly the DJGPP settings, so
   that what is tested here is what a DOS build compiles. Notes in ports/i486/README.md. */
#include "../djgpp/prayconf.h"
