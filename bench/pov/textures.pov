// textures.pov - examples/textures.ray in POV-Ray 3.7's language, for the benchmark suite and
// the flat-colour check (docs/povray.md). A floor of twelve planks (the wood image laid by
// planemap, moved differently on every plank, between dark gaps), a brick wall coloured and
// bumped by one image, three balls with images wrapped round them by spheremap (a checker, the
// wood, and bumps on steel), and a label in pray's built-in font (text.inc builds the same
// boxes as pray). The images are tex/*.tif (a copy of examples/tex where POV-Ray runs), read
// at pray's texture coordinates by the macros of pray.inc. The bumps are POV-Ray function
// normals of the images' luminance. pray tilts the normal by a times the luminance's slope per
// image; POV-Ray's bump_size has a scale of its own, so its values (-0.05 for pray's -0.012 on
// the wall, 0.8 for 0.05 on the ball) are the ones that came closest to pray's picture, by the
// mean difference over the wall and over the ball: close, not exact. A plank,
// infinite along Y and downwards in pray, is bounded here by a box that reaches into the wall
// and the floor below it and 10^4 units towards the eye.
// Flat: one colour per material; the label's model and the checkered ball's blend of Red and
// Cream are written inline in the .ray (the "// ray:" comments).
#version 3.7;
#include "pray.inc"
#include "text.inc"

#declare Eye = <1.2, -6.5, 1.6>;
#declare Look = <0, 0.6, -0.3>;
#declare View = Look - Eye;
#declare Xv = 2.6*vnormalize(vcross(View, z));
#declare Yv = 2.6*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.3, 0.35, 0.45>, <0.3, 0.35, 0.45>, Xv, Yv, Eye, Look)

// tiff(phong({0}, {0.25}, 30), phong({1}, {0.25}, 30), wood.tif): the image's colours
#declare WoodFinish = finish { diffuse 1 ambient 0 phong 0.25 phong_size 30 }
#declare Gap = Phong(<0.1, 0.07, 0.04>, 0, <0, 0, 0>, 1)
#macro Plank(K) material { texture {
  PlaneMapPigment("tex/wood.tif", <-3 + K*0.5, 0, -1>, <0, 2.5, 0>, <0.5, 0, 0>, K*0.37, K*0.61)
  finish { WoodFinish } } } #end
// tiffbump(tiff(phong({0}, {0}, 1), phong({1}, {0.1}, 10), brick.tif), -0.012, brick.tif) on
// planemap([0, 3, 0], -y, 1.6x, -0.8z): colour c, highlight 0.1 c (exponent 1: here a grey 0.05)
#declare BrickImg = function { pigment { image_map { tiff "tex/brick.tif" interpolate 2 } } }
#declare BrickS = function(x, y, z) { x/1.6 - floor(x/1.6) }
#declare BrickT = function(x, y, z) { 1 - (-z/0.8 - floor(-z/0.8)) }
#declare BrickLum = function(x, y, z) { BrickImg(BrickS(x, y, z), BrickT(x, y, z), 0).red*0.2126
  + BrickImg(BrickS(x, y, z), BrickT(x, y, z), 0).green*0.7152 + BrickImg(BrickS(x, y, z), BrickT(x, y, z), 0).blue*0.0722 }
#declare Brick = material { texture {
  PlaneMapPigment("tex/brick.tif", <0, 3, 0>, <1.6, 0, 0>, <0, 0, -0.8>, 0, 0)
  normal { function { BrickLum(x, y, z) } bump_size -0.05 }
  finish { diffuse 1 ambient 0 phong 0.05 phong_size 1 } } }
#declare CheckLum = SphereLum("tex/checker.tif", <-1.9, 0.4, -0.35>, <0, 0.3, 1>, <-1, -1, 0>, 0, 0)
#declare Checks = material { texture {                      // tiff(Red, Cream, checker.tif)
  pigment { function { min(0.9999, CheckLum(x, y, z)) }
            color_map { [0 rgb <0.8, 0.1, 0.1>] [0.9999 rgb <0.95, 0.92, 0.8>] } }
  finish { diffuse 1 ambient 0 phong 0.5 phong_size 40 } } }
#declare Bowl = material { texture {
  SphereImage("tex/wood.tif", <0, 0.9, -0.35>, <1, 0, 0.4>, <0, -1, 0>, 0, 0)
  finish { WoodFinish } } }
#declare BumpLum = SphereLum("tex/bumps.tif", <1.9, 0.3, -0.35>, <0, 0, 1>, <0, -1, 0>, 0, 0)
#declare Bumpy = material { texture {                       // tiffbump(Steel, 0.05, bumps.tif)
  pigment { rgb <0.35, 0.37, 0.4> }
  normal { function { BumpLum(x, y, z) } bump_size 0.8 }
  finish { diffuse 1 ambient 0 phong 0.8 phong_size 60 reflection { rgb 0.35 } } } }
#declare Label = Phong(<0.95, 0.8, 0.2>, 0.5, <0.2, 0.16, 0.04>, 30)
#if (Flat)
  #declare Black = FlatColour(<0, 0, 0.4>)
  #declare White = FlatColour(<1, 1, 1>)
  #declare Wood = FlatColour(<0.6, 0.4, 0>)
  #macro Plank(K) Wood #end
  #declare Gap = FlatColour(<0.2, 0.2, 0.2>)
  #declare Brick = FlatColour(<0.8, 0.2, 0>)
  #declare Red = FlatColour(<1, 0, 0>)
  #declare Cream = FlatColour(<1, 1, 0.6>)
  #declare Checks = FlatColour(<0, 1, 0>)  // ray: tiff(Red, Cream, "tex/checker.tif")
  #declare Bowl = Wood;
  #declare Steel = FlatColour(<0.4, 0.6, 1>)
  #declare Bumpy = Steel;
  #declare Label = FlatColour(<1, 0.8, 0>)  // ray: phong({0.95, 0.8, 0.2}, {0.5}, {0.2, 0.16, 0.04}, 30)
#end

// ---- the floor: the gaps' floor and twelve planks
Half(Gap, <0, 0, -1.01>, z)
#declare K = 0;
#while (K < 12)
  #declare X0 = -3 + K*0.5;
  intersection {
    Half(Plank(K), <X0, 0, -1>, z)
    Half(Gap, <X0 + 0.01, 0, 0>, -x)
    Half(Gap, <X0 + 0.49, 0, 0>, x)
    bounded_by { box { <X0 + 0.009, -1e4, -1.02>, <X0 + 0.491, 3.001, -0.999> } }
  }
  #declare K = K + 1;
#end

Half(Brick, <0, 3, 0>, -y)                       // the wall

sphere { <-1.9, 0.4, -0.35>, 0.65 material { Checks } }
sphere { <0, 0.9, -0.35>, 0.65 material { Bowl } }
sphere { <1.9, 0.3, -0.35>, 0.65 material { Bumpy } }

Text(Label, "TEXTURES", <-1.25, -1.6, -1>, <0.32, 0, 0>, <0, 0, 0.45>, 0.08, "", 1)

DirLight(<0.85, 0.85, 0.85>, <1, 2, -1.6>)
PointLight(<0.45, 0.45, 0.45>, <-2, -6, 3>)
