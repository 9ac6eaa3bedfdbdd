// chess.pov - examples/chess.ray ("Chess") in POV-Ray 3.7's language, for bench/pov.sh.
// The version-2 primitives of PRAY one to one: box, cylinder (rod), cone, torus (POV-Ray's lies
// around its Y axis: turned to pray's Z), and a scaled sphere for stretch.
// Flat: one colour per material (Ebony, Ivory, Dark, Light).
#version 3.7;
#include "pray.inc"

#declare Eye = <3.4, -5.2, 3.6>;
#declare Look = <0.2, 0.4, 0.5>;
#declare View = Look - Eye;
#declare Xv = 1.9*vnormalize(vcross(View, z));
#declare Yv = 1.9*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.55, 0.62, 0.75>, <0.2, 0.22, 0.3>, Xv, Yv, Eye, Look)

#declare Ebony = Phong(<0.12, 0.1, 0.09>, 0.6, <0.02, 0.02, 0.02>, 60)
#declare Ivory = Phong(<0.88, 0.84, 0.72>, 0.45, <0.1, 0.1, 0.09>, 40)
#declare Dark = Phong(<0.35, 0.2, 0.1>, 0.2, <0.05, 0.03, 0.02>, 15)
#declare Light = Phong(<0.85, 0.7, 0.5>, 0.2, <0.1, 0.08, 0.06>, 15)
#if (Flat)
  #declare Ebony = FlatColour(<1, 0, 0>)
  #declare Ivory = FlatColour(<0, 1, 0>)
  #declare Dark = FlatColour(<0, 0, 1>)
  #declare Light = FlatColour(<1, 1, 0>)
#end

// torus(M, C, <0, 0, 1>, R, r)
#macro TorusZ(M, C, R, Rt) torus { R, Rt rotate 90*x translate C material { M } } #end

#declare Board = union {
  #for (I, 0, 3)
    #for (J, 0, 3)
      #if (mod(I + J, 2) < 1)
        box { <I - 2, J - 2, -0.2>, <I - 1, J - 1, 0> material { Dark } }
      #else
        box { <I - 2, J - 2, -0.2>, <I - 1, J - 1, 0> material { Light } }
      #end
    #end
  #end
}

#declare Pawn = union {
  cylinder { <0, 0, 0>, <0, 0, 0.12>, 0.36 material { Ivory } }
  TorusZ(Ivory, <0, 0, 0.14>, 0.28, 0.06)
  cone { <0, 0, 0.12>, 0.27, <0, 0, 0.66>, 0.09 material { Ivory } }
  TorusZ(Ivory, <0, 0, 0.66>, 0.15, 0.05)
  sphere { <0, 0, 0.82>, 0.17 material { Ivory } }
}

#declare Mitre = sphere { <0, 0, 0>, 1 scale <0.17, 0.17, 0.27> translate <0, 0, 1.27> material { Ebony } }
#declare Slot = box { <-0.3, -0.035, 0>, <0.3, 0.035, 0.4> rotate <0, -35, 0> rotate <0, 0, -60>
                      translate <0.02, 0, 1.3> material { Ebony } }
#declare Bishop = union {
  cylinder { <0, 0, 0>, <0, 0, 0.12>, 0.38 material { Ebony } }
  TorusZ(Ebony, <0, 0, 0.14>, 0.3, 0.06)
  cone { <0, 0, 0.12>, 0.29, <0, 0, 1.02>, 0.08 material { Ebony } }
  TorusZ(Ebony, <0, 0, 1.02>, 0.16, 0.05)
  difference { object { Mitre } object { Slot } }
  sphere { <0, 0, 1.59>, 0.06 material { Ebony } }
}

#declare Crown = difference {
  cylinder { <0, 0, 0.78>, <0, 0, 1.1>, 0.3 material { Ivory } }
  cylinder { <0, 0, 0.98>, <0, 0, 1.2>, 0.2 material { Ivory } }
  box { <-0.4, -0.05, 0.98>, <0.4, 0.05, 1.2> material { Ivory } }
  box { <-0.05, -0.4, 0.98>, <0.05, 0.4, 1.2> material { Ivory } }
}
#declare Rook = union {
  cylinder { <0, 0, 0>, <0, 0, 0.12>, 0.38 material { Ivory } }
  TorusZ(Ivory, <0, 0, 0.14>, 0.3, 0.06)
  cone { <0, 0, 0.12>, 0.29, <0, 0, 0.78>, 0.22 material { Ivory } }
  object { Crown rotate <0, 0, 30> }
}

object { Board }
object { Pawn translate <-0.5, -0.5, 0> }
object { Bishop translate <0.5, 0.5, 0> }
object { Rook translate <-1.5, 1.5, 0> }
DirLight(<0.9, 0.9, 0.9>, <1, 2, -3>)
PointLight(<0.35, 0.35, 0.35>, <-3, -4, 5>)
