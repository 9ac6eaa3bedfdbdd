// models.pov - examples/models.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). One ball per kind of surface on a polished floor: a flat
// colour, phong with three and with four arguments, phong + mirror, and phong scaled by a
// colour. The scaled model has a coloured highlight; POV-Ray's phong is grey, so `metallic`
// tints it with the pigment (exactly so only away from grazing angles).
// Flat: one colour per material. pray's Flat and Glow are names pray.inc uses, so here they are
// FlatBall and GlowBall (the "// ray:" comments tell helper.py).
#version 3.7;
#include "pray.inc"

#declare Eye = <0, -6, 1.8>;
#declare Look = <0, 0, -0.2>;
#declare View = Look - Eye;
#declare Xv = 3*vnormalize(vcross(View, z));
#declare Yv = 3*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.6, 0.65, 0.7>, <0.6, 0.65, 0.7>, Xv, Yv, Eye, Look)

#declare FlatBall = Colour(<0.95, 0.75, 0.2>)
#declare Plain = Phong(<0.2, 0.4, 0.9>, 0.5, <0, 0, 0>, 30)
#declare GlowBall = Phong(<0.2, 0.4, 0.9>, 0.5, <0.15, 0.1, 0.2>, 30)
#declare Shiny = Model(<0.2, 0.4, 0.9>, 0.5, <0, 0, 0>, 30, 0.3, <0, 0, 0>, 1)
#declare Tinted = material { texture {                 // phong({0.8}, {0.5}, 30) * {1, 0.55, 0.2}
  pigment { rgb <0.8, 0.44, 0.16> }
  finish { diffuse 1 ambient 0 phong 0.625 phong_size 30 metallic 1 } } }
#declare Polish = Model(<0.5, 0.5, 0.45>, 0, <0, 0, 0>, 1, 0.25, <0, 0, 0>, 1)
#if (Flat)
  #declare FlatBall = FlatColour(<1, 0.6, 0>)  // ray: Flat
  #declare Plain = FlatColour(<0, 0, 1>)
  #declare GlowBall = FlatColour(<0.6, 0.2, 1>)  // ray: Glow
  #declare Shiny = FlatColour(<0, 1, 1>)
  #declare Tinted = FlatColour(<1, 0, 0>)
  #declare Polish = FlatColour(<0.6, 0.6, 0.6>)
#end

#declare B = <-2.4, 0, -0.5>;
#declare Step = <1.2, 0, 0>;
sphere { B, 0.5 material { FlatBall } }
sphere { B + Step, 0.5 material { Plain } }
sphere { B + 2*Step, 0.5 material { GlowBall } }
sphere { B + 3*Step, 0.5 material { Shiny } }
sphere { B + 4*Step, 0.5 material { Tinted } }
Half(Polish, <0, 0, -1>, z)

DirLight(<0.7, 0.7, 0.7>, <1, 2, -2>)
PointLight(<0.4, 0.4, 0.4>, <-3, -3, 3>)
