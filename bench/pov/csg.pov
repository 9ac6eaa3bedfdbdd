// csg.pov - examples/csg.ray (the thesis' CSG.RAY) in POV-Ray 3.7's language, for bench/pov.sh.
// A cube of six half-spaces and a rod (an infinite cylinder cut by two half-spaces); the
// bottom row shows their union, difference and intersection, the top row the two solids.
// The half-spaces are POV-Ray planes, as in the thesis. The infinite cylinder is a closed
// cylinder 2 units long: it is only ever seen where the cube or the caps at +-0.15 cut it, so
// its own end caps never show, and POV-Ray can bound it. Flat: each of the nine primitives
// o1..o9 in its own colour (the scene has one material, so that is the useful granularity).
#version 3.7;
#include "pray.inc"

#declare X0 = <1, 0, 0>;
#declare Eye = <2, -5, 2>;
#declare Point = <0.5, 0.5, 0.5>;
#declare View = Point - Eye;
#declare Yv = -1.1*vnormalize(vcross(X0, View));
#declare Xv = 1.1*vnormalize(vcross(Yv, View));
Perspective(Xv, Yv, Eye, Point)
#if (Flat) background { rgb 0 } #end

DirLight(<1, 1, 1>, <-0.3, 0.6, -0.4>)
#declare White = Phong(<0.6, 0.6, 0.6>, 0.3, <0.1, 0.1, 0.1>, 10)

#declare o1 = White; #declare o2 = White; #declare o3 = White;
#declare o4 = White; #declare o5 = White; #declare o6 = White;
#declare o7 = White; #declare o8 = White; #declare o9 = White;
#if (Flat)
  #declare White = FlatColour(<0.6, 0.6, 0.6>)   // (all its faces are o1..o9)
  #declare o1 = FlatColour(<1, 0, 0>)
  #declare o2 = FlatColour(<0, 1, 0>)
  #declare o3 = FlatColour(<0, 0, 1>)
  #declare o4 = FlatColour(<1, 1, 0>)
  #declare o5 = FlatColour(<1, 0, 1>)
  #declare o6 = FlatColour(<0, 1, 1>)
  #declare o7 = FlatColour(<1, 1, 1>)
  #declare o8 = FlatColour(<1, 0.6, 0.2>)
  #declare o9 = FlatColour(<0.4, 0.2, 1>)
#end

#declare Cube = intersection {
  Half(o1, <-0.1, 0, 0>, <-1, 0, 0>)
  Half(o2, <0.1, 0, 0>, <1, 0, 0>)
  Half(o3, <0, -0.1, 0>, <0, -1, 0>)
  Half(o4, <0, 0.1, 0>, <0, 1, 0>)
  Half(o5, <0, 0, -0.1>, <0, 0, -1>)
  Half(o6, <0, 0, 0.1>, <0, 0, 1>)
  bounded_by { box { -0.1001, 0.1001 } }
}
#declare Rod = intersection {
  cylinder { <0, 0, -1>, <0, 0, 1>, 0.05 material { o7 } }
  Half(o8, <0, 0, 0.15>, <0, 0, 1>)
  Half(o9, <0, 0, -0.15>, <0, 0, -1>)
  bounded_by { box { <-0.0501, -0.0501, -0.1501>, <0.0501, 0.0501, 0.1501> } }
}

union {
  union { object { Cube } object { Rod } translate <-0.3, 0, 0> }      // Uni
  difference { object { Cube } object { Rod } }                         // Dif
  intersection { object { Cube } object { Rod } translate <0.25, 0, 0> }  // Int
  object { Cube translate <-0.15, 0, 0.4> }                            // Pri
  object { Rod translate <0.2, 0, 0.4> }
  scale 1.3 translate <0.55, 0.5, 0.25>
}
