// parallel.pov - examples/parallel.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). A parallel view of unit cubes (boxes here) moved, turned
// and shrunk, and a ball, lit by two directional lights, in front of a background that blends
// from the top row to the bottom row (a backdrop here, see pray.inc). The .ray file asks for
// 2 x 2 anti-aliasing; the benchmarks render both programs without it.
// Flat: one colour per material (Clay, Slate).
#version 3.7;
#include "pray.inc"

#declare Look = <0, 0.3, -0.6>;
#declare Eye = Look + <6, -8, 6>;
#declare View = Look - Eye;
#declare Xv = 2.6*vnormalize(vcross(View, z));
#declare Yv = 2.6*vnormalize(vcross(View, Xv));
Parallel(Xv, Yv, Eye, Look)
ParallelBackground(<0.15, 0.25, 0.6>, <0.95, 0.8, 0.6>, Xv, Yv, Eye, Look)

#declare Clay = Phong(<0.85, 0.5, 0.3>, 0.3, <0.12, 0.07, 0.05>, 15)
#declare Slate = Phong(<0.3, 0.4, 0.5>, 0.3, <0, 0, 0>, 15)
#if (Flat)
  #declare Clay = FlatColour(<1, 0.6, 0.2>)
  #declare Slate = FlatColour(<0, 0.4, 1>)
#end

#declare Block = Box(Clay, -0.5, 0.5)
object { Block translate <0, 0, -1.5> }          // the base
object { Block translate <1.1, 0, -1.5> }
object { Block translate <0, 1.1, -1.5> }
object { Block translate <1.1, 1.1, -1.5> }
object { Block rotate <0, 0, 45> translate <0.55, 0.55, -0.5> }                // the tower
object { Block scale 0.5 rotate <0, 0, 20> translate <0.55, 0.55, 0.25> }      // the cap
sphere { <-1.2, 1.5, 0.6>, 0.6 material { Slate } }                             // the moon

DirLight(<0.8, 0.8, 0.8>, <1, 0.6, -1.5>)
DirLight(<0.25, 0.25, 0.25>, <-1, 1, 0.2>)
