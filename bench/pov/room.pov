// room.pov - examples/room.ray ("Room", the general view) in POV-Ray 3.7's language, for
// bench/pov.sh. The same walls, window, door, plank floor, rug, table, bowl, fruit, mug,
// chairs, bookcase with its pseudo-random books, lamps, sideboard, vase, picture and mirror,
// built by the same loops. A box of six half-spaces of one model is a POV-Ray box; an infinite
// cylinder cut square by two half-spaces is a closed cylinder between them; an infinite
// cylinder that is only cut on one side (the round mirror, a hole's inner cylinder) is a
// closed cylinder that reaches past everything it touches, into a wall or through the part it
// is taken from, so its end caps are never seen. The room's inside (Air) keeps its six
// half-spaces, because each wall has its own material. The union of everything is POV-Ray's
// scene itself: the parts are top-level objects; the smaller unions are POV-Ray unions.
// Flat: one colour per material (31 of them).
#version 3.7;
#include "pray.inc"

#declare Xv = <1.8103, 1.7241, 0>;       // CAMERA: the general view
#declare Yv = <0.2548, -0.2675, -2.4725>;
#declare Eye = <5.3, 0.55, 1.55>;
#declare Look = <2.3, 3.7, 0.9>;
Perspective(Xv, Yv, Eye, Look)
Background(<0.4, 0.6, 0.92>, <0.85, 0.9, 0.95>, Xv, Yv, Eye, Look)

// ---------------------------------------------------------------- materials
#declare Cream = Phong(<0.82, 0.77, 0.66>, 0.05, <0.13, 0.12, 0.1>, 5)
#declare Sage = Phong(<0.6, 0.7, 0.6>, 0.05, <0.09, 0.11, 0.09>, 5)
#declare Ceiling = Phong(<0.9, 0.9, 0.88>, 0, <0.15, 0.15, 0.15>, 1)
#declare Gap = Phong(<0.15, 0.1, 0.06>, 0, <0.03, 0.03, 0.03>, 1)
#declare Oak = Phong(<0.72, 0.52, 0.3>, 0.25, <0.1, 0.07, 0.04>, 25)
#declare Beech = Phong(<0.8, 0.62, 0.42>, 0.25, <0.11, 0.08, 0.05>, 25)
#declare Walnut = Phong(<0.42, 0.27, 0.15>, 0.3, <0.06, 0.04, 0.02>, 30)
#declare Paint = Phong(<0.92, 0.92, 0.9>, 0.3, <0.13, 0.13, 0.13>, 30)
#declare Rug1 = Phong(<0.6, 0.12, 0.1>, 0, <0.08, 0.02, 0.02>, 1)
#declare Rug2 = Phong(<0.85, 0.75, 0.5>, 0, <0.11, 0.1, 0.07>, 1)
#declare Cushion = Phong(<0.25, 0.35, 0.6>, 0.1, <0.04, 0.05, 0.09>, 8)
#declare Brass = Phong(<0.7, 0.55, 0.25>, 0.7, <0.08, 0.06, 0.03>, 60)
#declare Shade = Model(<0.5, 0.45, 0.32>, 0.1, <0.12, 0.1, 0.06>, 5, 0, <0.6, 0.5, 0.35>, 1)
#declare Bulb = Glow(<1, 0.96, 0.82>)
#declare Glass = Model(<0, 0, 0>, 0.7, <0, 0, 0>, 80, 0.08, <0.82, 0.9, 0.88>, 1.5)
#declare Pane = Model(<0, 0, 0>, 0.5, <0, 0, 0>, 100, 0, <0.9, 0.95, 0.95>, 1.5)
#declare Mirror = Model(<0.03, 0.03, 0.03>, 0.5, <0, 0, 0>, 80, 0.85, <0, 0, 0>, 1)
#declare China = Phong(<0.9, 0.9, 0.92>, 0.6, <0.13, 0.13, 0.13>, 60)
#declare Orange = Phong(<0.95, 0.5, 0.08>, 0.3, <0.12, 0.06, 0.01>, 20)
#declare Apple = Phong(<0.75, 0.1, 0.08>, 0.5, <0.1, 0.02, 0.01>, 40)
#declare Lime = Phong(<0.45, 0.75, 0.15>, 0.4, <0.06, 0.1, 0.02>, 30)
#declare Canvas = Phong(<0.55, 0.75, 0.95>, 0, <0.09, 0.11, 0.13>, 1)
#declare Hills = Phong(<0.3, 0.6, 0.25>, 0, <0.05, 0.08, 0.04>, 1)
#declare SunPaint = Phong(<1, 0.85, 0.2>, 0, <0.15, 0.12, 0.03>, 1)
#declare Stalk = Phong(<0.2, 0.5, 0.15>, 0.1, <0.03, 0.06, 0.02>, 5)
#declare Petal = Phong(<0.95, 0.3, 0.55>, 0.2, <0.12, 0.04, 0.07>, 10)
#declare B0 = Phong(<0.6, 0.1, 0.1>, 0.2, <0.07, 0.02, 0.02>, 15)
#declare B1 = Phong(<0.1, 0.25, 0.55>, 0.2, <0.02, 0.03, 0.07>, 15)
#declare B2 = Phong(<0.15, 0.45, 0.2>, 0.2, <0.02, 0.06, 0.03>, 15)
#declare B3 = Phong(<0.85, 0.7, 0.3>, 0.2, <0.1, 0.08, 0.04>, 15)
#declare B4 = Phong(<0.3, 0.25, 0.22>, 0.2, <0.04, 0.03, 0.03>, 15)
#if (Flat)
  #declare Cream = FlatColour(<1, 1, 0.6>)
  #declare Sage = FlatColour(<0.6, 1, 0.6>)
  #declare Ceiling = FlatColour(<1, 1, 1>)
  #declare Gap = FlatColour(<0.2, 0.2, 0.2>)
  #declare Oak = FlatColour(<1, 0.6, 0.2>)
  #declare Beech = FlatColour(<0.8, 0.8, 0.4>)
  #declare Walnut = FlatColour(<0.6, 0.2, 0>)
  #declare Paint = FlatColour(<0.8, 0.8, 1>)
  #declare Rug1 = FlatColour(<1, 0, 0>)
  #declare Rug2 = FlatColour(<1, 0.8, 0.6>)
  #declare Cushion = FlatColour(<0, 0, 1>)
  #declare Brass = FlatColour(<0.8, 0.6, 0>)
  #declare Shade = FlatColour(<1, 0.4, 1>)
  #declare Bulb = FlatColour(<1, 1, 0>)
  #declare Glass = FlatColour(<0, 1, 1>)
  #declare Pane = FlatColour(<0.4, 0.8, 1>)
  #declare Mirror = FlatColour(<0.4, 0.4, 0.6>)
  #declare China = FlatColour(<0.6, 0.6, 0.6>)
  #declare Orange = FlatColour(<1, 0.4, 0>)
  #declare Apple = FlatColour(<0.6, 0, 0.2>)
  #declare Lime = FlatColour(<0.4, 1, 0>)
  #declare Canvas = FlatColour(<0, 0.6, 1>)
  #declare Hills = FlatColour(<0, 0.6, 0>)
  #declare SunPaint = FlatColour(<1, 1, 0.2>)
  #declare Stalk = FlatColour(<0, 0.4, 0.2>)
  #declare Petal = FlatColour(<1, 0.2, 0.6>)
  #declare B0 = FlatColour(<0.8, 0, 0>)
  #declare B1 = FlatColour(<0, 0.2, 0.6>)
  #declare B2 = FlatColour(<0.2, 0.6, 0.4>)
  #declare B3 = FlatColour(<1, 0.8, 0.2>)
  #declare B4 = FlatColour(<0.4, 0.2, 0.2>)
#end

// ---------------------------------------------------------------- the shell
#declare T = 0.15;
difference {
  Box(Cream, <-T, -T, -T>, <6 + T, 5 + T, 2.8 + T>)
  intersection {                                    // the room's air: each face its material
    Half(Cream, <6, 0, 0>, x) Half(Sage, <0, 0, 0>, -x) Half(Cream, <0, 5, 0>, y)
    Half(Cream, <0, 0, 0>, -y) Half(Ceiling, <0, 0, 2.8>, z) Half(Gap, <0, 0, 0>, -z)
  }
  Box(Paint, <2.6, 4.8, 0.9>, <4.2, 5.5, 2.2>)       // the window opening
  Box(Paint, <5.8, 1, -0.05>, <6.5, 2, 2.1>)         // the door opening
}

// the window: a frame, a cross of glazing bars, a pane
union {
  difference { Box(Paint, <2.6, 5.02, 0.9>, <4.2, 5.1, 2.2>) Box(Paint, <2.68, 4.9, 0.98>, <4.12, 5.2, 2.12>) }
  Box(Paint, <3.37, 5.04, 0.98>, <3.43, 5.08, 2.12>)
  Box(Paint, <2.68, 5.04, 1.52>, <4.12, 5.08, 1.58>)
  Box(Pane, <2.68, 5.055, 0.98>, <4.12, 5.065, 2.12>)
}

// the door leaf, open to the outside
union {
  Box(Paint, <-0.04, -0.98, 0>, <0, 0, 2.08>)
  sphere { <0.04, -0.88, 1.0>, 0.04 material { Brass } }
  sphere { <-0.08, -0.88, 1.0>, 0.04 material { Brass } }
  rotate <0, 0, 65> translate <6.19, 1.98, 0.02>
}

// ---------------------------------------------------------------- the floor
#declare K = 0;
#while (K < 10)
  Box(#switch (mod(K, 3)) #case (0) Oak #break #case (1) Beech #break #else Walnut #end,
      <0, 0.5*K + 0.004, 0>, <6, 0.5*K + 0.496, 0.02>)
  #declare K = K + 1;
#end

// the rug: a red ring round a sand-coloured disc
#declare Rc = <2.8, 2.6, 0>;
union {
  difference {
    cylinder { Rc + <0, 0, 0.01>, Rc + <0, 0, 0.032>, 1.4 material { Rug1 } }
    cylinder { Rc, Rc + <0, 0, 0.05>, 1.2 material { Rug1 } }
  }
  cylinder { Rc + <0, 0, 0.01>, Rc + <0, 0, 0.03>, 1.2 material { Rug2 } }
}

// ---------------------------------------------------------------- the table
union {
  Box(Walnut, <2, 2.15, 0.72>, <3.6, 3.05, 0.77>)
  #declare I = 0;
  #while (I < 4)
    #declare Lx = 2.1 + 1.4*mod(I, 2);
    #declare Ly = 2.25 + 0.7*((I - mod(I, 2))/2);
    cylinder { <Lx, Ly, 0.02>, <Lx, Ly, 0.72>, 0.035 material { Walnut } }
    #declare I = I + 1;
  #end
}

// a glass bowl with three fruits
#declare C = <2.55, 2.6, 0.955>;
union {
  intersection {
    difference { sphere { C, 0.2 } sphere { C, 0.18 } Half(Glass, C + <0, 0, 0.06>, -z) }
    Half(Glass, <0, 0, 0.77>, -z)
    material { Glass }
  }
  sphere { C + <0.05, 0.03, -0.1>, 0.065 material { Orange } }
  sphere { C + <-0.06, 0.02, -0.095>, 0.065 material { Apple } }
  sphere { C + <0, -0.07, -0.09>, 0.062 material { Lime } }
}

// a mug with a half-ring handle
#declare C = <3.2, 2.8, 0.77>;
#declare H = C + <0.045, 0, 0.05>;
union {
  difference { cylinder { C, C + <0, 0, 0.1>, 0.045 } cylinder { C - <0, 0, 0.1>, C + <0, 0, 0.2>, 0.038 } }
  cylinder { C, C + <0, 0, 0.008>, 0.04 }
  intersection {
    difference { cylinder { H - <0, 0.007, 0>, H + <0, 0.007, 0>, 0.032 } cylinder { H - <0, 0.1, 0>, H + <0, 0.1, 0>, 0.022 } }
    Half(China, H, -x)
  }
  material { China }
}

// ---------------------------------------------------------------- the chairs
#declare Chair = union {
  #declare I = 0;
  #while (I < 4)                                   // four legs
    #declare Lx = -0.19 + 0.38*mod(I, 2);
    #declare Ly = -0.19 + 0.38*((I - mod(I, 2))/2);
    cylinder { <Lx, Ly, 0>, <Lx, Ly, 0.44>, 0.022 material { Beech } }
    #declare I = I + 1;
  #end
  Box(Cushion, <-0.22, -0.22, 0.44>, <0.22, 0.22, 0.49>)        // the seat
  #declare I = 0;
  #while (I < 2)                                   // two back posts
    Box(Beech, <-0.21 + 0.38*I, -0.22, 0.49>, <-0.17 + 0.38*I, -0.18, 1>)
    #declare I = I + 1;
  #end
  #declare I = 0;
  #while (I < 3)                                   // three slats
    Box(Beech, <-0.17, -0.215, 0.62 + 0.13*I>, <0.17, -0.185, 0.68 + 0.13*I>)
    #declare I = I + 1;
  #end
}
object { Chair rotate <0, 0, 12> translate <2.75, 1.6, 0.02> }
object { Chair rotate <0, 0, 180> translate <2.9, 3.55, 0.02> }
object { Chair rotate <0, 0, -90> translate <1.55, 2.6, 0.02> }

// ---------------------------------------------------------------- the bookcase
union {
  Box(Oak, <0.3, 4.6, 0>, <0.34, 4.99, 1.95>)
  Box(Oak, <1.86, 4.6, 0>, <1.9, 4.99, 1.95>)
  Box(Oak, <0.34, 4.97, 0>, <1.86, 4.99, 1.95>)
  #declare K = 0;
  #while (K < 5)                                   // bottom, three shelves, top
    #declare Zs = 0.06 + 0.46*K;
    Box(Oak, <0.34, 4.6, Zs>, <1.86, 4.97, Zs + 0.04>)
    #declare K = K + 1;
  #end
}
#declare Nb = 0;
#declare K = 0;
#while (K < 3)                                     // three rows of books
  #declare Zb = 0.1 + 0.46*K;
  #declare Xb = 0.36 + 0.25*K;
  #declare Count = 9 - 2*K;
  #declare I = 0;
  #while (I < Count)
    #declare Rnd = abs(mod(sin(Nb*12.9898 + 4.1414)*43758.5453, 1));
    #declare Rnd2 = abs(mod(sin(Nb*78.233 + 1.732)*24634.6345, 1));
    #declare W = 0.03 + 0.04*Rnd;
    #declare Hb = 0.24 + 0.14*Rnd2;
    #declare Db = 0.18 + 0.1*Rnd;
    Box(#switch (mod(Nb, 5)) #case (0) B0 #break #case (1) B1 #break #case (2) B2 #break #case (3) B3 #break #else B4 #end,
        <Xb, 4.96 - Db, Zb>, <Xb + W, 4.96, Zb + Hb>)
    #declare Xb = Xb + W + 0.004;
    #declare Nb = Nb + 1;
    #declare I = I + 1;
  #end
  #declare K = K + 1;
#end
Box(B1, <1.3, 4.7, 1.48>, <1.65, 4.94, 1.52>)      // a book lying flat
object { Box(B3, <0, -0.24, 0>, <0.035, 0, 0.3>) rotate <0, -20, 0> translate <Xb + 0.1, 4.95, Zb> }
sphere { <0.75, 4.8, 1.61>, 0.09 material { B1 } } // a globe on a brass foot
cylinder { <0.75, 4.8, 1.48>, <0.75, 4.8, 1.51>, 0.05 material { Brass } }

// ---------------------------------------------------------------- the lamps
// The lamps. In pray's union the pole (the cord) has no surface inside the bulb, so the light at
// the bulb's centre shines out all round; here the pole stops at the bulb's surface, which is
// the same visible solid (a merge would be too; plain overlapping objects would not).
#declare C = <5.45, 4.45, 0>;
#declare S = C + <0, 0, 1.5>;
cylinder { C + <0, 0, 0.02>, C + <0, 0, 0.05>, 0.18 material { Brass } }
difference { cylinder { C, S, 0.016 } sphere { S, 0.05 } material { Brass } }
difference { sphere { S, 0.26 } sphere { S, 0.245 } Half(Shade, S, z) material { Shade } }
sphere { S, 0.05 material { Bulb } }
PointLight(<0.4, 0.37, 0.3>, S)

#declare S = <2.8, 2.6, 1.75>;
difference { cylinder { S, <2.8, 2.6, 2.8>, 0.008 } sphere { S - <0, 0, 0.03>, 0.05 } material { Walnut } }
difference { sphere { S, 0.22 } sphere { S, 0.205 } Half(Shade, S, z) material { Shade } }
sphere { S - <0, 0, 0.03>, 0.05 material { Bulb } }
PointLight(<0.6, 0.56, 0.48>, S - <0, 0, 0.03>)

// ---------------------------------------------------------------- the sideboard
Box(Walnut, <1.8, 0, 0>, <3.8, 0.45, 0.8>)
#declare I = 0;
#while (I < 2)
  Box(Oak, <1.88 + 0.94*I, 0.45, 0.1>, <2.78 + 0.94*I, 0.47, 0.72>)
  sphere { <2.7 + 0.2*I, 0.5, 0.45>, 0.025 material { Brass } }
  #declare I = I + 1;
#end
#declare C = <3.3, 0.22, 0.8>;
union {
  intersection {
    difference { sphere { C + <0, 0, 0.12>, 0.12 } cylinder { C - <0, 0, 0.1>, C + <0, 0, 0.4>, 0.05 } }
    Half(China, C, -z)
  }
  difference { cylinder { C + <0, 0, 0.2>, C + <0, 0, 0.34>, 0.06 } cylinder { C + <0, 0, 0.1>, C + <0, 0, 0.4>, 0.05 } }
  cylinder { C, C + <0, 0, 0.02>, 0.06 }
  material { China }
}
#declare I = 0;
#while (I < 3)                                     // three flowers on stalks
  #declare A = radians(40 + 120*I);
  #declare F = C + <0.09*cos(A), 0.09*sin(A), 0.55 + 0.06*I>;
  #declare Dir = F - (C + <0, 0, 0.1>);
  cylinder { C + <0, 0, 0.1>, F, 0.006 material { Stalk } }
  sphere { F, 0.045 material { Petal } }
  sphere { F + 0.03*vnormalize(Dir), 0.02 material { SunPaint } }
  #declare I = I + 1;
#end

// ---------------------------------------------------------------- the left wall
#declare Opening = Box(Brass, <-1, 0.92, 1.27>, <1, 1.68, 1.73>)
difference { Box(Brass, <0, 0.85, 1.2>, <0.05, 1.75, 1.8>) object { Opening } }
Box(Canvas, <0, 0.92, 1.27>, <0.025, 1.68, 1.73>)
intersection {
  union {
    intersection { sphere { <0, 1.45, 1.6>, 0.05 material { SunPaint } } Half(SunPaint, <0.03, 0, 0>, x) }
    intersection {
      union { sphere { <0, 1.05, 0.95>, 0.5 } sphere { <0, 1.55, 0.9>, 0.5 } material { Hills } }
      Half(Hills, <0.034, 0, 0>, x)
    }
  }
  object { Opening }
}

// a round mirror in a brass ring; pray's cylinders run on into the wall
#declare C = <0, 3.2, 1.45>;
cylinder { C - <0.1, 0, 0>, C + <0.02, 0, 0>, 0.42 material { Mirror } }
difference {
  cylinder { C - <0.1, 0, 0>, C + <0.045, 0, 0>, 0.48 }
  cylinder { C - <0.2, 0, 0>, C + <0.1, 0, 0>, 0.42 }
  material { Brass }
}

DirLight(<0.75, 0.7, 0.6>, <-0.45, -1, -0.75>)    // through the window
