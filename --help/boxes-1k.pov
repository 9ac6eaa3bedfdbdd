// boxes-1k.pov - a keyboard: 1000 keys on a board, each key a box of six half-spaces
// written by bench/suite/gen.py
#version 3.7;
#include "pray.inc"
#declare Eye = <0, -35, 25>;
#declare Look = <0, 0, 0>;
#declare View = Look - Eye;
#declare Xv = 23*vnormalize(vcross(View, z));
#declare Yv = 23*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
background { rgb <0.2, 0.25, 0.35> }
#declare Red = Model(<0.85, 0.25, 0.2>, 0.5, <0.102, 0.03, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare White = Model(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20, 0, <0, 0, 0>, 1)
#declare Grey = Model(<0.45, 0.46, 0.5>, 0.1, <0.06, 0.06, 0.06>, 5, 0, <0, 0, 0>, 1)
DirLight(<1, 1, 1>, <1, 2, -3>)
box { <-21, -13.5, -1>, <21, 13.5, 0> material { Grey } }
#declare KeyA = box { <-0.4, -0.4, 0>, <0.4, 0.4, 0.4> material { White } }
#declare KeyB = box { <-0.4, -0.4, 0>, <0.4, 0.4, 0.4> material { Red } }
#declare I = 0;
#while (I < 40)
  #declare J = 0;
  #while (J < 25)
    #declare K = mod(I + J*3, 3);
    #if (K < 1)
      #declare B = KeyA;
    #else
      #if (K < 2)
        #declare B = KeyA;
      #else
        #declare B = KeyB;
      #end
    #end
    object { B translate <-19.5 + I, -12 + J, 0> }
    #declare J = J + 1;
  #end
  #declare I = I + 1;
#end
