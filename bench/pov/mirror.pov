// mirror.pov - examples/mirror.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). A mirror ball on a floor, three matte balls around it,
// one point light with shadows.
// Flat: one colour per material (Chrome, Matte, Red, Green, Blue).
#version 3.7;
#include "pray.inc"

#declare Eye = <0, -6, 1.5>;
#declare Look = <0, 0, -0.3>;
#declare View = Look - Eye;
#declare Xv = 2.6*vnormalize(vcross(View, z));
#declare Yv = 2.6*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.55, 0.7, 0.9>, <0.55, 0.7, 0.9>, Xv, Yv, Eye, Look)

#declare Chrome = Model(<0.05, 0.05, 0.05>, 0.8, <0, 0, 0>, 60, 0.85, <0, 0, 0>, 1)
#declare Matte = Phong(<0.75, 0.72, 0.65>, 0.1, <0, 0, 0>, 10)
#declare Red = Phong(<0.8, 0.15, 0.1>, 0.4, <0, 0, 0>, 20)
#declare Green = Phong(<0.2, 0.7, 0.25>, 0.4, <0, 0, 0>, 20)
#declare Blue = Phong(<0.15, 0.25, 0.85>, 0.4, <0, 0, 0>, 20)
#if (Flat)
  #declare Chrome = FlatColour(<0.6, 0.6, 0.6>)
  #declare Matte = FlatColour(<1, 1, 0.6>)
  #declare Red = FlatColour(<1, 0, 0>)
  #declare Green = FlatColour(<0, 1, 0>)
  #declare Blue = FlatColour(<0, 0, 1>)
#end

Half(Matte, <0, 0, -1>, <0, 0, 1>)               // the floor: everything below z = -1
sphere { <0, 0, 0>, 1 material { Chrome } }
sphere { <-2, 1.2, -0.4>, 0.6 material { Red } }
sphere { <1.2, 2.6, -0.3>, 0.7 material { Green } }
sphere { <1.7, -0.8, -0.55>, 0.45 material { Blue } }

PointLight(<1, 1, 1>, <-5, -3, 4>)
