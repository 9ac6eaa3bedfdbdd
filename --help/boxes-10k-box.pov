// boxes-10k-box.pov - bookshelves: 20 shelves of 500 books, each book and board a box
// written by bench/suite/gen.py
#version 3.7;
#include "pray.inc"
#declare Eye = <-12, -26, 13>;
#declare Look = <28, 0, 10>;
#declare View = Look - Eye;
#declare Xv = 12*vnormalize(vcross(View, z));
#declare Yv = 12*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
background { rgb <0.2, 0.25, 0.35> }
#declare Red = Model(<0.85, 0.25, 0.2>, 0.5, <0.102, 0.03, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Gold = Model(<0.95, 0.75, 0.2>, 0.5, <0.114, 0.09, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Green = Model(<0.25, 0.7, 0.35>, 0.5, <0.03, 0.084, 0.042>, 40, 0, <0, 0, 0>, 1)
#declare Blue = Model(<0.3, 0.45, 0.9>, 0.5, <0.036, 0.054, 0.108>, 40, 0, <0, 0, 0>, 1)
#declare White = Model(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20, 0, <0, 0, 0>, 1)
#declare Grey = Model(<0.45, 0.46, 0.5>, 0.1, <0.06, 0.06, 0.06>, 5, 0, <0, 0, 0>, 1)
DirLight(<1, 1, 1>, <1, 2, -3>)
plane { z, 0 material { Grey } }
#declare S = 17;
#declare L = 0;
#while (L < 20)
  #declare Z = 1.2*L;
  box { <-0.2, 0, Z - 0.1>, <62, 0.8, Z> material { White } }
  #declare X = 0;
  #declare N = 0;
  #while (N < 500)
    #declare S = mod(S*16807, 2147483647);
    #declare A = S/2147483647;
    #declare S = mod(S*16807, 2147483647);
    #declare B = S/2147483647;
    #declare S = mod(S*16807, 2147483647);
    #declare C = S/2147483647;
    #declare K = mod(N + L, 4);
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
    #declare W = 0.06 + 0.12*A;
    box { <X, 0.05, Z>, <X + W, 0.5 + 0.25*C, Z + 0.6 + 0.4*B> material { M } }
    #declare X = X + W + 0.003;
    #declare N = N + 1;
  #end
  #declare L = L + 1;
#end
