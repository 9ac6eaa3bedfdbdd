// cluster-10k.pov - 10000 small balls in a cube of side 2, in a plain 1000 units wide with 60 pillars
// written by bench/suite/gen.py
#version 3.7;
#include "pray.inc"
#declare Eye = <0, -7, 4.5>;
#declare Look = <0, 0, 3>;
#declare View = Look - Eye;
#declare Xv = 1.6*vnormalize(vcross(View, z));
#declare Yv = 1.6*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
background { rgb <0.55, 0.65, 0.8> }
#declare Red = Model(<0.85, 0.25, 0.2>, 0.5, <0.102, 0.03, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Gold = Model(<0.95, 0.75, 0.2>, 0.5, <0.114, 0.09, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Green = Model(<0.25, 0.7, 0.35>, 0.5, <0.03, 0.084, 0.042>, 40, 0, <0, 0, 0>, 1)
#declare Blue = Model(<0.3, 0.45, 0.9>, 0.5, <0.036, 0.054, 0.108>, 40, 0, <0, 0, 0>, 1)
#declare White = Model(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20, 0, <0, 0, 0>, 1)
#declare Grey = Model(<0.45, 0.46, 0.5>, 0.1, <0.06, 0.06, 0.06>, 5, 0, <0, 0, 0>, 1)
DirLight(<1, 1, 1>, <1, 2, -3>)
plane { z, 0 material { Grey } }
#declare S = 11;
#declare N = 0;
#while (N < 60)
  #declare S = mod(S*16807, 2147483647);
  #declare X = S/2147483647;
  #declare S = mod(S*16807, 2147483647);
  #declare Y = S/2147483647;
  cylinder { <-500 + 1000*X, 50 + 450*Y, -1>, <-500 + 1000*X, 50 + 450*Y, 40>, 3 material { White } }
  #declare N = N + 1;
#end
#declare S = 13;
#declare N = 0;
#while (N < 10000)
  #declare S = mod(S*16807, 2147483647);
  #declare X = S/2147483647;
  #declare S = mod(S*16807, 2147483647);
  #declare Y = S/2147483647;
  #declare S = mod(S*16807, 2147483647);
  #declare Z = S/2147483647;
  #declare K = mod(N, 4);
  #if (K < 1)
    #declare M = Red;
  #else
    #if (K < 2)
      #declare M = Gold;
    #else
      #if (K < 3)
        #declare M = Green;
      #else
        #declare M = Blue;
      #end
    #end
  #end
  sphere { <-1 + 2*X, -1 + 2*Y, 2 + 2*Z>, 0.03 material { M } }
  #declare N = N + 1;
#end
