// rabbit.pov - examples/rabbit.ray ("Rabbit") in POV-Ray 3.7's language, for the benchmark
// suite and the flat-colour check (docs/povray.md). A rabbit of balls, capsules and half-spaces
// on a checkered floor, built by the same loops. A capsule (an infinite cylinder cut square by
// two half-spaces, with a ball on its end) is a closed cylinder and a sphere; the ears' grooves
// are closed cylinders whose lower caps lie outside the ear. The floor's texture,
// tex/checker.tif (8 x 8 squares, black where column + row is even) laid on it by planemap, is
// POV-Ray's checker pattern with the same squares: the same picture without reading the file.
// Flat: one colour per material (Fur, Belly, Pink, Eyeball, Whisker, Grass).
#version 3.7;
#include "pray.inc"

#declare Eye = <-3.4, -4.6, 2.2>;
#declare Look = <-0.1, 0, 0.75>;
#declare View = Look - Eye;
#declare Xv = 1.35*vnormalize(vcross(View, z));
#declare Yv = 1.35*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.55, 0.68, 0.85>, <0.95, 0.93, 0.88>, Xv, Yv, Eye, Look)

#declare Fur = Phong(<0.62, 0.5, 0.38>, 0.12, <0.1, 0.08, 0.06>, 8)
#declare Belly = Phong(<0.9, 0.86, 0.8>, 0.1, <0.14, 0.13, 0.12>, 8)
#declare Pink = Phong(<0.95, 0.6, 0.65>, 0.2, <0.15, 0.09, 0.1>, 15)
#declare Eyeball = Model(<0.02, 0.02, 0.02>, 0.9, <0, 0, 0>, 120, 0.1, <0, 0, 0>, 1)
#declare Whisker = Phong(<0.95, 0.95, 0.95>, 0.3, <0, 0, 0>, 20)
// tiff(phong({0.35, 0.55, 0.3}, {0.1}, 10), phong({0.75, 0.85, 0.6}, {0.1}, 10), checker.tif)
// on planemap([0, 0, 0], z, 4x, 4y): squares of 0.5, the first colour where
// floor(2x) + floor(2y) is even. The pattern is moved so that z = 0 lies inside one layer.
#declare Grass = material { texture {
  pigment { checker rgb <0.35, 0.55, 0.3> rgb <0.75, 0.85, 0.6> scale 0.5 translate <0, 0, -0.25> }
  finish { diffuse 1 ambient 0 phong 0.1 phong_size 10 } } }
#if (Flat)
  #declare Fur = FlatColour(<0.6, 0.4, 0.2>)
  #declare Belly = FlatColour(<1, 1, 0.8>)
  #declare Pink = FlatColour(<1, 0.4, 0.6>)
  #declare Eyeball = FlatColour(<0, 0, 1>)
  #declare Whisker = FlatColour(<1, 0, 0>)
  #declare Grass = FlatColour(<0, 0.6, 0>)
#end

// ---- body, head and muzzle
union {
  sphere { <0.3, 0, 0.55>, 0.55 material { Fur } }
  sphere { <-0.22, 0, 0.66>, 0.42 material { Fur } }
  sphere { <-0.36, 0, 0.6>, 0.34 material { Belly } }
}
union {
  sphere { <-0.62, 0, 1.17>, 0.33 material { Fur } }
  sphere { <-0.86, 0.1, 1.06>, 0.15 material { Belly } }
  sphere { <-0.86, -0.1, 1.06>, 0.15 material { Belly } }
  sphere { <-1.0, 0, 1.13>, 0.045 material { Pink } }
  sphere { <-0.8, 0.2, 1.25>, 0.06 material { Eyeball } }
  sphere { <-0.8, -0.2, 1.25>, 0.06 material { Eyeball } }
}

// ---- the ears
#declare S = -1;
#while (S <= 1)
  #declare B = <-0.55, 0.13*S, 1.38>;
  #declare D = vnormalize(<0.35, 0.28*S, 1>);
  #declare F = vnormalize(<-1, 0, 0> - D*vdot(D, <-1, 0, 0>));
  #declare L = 0.62;
  #declare Tip = B + D*L;
  difference {
    intersection {
      union { cylinder { B, Tip, 0.1 } sphere { Tip, 0.1 } material { Fur } }
      Half(Fur, B + F*0.05, F)
      Half(Fur, B - F*0.05, -F)
    }
    union { cylinder { B + F*0.05 - D*0.2, Tip + F*0.05, 0.055 } sphere { Tip + F*0.05, 0.055 } material { Pink } }
    bounded_by { sphere { B + D*L/2, L/2 + 0.11 } }
  }
  #declare S = S + 2;
#end

// ---- paws and hind feet
sphere { <-0.52, 0.17, 0.08>, 0.1 material { Belly } }
sphere { <-0.52, -0.17, 0.08>, 0.1 material { Belly } }
#declare S = -1;
#while (S <= 1)
  #declare A = <-0.2, 0.36*S, 0.11>;
  #declare C = <0.5, 0.36*S, 0.11>;
  union { cylinder { A, C, 0.11 } sphere { A, 0.11 } sphere { C, 0.11 } material { Fur } }
  #declare S = S + 2;
#end

// ---- the tail
union {
  sphere { <0.86, 0, 0.5>, 0.13 }
  #declare K = 0;
  #while (K < 8)
    sphere { <0.86, 0, 0.5> + <0.09*cos(K*pi/4), 0.09*sin(K*pi/4), 0.07*sin(K*1.7)>, 0.07 }
    #declare K = K + 1;
  #end
  material { Belly }
}

// ---- whiskers
union {
  #declare S = -1;
  #while (S <= 1)
    #declare K = -1;
    #while (K <= 1)
      #declare W0 = <-0.93, 0.08*S, 1.05>;
      #declare Dir = vnormalize(<-0.25, S, 0.25*K>);
      cylinder { W0, W0 + Dir*0.38, 0.006 }
      #declare K = K + 1;
    #end
    #declare S = S + 2;
  #end
  material { Whisker }
}

// ---- the floor
Half(Grass, <0, 0, 0>, z)

DirLight(<0.85, 0.85, 0.85>, <0.8, 1, -1.6>)
PointLight(<0.3, 0.3, 0.3>, <-4, -5, 3>)
