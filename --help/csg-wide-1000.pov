// csg-wide-1000.pov - a slab minus 1000 cutters: dimples (balls) and holes (cylinders)
// written by bench/suite/gen.py
#version 3.7;
#include "pray.inc"
#declare Eye = <0, -12, 10>;
#declare Look = <0, 0, -0.5>;
#declare View = Look - Eye;
#declare Xv = 6*vnormalize(vcross(View, z));
#declare Yv = 6*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
background { rgb <0.2, 0.25, 0.35> }
#declare Red = Model(<0.85, 0.25, 0.2>, 0.5, <0.102, 0.03, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Blue = Model(<0.3, 0.45, 0.9>, 0.5, <0.036, 0.054, 0.108>, 40, 0, <0, 0, 0>, 1)
#declare White = Model(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20, 0, <0, 0, 0>, 1)
#declare Grey = Model(<0.45, 0.46, 0.5>, 0.1, <0.06, 0.06, 0.06>, 5, 0, <0, 0, 0>, 1)
DirLight(<1, 1, 1>, <1, 2, -3>)
difference {
box { <-5, -5, -1>, <5, 5, 0> material { White } }
#declare S = 5;
#declare N = 0;
#while (N < 1000)
  #declare S = mod(S*16807, 2147483647);
  #declare X = S/2147483647;
  #declare S = mod(S*16807, 2147483647);
  #declare Y = S/2147483647;
  #declare S = mod(S*16807, 2147483647);
  #declare R = S/2147483647;
  #declare X = -4.5 + 9*X;
  #declare Y = -4.5 + 9*Y;
  #declare R = 0.12 + 0.18*R;
  #declare J = mod(N, 2);
  #if (J < 1)
    sphere { <X, Y, 0>, R material { Red } }
  #else
    cylinder { <X, Y, -3>, <X, Y, 3>, R/2 material { Blue } }
  #end
  #declare N = N + 1;
#end
}
