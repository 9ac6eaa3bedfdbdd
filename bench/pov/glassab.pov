// glassab.pov - examples/glassab.ray ("Glass abstraction") in POV-Ray 3.7's language, for the
// benchmark suite and the flat-colour check (docs/povray.md). A glass ball, a lens (two balls'
// common part), a hexagonal prism of blue glass with a hollow, a turned amber cube with a round
// hole, two opaque balls, and a mirror in a gold frame, on a checkered floor. The mirror and its
// frame have no bottom face in pray (they run on into the floor): here they are boxes reaching
// into the floor. The floor's tex/checker.tif (8 x 8 squares, black where column + row is even)
// laid on by planemap is POV-Ray's checker pattern with the same squares. pray's option depth 8
// is max_trace_level 8.
// Flat: one colour per material (Glass, Blue, Amber, Silver, Red, Green, Gold, Tiles).
#version 3.7;
#include "pray.inc"
global_settings { max_trace_level 8 }

#declare Eye = <0.8, -7.2, 2.6>;
#declare Look = <0, 0.4, 0.1>;
#declare View = Look - Eye;
#declare Xv = 2.5*vnormalize(vcross(View, z));
#declare Yv = 2.5*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.05, 0.05, 0.12>, <0.35, 0.3, 0.4>, Xv, Yv, Eye, Look)

#declare Glass = Model(<0, 0, 0>, 0.8, <0, 0, 0>, 120, 0.06, <0.9, 0.9, 0.9>, 1.5)
#declare Blue = Model(<0, 0, 0>, 0.8, <0, 0, 0>, 120, 0.05, <0.55, 0.75, 0.95>, 1.45)
#declare Amber = Model(<0, 0, 0>, 0.8, <0, 0, 0>, 120, 0.05, <0.95, 0.7, 0.3>, 1.5)
#declare Silver = Model(<0.05, 0.05, 0.05>, 0.5, <0, 0, 0>, 60, 0.85, <0, 0, 0>, 1)
#declare Red = Phong(<0.85, 0.15, 0.1>, 0.5, <0, 0, 0>, 40)
#declare Green = Phong(<0.15, 0.7, 0.3>, 0.5, <0, 0, 0>, 40)
#declare Gold = Phong(<0.8, 0.6, 0.2>, 0.7, <0.12, 0.09, 0.03>, 40)
// tiff(phong({0.12, 0.1, 0.15}, {0.2}, 20), phong({0.9, 0.88, 0.8}, {0.2}, 20), checker.tif) on
// planemap([0, 0, -1], z, 8x, 8y): squares of 1, the first colour where floor(x) + floor(y) is
// even. The pattern is moved so that z = -1 lies inside one layer.
#declare Tiles = material { texture {
  pigment { checker rgb <0.12, 0.1, 0.15> rgb <0.9, 0.88, 0.8> translate <0, 0, -1.5> }
  finish { diffuse 1 ambient 0 phong 0.2 phong_size 20 } } }
#if (Flat)
  #declare Glass = FlatColour(<0, 1, 1>)
  #declare Blue = FlatColour(<0, 0, 1>)
  #declare Amber = FlatColour(<1, 0.6, 0>)
  #declare Silver = FlatColour(<0.6, 0.6, 0.6>)
  #declare Red = FlatColour(<1, 0, 0>)
  #declare Green = FlatColour(<0, 1, 0>)
  #declare Gold = FlatColour(<1, 1, 0.4>)
  #declare Tiles = FlatColour(<0.6, 0.2, 0.6>)
#end

Half(Tiles, <0, 0, -1>, z)                       // the floor
sphere { <-1.7, -0.2, -0.3>, 0.7 material { Glass } }
intersection {                                   // the lens
  sphere { <0.2, -1.15, -0.41>, 1.2 }
  sphere { <0.2, 0.95, -0.41>, 1.2 }
  material { Glass }
}

// the prism: two faces and six sides, minus a hollow ball
difference {
  intersection {
    Half(Blue, <0, 0, 0.9>, z)
    Half(Blue, <0, 0, -1>, -z)
    #declare K = 0;
    #while (K < 6)
      #declare Out = <cos(K*pi/3 + pi/6), sin(K*pi/3 + pi/6), 0>;
      Half(Blue, 0.5*Out, Out)
      #declare K = K + 1;
    #end
  }
  sphere { <0, 0, 0.2>, 0.32 material { Blue } }
  bounded_by { box { <-0.6, -0.6, -1.01>, <0.6, 0.6, 0.91> } }
  translate <1.6, 0.9, 0>
}

// the amber cube with a hole along Y, turned and moved
difference {
  box { -0.4, 0.4 }
  cylinder { <0, -1, 0>, <0, 1, 0>, 0.2 }
  material { Amber }
  rotate <0, 0, 35>
  translate <1.7, -0.9, -0.6>
}

sphere { <-1.3, 1.4, -0.55>, 0.45 material { Red } }
sphere { <0.1, 1.5, -0.6>, 0.4 material { Green } }

Box(Silver, <-2.3, 2.6, -2>, <2.3, 2.65, 1.2>)   // the mirror
Box(Gold, <-2.45, 2.65, -2>, <2.45, 2.8, 1.35>)  // its frame

PointLight(<0.8, 0.8, 0.8>, <-3, -4, 5>)
PointLight(<0.35, 0.35, 0.35>, <4, 1, 3>)
