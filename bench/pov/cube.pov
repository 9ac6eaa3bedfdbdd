// cube.pov - examples/cube.ray ("Cube") in POV-Ray 3.7's language, for bench/pov.sh.
// A cube of side 2 with rounded corners (six half-spaces and a sphere; here a box and the
// sphere), drilled by 8 x 8 holes along each of the three axes, with a spherical cavity, on a
// floor. pray's holes are infinite cylinders; here each is a closed cylinder from -1.5 to 1.5,
// which passes right through the cube (its end caps lie outside it and are never seen), so
// the visible surface is the same and POV-Ray can bound every hole. As in pray, the 193 things
// taken away are the children of one difference.
// Flat: one colour per material (Ivory, HoleX, HoleY, HoleZ, Gold, Stone).
#version 3.7;
#include "pray.inc"

#declare Eye = <4.2, -5.6, 3.9>;
#declare Look = <0, 0, -0.3>;
#declare View = Look - Eye;
#declare Xv = 2.1*vnormalize(vcross(View, z));
#declare Yv = 2.1*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.62, 0.7, 0.8>, <0.3, 0.33, 0.4>, Xv, Yv, Eye, Look)

#declare Ivory = Phong(<0.85, 0.82, 0.72>, 0.35, <0.1, 0.1, 0.09>, 25)
#declare HoleX = Phong(<0.8, 0.4, 0.3>, 0.2, <0.1, 0.05, 0.04>, 15)
#declare HoleY = Phong(<0.35, 0.7, 0.4>, 0.2, <0.05, 0.09, 0.05>, 15)
#declare HoleZ = Phong(<0.35, 0.5, 0.85>, 0.2, <0.04, 0.06, 0.1>, 15)
#declare Gold = Phong(<0.9, 0.7, 0.25>, 0.6, <0.12, 0.09, 0.03>, 40)
#declare Stone = Phong(<0.5, 0.5, 0.52>, 0.05, <0.07, 0.07, 0.07>, 3)
#if (Flat)
  #declare Ivory = FlatColour(<1, 1, 0.6>)
  #declare HoleX = FlatColour(<1, 0, 0>)
  #declare HoleY = FlatColour(<0, 1, 0>)
  #declare HoleZ = FlatColour(<0, 0, 1>)
  #declare Gold = FlatColour(<1, 0.6, 0>)
  #declare Stone = FlatColour(<0.4, 0.4, 0.4>)
#end

#declare S = 1;
#declare N = 8;
#declare D = 2*S/N;
#declare R = 0.34*D;
#declare L = 1.5*S;              // half the length of a hole
difference {
  intersection { box { -S, S } sphere { 0, 1.6*S } material { Ivory } }
  #declare I = 0;
  #while (I < N)
    #declare A = -S + (I + 0.5)*D;
    #declare J = 0;
    #while (J < N)
      #declare B = -S + (J + 0.5)*D;
      cylinder { <-L, A, B>, <L, A, B>, R material { HoleX } }
      cylinder { <A, -L, B>, <A, L, B>, R material { HoleY } }
      cylinder { <A, B, -L>, <A, B, L>, R material { HoleZ } }
      #declare J = J + 1;
    #end
    #declare I = I + 1;
  #end
  sphere { 0, 0.55*S material { Gold } }
}
Half(Stone, <0, 0, -S>, <0, 0, 1>)

DirLight(<0.85, 0.85, 0.85>, <-0.8, 1.3, -1.6>)
PointLight(<0.3, 0.3, 0.3>, <5, -2, 3>)
