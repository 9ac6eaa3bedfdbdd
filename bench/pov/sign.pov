// sign.pov - examples/sign.ray in POV-Ray 3.7's language, for the benchmark suite and the
// flat-colour check (docs/povray.md). A signpost: two wooden boards on two posts, lettered in
// pray's built-in font and in the atlas font tex/font.tif (text.inc builds the same boxes as
// pray), on a checkered lawn. The boards' fronts show tex/wood.tif (an image_map laid as
// planemap lays it); their other faces and the posts have no texture coordinates, so they show
// the image's colour at (0, 0). The lawn's tex/checker.tif is POV-Ray's checker pattern with
// the same squares. The posts are infinite cylinders in pray: here closed ones reaching into
// the lawn. POV-Ray must be able to read tex/ (a copy of examples/tex) where it runs.
// Flat: one colour per material (Black and White make up Wood; they get colours the .pov does
// not use).
#version 3.7;
#include "pray.inc"
#include "text.inc"

#declare Eye = <1.5, -7, 1.2>;
#declare Look = <0, 0, 0.6>;
#declare View = Look - Eye;
#declare Xv = 2.3*vnormalize(vcross(View, z));
#declare Yv = 2.3*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.35, 0.55, 0.85>, <0.85, 0.9, 0.95>, Xv, Yv, Eye, Look)

#declare WoodFinish = finish { diffuse 1 ambient 0 phong 0.2 phong_size 20 }
#declare Wood00 = TexelAt00("tex/wood.tif");
#declare Wood = material { texture { pigment { rgb <Wood00.red, Wood00.green, Wood00.blue> } finish { WoodFinish } } }
#declare UpperFront = material { texture {
  PlaneMapPigment("tex/wood.tif", <0, 0, 0>, <1, 0, 0>, <0, 0, -0.5>, 0, 0) finish { WoodFinish } } }
#declare LowerFront = material { texture {
  PlaneMapPigment("tex/wood.tif", <0, 0, 0>, <1, 0, 0>, <0, 0, -0.5>, 0.4, 0.3) finish { WoodFinish } } }
#declare Paint = Phong(<0.15, 0.25, 0.5>, 0.4, <0.03, 0.04, 0.08>, 30)
#declare Gold = Phong(<0.9, 0.7, 0.25>, 0.6, <0.15, 0.1, 0.03>, 40)
// tiff(phong({0.2, 0.45, 0.15}, {0}, 1), phong({0.3, 0.6, 0.2}, {0}, 1), checker.tif) on
// planemap([0, 0, -0.2], z, 4x, 4y): squares of 0.5, the first colour where floor(2x) + floor(2y)
// is even. The pattern is moved so that z = -0.2 lies inside one layer.
#declare Grass = material { texture {
  pigment { checker rgb <0.2, 0.45, 0.15> rgb <0.3, 0.6, 0.2> scale 0.5 translate <0, 0, -0.45> }
  finish { diffuse 1 ambient 0 phong 0 } } }
#if (Flat)
  #declare Black = FlatColour(<0.2, 0.2, 0.2>)
  #declare White = FlatColour(<1, 1, 1>)
  #declare Wood = FlatColour(<0.6, 0.4, 0.2>)
  #declare UpperFront = Wood;
  #declare LowerFront = Wood;
  #declare Paint = FlatColour(<0, 0, 1>)
  #declare Gold = FlatColour(<1, 0.8, 0>)
  #declare Grass = FlatColour(<0, 0.6, 0>)
#end

// the boards: x from -W to W, y from 0 (the front, textured) to D
#declare W = 1.7;
#declare D = 0.12;
#macro Board(Front, Z0, Z1)
  intersection {
    Half(Front, <0, 0, 0>, -y)
    Half(Wood, <0, D, 0>, y)
    Half(Wood, <-W, 0, 0>, -x) Half(Wood, <W, 0, 0>, x)
    Half(Wood, <0, 0, Z0>, -z) Half(Wood, <0, 0, Z1>, z)
    bounded_by { box { <-W, 0, Z0> - 0.001, <W, D, Z1> + 0.001 } }
  }
#end
Board(UpperFront, 1.1, 1.9)
Board(LowerFront, 0.02, 0.96)

Text(Paint, "PRAY  1995", <-1.45, 0.01, 1.3>, <0.3, 0, 0>, <0, 0, 0.4>, 0.05, "", 1)
#declare Cell = 0.5;
Text(Gold, "Realistic", <-1.4, 0.01, 0.45>, <Cell, 0, 0>, <0, 0, Cell>, 0.05, "tex/font.tif", 0.62)
Text(Gold, "Rendering", <-1.4, 0.01, 0>, <Cell, 0, 0>, <0, 0, Cell>, 0.05, "tex/font.tif", 0.62)

cylinder { <-1.35, 0.25, -1>, <-1.35, 0.25, 2.05>, 0.09 material { Wood } }   // the posts
cylinder { <1.35, 0.25, -1>, <1.35, 0.25, 2.05>, 0.09 material { Wood } }
Half(Grass, <0, 0, -0.2>, z)                                                    // the lawn

DirLight(<0.9, 0.9, 0.9>, <-1, 2, -1.5>)
PointLight(<0.35, 0.35, 0.35>, <3, -8, 4>)
