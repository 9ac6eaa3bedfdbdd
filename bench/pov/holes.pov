// holes.pov - examples/holes.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). A die (a box rounded by a ball) drilled by three
// cylinders, a ball with a bite taken out, a hexagonal nut with a hole, on a table. The
// infinite cylinders become closed cylinders that pass right through what they are taken
// from (their end caps are never seen). A & -B is the difference A - B. The nut is an
// intersection of eight half-spaces, with a hand-written bounded_by.
// Flat: one colour per material (Ivory, Apple, Steel, Wood), and the holes' walls (Cx, Cy,
// Cz) and the bite (Bite) get their own.
#version 3.7;
#include "pray.inc"

#declare Eye = <0, -6.5, 3.2>;
#declare Look = <0, 0.4, -0.3>;
#declare View = Look - Eye;
#declare Xv = 3.1*vnormalize(vcross(View, z));
#declare Yv = 3.1*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.3, 0.35, 0.4>, <0.3, 0.35, 0.4>, Xv, Yv, Eye, Look)

#declare Ivory = Phong(<0.9, 0.88, 0.8>, 0.3, <0.08, 0.08, 0.08>, 20)
#declare Apple = Phong(<0.7, 0.85, 0.2>, 0.5, <0.06, 0.06, 0.06>, 40)
#declare Steel = Phong(<0.55, 0.6, 0.65>, 0.6, <0.06, 0.06, 0.06>, 30)
#declare Wood = Phong(<0.55, 0.4, 0.25>, 0.1, <0.06, 0.06, 0.06>, 5)
#declare Cx = Ivory;                             // the walls of the holes and of the bite
#declare Cy = Ivory;
#declare Cz = Ivory;
#declare Bite = Apple;
#if (Flat)
  #declare Ivory = FlatColour(<1, 1, 0.6>)
  #declare Cx = FlatColour(<1, 0, 0>)
  #declare Cy = FlatColour(<0, 1, 0>)
  #declare Cz = FlatColour(<0, 0, 1>)
  #declare Bite = FlatColour(<1, 0.4, 1>)
  #declare Apple = FlatColour(<0.4, 1, 0>)
  #declare Steel = FlatColour(<0.4, 0.6, 1>)
  #declare Wood = FlatColour(<0.6, 0.2, 0>)
#end

// the die, turned 25 degrees about the vertical axis
difference {
  intersection { box { -0.8, 0.8 } sphere { 0, 1.05 } material { Ivory } }
  cylinder { <-1.5, 0, 0>, <1.5, 0, 0>, 0.35 material { Cx } }
  cylinder { <0, -1.5, 0>, <0, 1.5, 0>, 0.35 material { Cy } }
  cylinder { <0, 0, -1.5>, <0, 0, 1.5>, 0.35 material { Cz } }
  rotate <0, 0, 25>
}

// the bitten ball
difference {
  sphere { <-2.2, 0.7, -0.1>, 0.7 material { Apple } }
  sphere { <-1.75, 0.25, 0.25>, 0.45 material { Bite } }
}

// the nut: six sides and two faces, minus a hole
#declare Centre = <2.2, 0.6, -0.6>;
difference {
  intersection {
    #declare K = 0;
    #while (K < 6)
      #declare A = K*pi/3;
      #declare Out = <cos(A), sin(A), 0>;
      Half(Steel, Centre + 0.75*Out, Out)
      #declare K = K + 1;
    #end
    Half(Steel, Centre + <0, 0, 0.2>, z)
    Half(Steel, Centre - <0, 0, 0.2>, -z)
  }
  cylinder { Centre - <0, 0, 0.5>, Centre + <0, 0, 0.5>, 0.38 material { Steel } }
  bounded_by { box { Centre - <0.9, 0.9, 0.21>, Centre + <0.9, 0.9, 0.21> } }
}

Half(Wood, <0, 0, -0.8>, z)                      // the table

DirLight(<0.9, 0.9, 0.9>, <1, 1.5, -2>)
