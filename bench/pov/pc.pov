// pc.pov - examples/pc.ray ("Personal computer") in POV-Ray 3.7's language, for the benchmark
// suite and the flat-colour check (docs/povray.md). A desktop PC on a wooden desk: a monitor
// whose screen shows four lines in pray's built-in font, a case with two floppy drives, a power
// light and a name plate lettered in the atlas tex/font.tif (text.inc builds the same boxes as
// pray), a keyboard of 63 keys laid out by the same loops, a mouse on its cable. The desk's top
// shows tex/wood.tif as planemap lays it (the front plank moved); its other faces have no
// texture coordinates and show the image's colour at (0, 0). Half-spaces that bound nothing on
// one side (the drive bays and slots run on through the case's back, the mouse's groove through
// its back and top) are boxes reaching past the solid they are taken from. POV-Ray must be able
// to read tex/ (a copy of examples/tex) where it runs.
// Flat: one colour per material; pray's Glow is GlowText here (a name pray.inc uses), and the
// mouse's Grey * 1.6 gets its own colour (the "// ray:" comments tell helper.py).
#version 3.7;
#include "pray.inc"
#include "text.inc"

#declare Eye = <4.6, -12.5, 7.2>;
#declare Look = <0.3, -1.1, 1.4>;
#declare View = Look - Eye;
#declare Xv = 4.4*vnormalize(vcross(View, z));
#declare Yv = 4.4*vnormalize(vcross(View, Xv));
Perspective(Xv, Yv, Eye, Look)
Background(<0.75, 0.73, 0.68>, <0.75, 0.73, 0.68>, Xv, Yv, Eye, Look)

#declare Beige = Phong(<0.82, 0.79, 0.7>, 0.25, <0.14, 0.13, 0.11>, 20)
#declare Keycap = Phong(<0.88, 0.86, 0.8>, 0.3, <0.15, 0.14, 0.12>, 30)
#declare Grey = Phong(<0.45, 0.45, 0.47>, 0.3, <0.08, 0.08, 0.08>, 20)
#declare MouseGrey = Phong(1.6*<0.45, 0.45, 0.47>, 1.6*0.3, 1.6*<0.08, 0.08, 0.08>, 20)
#declare Dark = Phong(<0.08, 0.08, 0.08>, 0.3, <0, 0, 0>, 30)
#declare Screen = Model(<0.04, 0.06, 0.05>, 0.6, <0, 0, 0>, 60, 0.08, <0, 0, 0>, 1)
#declare GlowText = Colour(<0.35, 1, 0.45>)
#declare Led = Colour(<0.2, 1, 0.2>)
#declare Wall = Phong(<0.7, 0.72, 0.66>, 0, <0.12, 0.12, 0.12>, 1)
// tiff(phong({0}, {0.3}, 30), phong({1}, {0.3}, 30), wood.tif)
#declare WoodFinish = finish { diffuse 1 ambient 0 phong 0.3 phong_size 30 }
#declare Wood00 = TexelAt00("tex/wood.tif");
#declare Wood = material { texture { pigment { rgb <Wood00.red, Wood00.green, Wood00.blue> } finish { WoodFinish } } }
#declare BackTop = material { texture {
  PlaneMapPigment("tex/wood.tif", <0, 0, 0>, <12, 0, 0>, <0, 4, 0>, 0, 0) finish { WoodFinish } } }
#declare FrontTop = material { texture {
  PlaneMapPigment("tex/wood.tif", <0, 0, 0>, <12, 0, 0>, <0, 4, 0>, 0.5, 0.35) finish { WoodFinish } } }
#if (Flat)
  #declare Beige = FlatColour(<1, 1, 0.6>)
  #declare Keycap = FlatColour(<1, 1, 1>)
  #declare Grey = FlatColour(<0.4, 0.4, 0.4>)
  #declare MouseGrey = FlatColour(<0.6, 0.6, 1>)  // ray: Grey * 1.6
  #declare Dark = FlatColour(<0, 0, 0.4>)
  #declare Screen = FlatColour(<0, 0.4, 0.4>)
  #declare GlowText = FlatColour(<0, 1, 0>)  // ray: Glow
  #declare Led = FlatColour(<1, 0, 0>)
  #declare Wall = FlatColour(<0.8, 0.6, 0.8>)
  #declare Wood = FlatColour(<0.6, 0.4, 0>)
  #declare BackTop = Wood;
  #declare FrontTop = Wood;
#end

// ---- the desk (0.6 thick, from y = -5 back into the wall) and the wall
intersection {
  union {
    intersection { Half(BackTop, <0, 0, 0>, z) Half(Wood, <0, 1, 0>, -y) }
    intersection { Half(FrontTop, <0, 0, 0>, z) Half(Wood, <0, 1, 0>, y) }
  }
  Half(Wood, <0, -5, 0>, -y)
  Half(Wood, <0, 0, -0.6>, -z)
}
Half(Wall, <0, 5.5, 0>, -y)

// ---- the system case with two floppy drives, a power light and a name plate
difference {
  Box(Beige, <-2.6, -0.6, 0.05>, <2.6, 3.4, 1.05>)
  #declare K = 0;
  #while (K < 2)
    #declare Zk = 0.3 + K*0.4;
    Box(Dark, <0.4, -0.45, Zk>, <2.2, 4, Zk + 0.24>)
    Box(Grey, <0.6, -0.7, Zk + 0.1>, <2.0, 4, Zk + 0.14>)
    #declare K = K + 1;
  #end
}
sphere { <-2.2, -0.6, 0.3>, 0.06 material { Led } }
Text(Dark, "PRAY 486", <-2.2, -0.59, 0.55>, <0.3, 0, 0>, <0, 0, 0.36>, 0.04, "tex/font.tif", 0.6)

// ---- the monitor: a box with a bevelled back, minus the sunk screen, on a foot
difference {
  intersection {
    Half(Beige, <-2.2, 0, 0>, -x) Half(Beige, <2.2, 0, 0>, x)
    Half(Beige, <0, -0.3, 0>, -y) Half(Beige, <0, 3, 0>, y)
    Half(Beige, <0, 0, 1.5>, -z) Half(Beige, <0, 0, 4.7>, z)
    Half(Beige, <2.2, 1.2, 0>, <1, 0.8, 0>) Half(Beige, <-2.2, 1.2, 0>, <-1, 0.8, 0>)
    Half(Beige, <0, 1.2, 4.7>, <0, 0.8, 1>)
  }
  Box(Screen, <-1.8, -0.5, 1.8>, <1.8, -0.15, 4.4>)
  bounded_by { box { <-2.21, -0.31, 1.49>, <2.21, 3.01, 4.71> } }
}
cylinder { <0, 1.2, 1.05>, <0, 1.2, 1.5>, 1.1 material { Grey } }
Text(GlowText, "C:\\>cd pray", <-1.55, -0.145, 3.85>, <0.2, 0, 0>, <0, 0, 0.28>, 0.02, "", 1)
Text(GlowText, "C:\\PRAY>pray pc", <-1.55, -0.145, 3.85 - 0.55>, <0.2, 0, 0>, <0, 0, 0.28>, 0.02, "", 1)
Text(GlowText, "2046 primitives", <-1.55, -0.145, 3.85 - 2*0.55>, <0.2, 0, 0>, <0, 0, 0.28>, 0.02, "", 1)
Text(GlowText, "C:\\PRAY>_", <-1.55, -0.145, 3.85 - 3*0.55>, <0.2, 0, 0>, <0, 0, 0.28>, 0.02, "", 1)

// ---- the keyboard: a slanted base and 63 keys
intersection {
  Half(Beige, <-2.7, 0, 0>, -x) Half(Beige, <2.7, 0, 0>, x)
  Half(Beige, <0, -4.4, 0>, -y) Half(Beige, <0, -2.3, 0>, y)
  Half(Beige, <0, 0, 0>, -z) Half(Beige, <0, -4.4, 0.2>, <0, -0.08, 1>)
  bounded_by { box { <-2.71, -4.41, -0.01>, <2.71, -2.29, 0.4> } }
}
union {
  #declare P = 0.32;
  #declare R = 0;
  #while (R < 5)
    #declare Y0 = -2.55 - R*P;
    #declare N = 14 - (R = 4)*7;
    #declare X0 = -2.5 + mod(R, 2)*0.1;
    #declare C = 0;
    #while (C < N)
      #declare Wk = P - 0.04;
      #if (R = 4 & C = 2) #declare Wk = 6*P - 0.04; #end
      #declare Xa = X0 + C*P + (R = 4 & C > 2)*5*P;
      #declare Tk = 0.32 + 0.08*(Y0 + 4.4);
      box { <Xa, Y0 - P + 0.04, 0.1>, <Xa + Wk, Y0, Tk> }
      #declare C = C + 1;
    #end
    #declare R = R + 1;
  #end
  material { Keycap }
}

// ---- the mouse and its cable
difference {
  intersection {
    sphere { <3.6, -3.2, -0.5>, 0.85 material { MouseGrey } }
    cylinder { <3.6, -4.2, 0>, <3.6, -2.2, 0>, 0.42 material { Grey } }
    Half(Grey, <0, 0, 0>, -z)
  }
  Box(Dark, <3.58, -2.9, -1>, <3.62, -2, 1>)
}
#declare A = <3.6, -2.45, 0.06>;
#declare K = 0;
#while (K < 5)
  #declare B = A + <-0.25*K, 0.55, 0>;
  cylinder { A, B, 0.04 material { Dark } }
  sphere { B, 0.04 material { Dark } }
  #declare A = B;
  #declare K = K + 1;
#end

DirLight(<0.55, 0.55, 0.55>, <0.6, 1, -1.2>)
PointLight(<0.5, 0.5, 0.5>, <-5, -7, 9>)
