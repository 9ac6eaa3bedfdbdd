// fractal.pov - examples/fractal.ray ("Fractal") in POV-Ray 3.7's language, for bench/pov.sh.
// A stepped base (three triangular steps, each the intersection of five half-spaces) and 1024
// balls placed as a Sierpinski tetrahedron of level 5, on a floor. pray renders one union of
// them all; POV-Ray's scene is itself a union of its top-level objects, so the balls, the steps
// and the floor are written as top-level objects, which POV-Ray puts in its bounding hierarchy.
// The steps are bounded by hand (POV-Ray cannot bound an intersection of planes by itself).
// Flat: one colour per material (M0..M3, Marble, Slate).
#version 3.7;
#include "pray.inc"

#declare Eye = <-2.9, -5.4, 3.3>;
#declare Look = <0, 0.1, 0.5>;
#declare View = Look - Eye;
#declare Xv = 2.05*vnormalize(vcross(View, z));
#declare Yv = 2.05*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.16, 0.2, 0.32>, <0.55, 0.5, 0.5>, Xv, Yv, Eye, Look)

#declare M0 = Phong(<0.85, 0.25, 0.2>, 0.5, <0.1, 0.03, 0.03>, 40)
#declare M1 = Phong(<0.95, 0.75, 0.2>, 0.5, <0.1, 0.08, 0.02>, 40)
#declare M2 = Phong(<0.25, 0.7, 0.35>, 0.5, <0.03, 0.08, 0.04>, 40)
#declare M3 = Phong(<0.3, 0.45, 0.9>, 0.5, <0.03, 0.05, 0.1>, 40)
#declare Marble = Phong(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20)
#declare Slate = Phong(<0.35, 0.36, 0.4>, 0.1, <0.05, 0.05, 0.05>, 5)
#if (Flat)
  #declare M0 = FlatColour(<1, 0, 0>)
  #declare M1 = FlatColour(<1, 1, 0>)
  #declare M2 = FlatColour(<0, 1, 0>)
  #declare M3 = FlatColour(<0, 0, 1>)
  #declare Marble = FlatColour(<1, 1, 1>)
  #declare Slate = FlatColour(<0.4, 0.4, 0.4>)
#end

#declare L = 2.6;
#declare Z0 = 0.3;
#declare Rc = L/sqrt(3);
#declare H = L*sqrt(2/3);
#declare Mid = <0, 0, Z0 + H/4>;

// the stepped base
#declare K = 0;
#while (K < 3)
  #declare Rs = Rc*(1.15 + 0.17*K);
  #declare Zt = Z0 - 0.1*K;
  intersection {
    Half(Marble, <0, 0, Zt>, <0, 0, 1>)
    Half(Marble, <0, 0, Zt - 0.1>, <0, 0, -1>)
    #declare C = 0;
    #while (C < 3)
      #declare A = radians(270 + 120*C);
      Half(Marble, <Rs/2*cos(A), Rs/2*sin(A), 0>, <cos(A), sin(A), 0>)
      #declare C = C + 1;
    #end
    bounded_by { box { <-Rs, -Rs, Zt - 0.1001>, <Rs, Rs, Zt + 0.0001> } }
  }
  #declare K = K + 1;
#end
Half(Slate, <0, 0, Z0 - 0.3>, <0, 0, 1>)

// the balls: ball I is found by reading I as five base-4 digits
#declare N = 1024;
#declare Levels = 5;
#declare R = 0.49*L/pow(2, Levels);
#declare I = 0;
#while (I < N)
  #declare P = Mid;
  #declare Q = I;
  #declare F = 0.5;
  #declare Lv = 0;
  #while (Lv < Levels)
    #declare Dg = mod(Q, 4);
    #declare Q = (Q - Dg)/4;
    #if (Dg = 3)
      #declare W = <0, 0, 3*H/4>;
    #else
      #declare A = radians(90 + 120*Dg);
      #declare W = <Rc*cos(A), Rc*sin(A), -H/4>;
    #end
    #declare P = P + F*W;
    #if (Lv = 0) #declare Top = Dg; #end
    #declare F = F/2;
    #declare Lv = Lv + 1;
  #end
  sphere { P, R material { #switch (Top) #case (0) M0 #break #case (1) M1 #break #case (2) M2 #break #else M3 #end } }
  #declare I = I + 1;
#end

DirLight(<0.85, 0.85, 0.85>, <1.2, 1.6, -2.2>)
PointLight(<0.3, 0.3, 0.3>, <-4, -3, 5>)
