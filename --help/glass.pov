// glass.pov - glass and mirror balls among 100 small opaque balls on a floor, a sun and a lamp
// written by bench/suite/gen.py
#version 3.7;
#include "pray.inc"
#declare Eye = <0, -12, 6>;
#declare Look = <0, 0, 0.5>;
#declare View = Look - Eye;
#declare Xv = 6*vnormalize(vcross(View, z));
#declare Yv = 6*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
background { rgb <0.55, 0.65, 0.8> }
#declare Red = Model(<0.85, 0.25, 0.2>, 0.5, <0.102, 0.03, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Gold = Model(<0.95, 0.75, 0.2>, 0.5, <0.114, 0.09, 0.024>, 40, 0, <0, 0, 0>, 1)
#declare Green = Model(<0.25, 0.7, 0.35>, 0.5, <0.03, 0.084, 0.042>, 40, 0, <0, 0, 0>, 1)
#declare Blue = Model(<0.3, 0.45, 0.9>, 0.5, <0.036, 0.054, 0.108>, 40, 0, <0, 0, 0>, 1)
#declare White = Model(<0.8, 0.78, 0.74>, 0.3, <0.1, 0.1, 0.1>, 20, 0, <0, 0, 0>, 1)
#declare Grey = Model(<0.45, 0.46, 0.5>, 0.1, <0.06, 0.06, 0.06>, 5, 0, <0, 0, 0>, 1)
#declare Glass = Model(<0, 0, 0>, 0.7, <0, 0, 0>, 80, 0.1, <0.9, 0.9, 0.9>, 1.5)
#declare Mirror = Model(<0.1, 0.1, 0.1>, 0.5, <0, 0, 0>, 50, 0.8, <0, 0, 0>, 1)
DirLight(<0.7, 0.7, 0.7>, <1, 2, -3>)
PointLight(<0.5, 0.5, 0.5>, <-3, -3, 6>)
plane { z, 0 material { White } }
#declare S = 19;
#declare I = 0;
#while (I < 10)
  #declare J = 0;
  #while (J < 10)
    #declare S = mod(S*16807, 2147483647);
    #declare X = S/2147483647;
    #declare S = mod(S*16807, 2147483647);
    #declare Y = S/2147483647;
    #declare X = -5.4 + 1.2*I + 0.3*(X - 0.5);
    #declare Y = -5.4 + 1.2*J + 0.3*(Y - 0.5);
    #declare J2 = mod(I + 3*J, 7);
    #if (J2 < 1)
      sphere { <X, Y, 0.42>, 0.42 material { Glass } }
    #else
      #if (J2 < 2)
        sphere { <X, Y, 0.42>, 0.42 material { Mirror } }
      #else
        #declare K = mod(I + J, 4);
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
        sphere { <X, Y, 0.3>, 0.3 material { M } }
      #end
    #end
    #declare J = J + 1;
  #end
  #declare I = I + 1;
#end
