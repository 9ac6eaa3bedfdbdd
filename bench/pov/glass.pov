// glass.pov - examples/glass.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). A glass ball in front of five coloured posts, a stone
// ball beside it, a floor and a back wall (two half-spaces), one point light. The posts are
// infinite cylinders cut by the half-space Top, whose face (of the Floor material) is their
// top: here each is a closed cylinder reaching into the floor, intersected with Top.
// Flat: one colour per material; the posts' materials are written inline in the .ray (the
// "// ray:" comments), and Top gets its own colour.
#version 3.7;
#include "pray.inc"

#declare Eye = <0.4, -6, 1.2>;
#declare Look = <0, 0.5, -0.2>;
#declare View = Look - Eye;
#declare Xv = 2.4*vnormalize(vcross(View, z));
#declare Yv = 2.4*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.2, 0.2, 0.25>, <0.2, 0.2, 0.25>, Xv, Yv, Eye, Look)

#declare Glass = Model(<0, 0, 0>, 0.7, <0, 0, 0>, 80, 0, <0.75, 0.88, 0.95>, 1.5)
#declare Stone = Phong(<0.6, 0.55, 0.5>, 0.2, <0, 0, 0>, 10)
#declare Floor = Phong(<0.85, 0.85, 0.8>, 0, <0, 0, 0>, 1)
#declare Top = Floor;
#declare P1 = Phong(<0.9, 0.2, 0.2>, 0.3, <0, 0, 0>, 20)
#declare P2 = Phong(<0.9, 0.7, 0.1>, 0.3, <0, 0, 0>, 20)
#declare P3 = Phong(<0.2, 0.8, 0.2>, 0.3, <0, 0, 0>, 20)
#declare P4 = Phong(<0.2, 0.6, 0.9>, 0.3, <0, 0, 0>, 20)
#declare P5 = Phong(<0.6, 0.3, 0.9>, 0.3, <0, 0, 0>, 20)
#if (Flat)
  #declare Glass = FlatColour(<0, 1, 1>)
  #declare Stone = FlatColour(<0.4, 0.4, 0.4>)
  #declare Floor = FlatColour(<1, 1, 0.6>)
  #declare Top = FlatColour(<1, 1, 1>)
  #declare P1 = FlatColour(<1, 0, 0>)  // ray: phong({0.9, 0.2, 0.2}, {0.3}, 20)
  #declare P2 = FlatColour(<1, 0.6, 0>)  // ray: phong({0.9, 0.7, 0.1}, {0.3}, 20)
  #declare P3 = FlatColour(<0, 0.6, 0>)  // ray: phong({0.2, 0.8, 0.2}, {0.3}, 20)
  #declare P4 = FlatColour(<0, 0, 1>)  // ray: phong({0.2, 0.6, 0.9}, {0.3}, 20)
  #declare P5 = FlatColour(<0.6, 0.2, 1>)  // ray: phong({0.6, 0.3, 0.9}, {0.3}, 20)
#end

Half(Floor, <0, 0, -1>, z)                       // the floor
Half(Floor, <0, 5, 0>, -y)                       // the back wall
sphere { <0, 0, 0>, 1 material { Glass } }
sphere { <-2.1, 0.6, -0.55>, 0.45 material { Stone } }

#macro Post(Px, M)
  intersection {
    cylinder { <Px, 3.6, -1.5>, <Px, 3.6, 2>, 0.18 material { M } }
    Half(Top, <0, 0, 1.4>, z)
  }
#end
Post(-1.6, P1) Post(-0.8, P2) Post(0, P3) Post(0.8, P4) Post(1.6, P5)

PointLight(<0.9, 0.9, 0.9>, <-5, -2, 4>)
