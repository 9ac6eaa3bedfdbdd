#!/usr/bin/env python3
"""bench/suite/gen.py - write the scenes of the benchmark suite (bench/suite/run.sh).

  gen.py OUTDIR

Each scene is written twice into OUTDIR: NAME.ray, a PRAY program, and NAME.pov, its POV-Ray 3.7
twin with the same camera, geometry and lights (the shading is only close: see docs/povray.md).
The .pov files include bench/pov/pray.inc, which the caller copies next to them. OUTDIR/scenes
lists the names in the suite's order, each with its number of primitives.

Both files of a scene are written statement by statement from one description, so they cannot
drift apart. Many objects are made by loops in both languages, with the same pseudo-random
numbers: the Park-Miller generator S = S * 16807 mod (2^31 - 1), whose products are exact in
double precision, so PRAY and POV-Ray compute the same coordinates. Nothing depends on Python's
own random numbers or hashing: the output is the same on every run.

The procedural families (flake-*, rings-*, tree-*: the sphere flake, rings and tree of the
classic procedural benchmark scenes, built here from their published descriptions) are written
object by object, computed in Python, with the same numbers in every file. The flakes and the
rings also get a third file, NAME.nff, a twin in the NFF format for Tachyon (see Triple).
"""
import math
import os
import sys


class Twin:
    """One scene, as a PRAY program and a POV-Ray scene written side by side."""

    def __init__(self, name, what):
        self.name, self.prims, self.ind = name, 0, ""
        self.ray = ["// %s.ray - %s" % (name, what), "// written by bench/suite/gen.py"]
        self.pov = ["// %s.pov - %s" % (name, what), "// written by bench/suite/gen.py",
                    "#version 3.7;", '#include "pray.inc"']
        self.put("All = nothing", None)
        self.put("Lights = none", None)

    def put(self, ray, pov):
        if ray is not None:
            self.ray.append(self.ind + ray)
        if pov is not None:
            self.pov.append(self.ind + pov)

    def let(self, name, ray, pov=None):
        self.put("%s = %s" % (name, ray), "#declare %s = %s;" % (name, ray if pov is None else pov))

    def rand(self, *names):
        """Each name gets the next pseudo-random number, uniform in [0, 1)."""
        for n in names:
            self.put("S = (S*16807) % 2147483647", "#declare S = mod(S*16807, 2147483647);")
            self.let(n, "S/2147483647")

    def if_(self, cond):
        self.put("if %s" % cond, "#if (%s)" % cond)
        self.ind += "  "

    def else_(self):
        self.ind = self.ind[:-2]
        self.put("else", "#else")
        self.ind += "  "

    def endif(self):
        self.ind = self.ind[:-2]
        self.put("endif", "#end")

    def loop(self, var, count, body):
        self.let(var, "0")
        self.put("while %s < %d" % (var, count), "#while (%s < %d)" % (var, count))
        self.ind += "  "
        body()
        self.let(var, "%s + 1" % var)
        self.ind = self.ind[:-2]
        self.put("endwhile", "#end")

    def pick(self, var, index, names):
        """var = names[index % len(names)], by a chain of ifs."""
        self.let("K", "(%s) %% %d" % (index, len(names)), "mod(%s, %d)" % (index, len(names)))

        def chain(k):
            if k == len(names) - 1:
                self.let(var, names[k])
                return
            self.if_("K < %d" % (k + 1))
            self.let(var, names[k])
            self.else_()
            chain(k + 1)
            self.endif()
        chain(0)

    def camera(self, eye, look, half):
        """Square view, half as wide as `half` at the point looked at; +Z up (docs/povray.md)."""
        self.put("Eye = [%s]" % vec(eye), "#declare Eye = <%s>;" % vec(eye))
        self.put("Look = [%s]" % vec(look), "#declare Look = <%s>;" % vec(look))
        self.let("View", "Look - Eye")
        self.let("Xv", "%g*norm(View %% <0, 0, 1>)" % half, "%g*vnormalize(vcross(View, z))" % half)
        self.let("Yv", "%g*norm(View %% Xv)" % half, "%g*vnormalize(vcross(View, Xv))" % half)
        self.put("perspective Xv, Yv, Eye, Look", "Perspective(Xv, Yv, Eye, Look)")

    def background(self, c):
        self.put("background {%s}" % vec(c), "background { rgb <%s> }" % vec(c))

    def material(self, name, c, s, a, e, mirror=0, clear=None, ior=1):
        ray = "phong({%s}, {%g}, {%s}, %g)" % (vec(c), s, vec(a), e)
        if mirror:
            ray += " + mirror({%g})" % mirror
        if clear:
            ray += " + transparent({%s}, %g)" % (vec(clear), ior)
        self.put("%s = %s" % (name, ray), "#declare %s = Model(<%s>, %g, <%s>, %g, %g, <%s>, %g)"
                 % (name, vec(c), s, vec(a), e, mirror, vec(clear or (0, 0, 0)), ior))

    def sun(self, i, d):
        self.put("Lights = Lights | dirlight({%g}, <%s>)" % (i, vec(d)),
                 "DirLight(<%g, %g, %g>, <%s>)" % (i, i, i, vec(d)))

    def lamp(self, i, p):
        self.put("Lights = Lights | pointlight({%g}, [%s])" % (i, vec(p)),
                 "PointLight(<%g, %g, %g>, <%s>)" % (i, i, i, vec(p)))

    def add(self, obj, prims, var="All", op="|"):
        """Add the object (a pair from sphere(), box(), ...) to the scene: PRAY's var grows by
        op, POV-Ray gets it as a top-level object (or inside the block being written)."""
        self.put("%s = %s %s %s" % (var, var, op, obj[0]), obj[1])
        self.prims += prims

    def files(self):
        return (("ray", self.ray), ("pov", self.pov))

    def write(self, out):
        self.put("rendertiff All, Lights", None)
        for ext, lines in self.files():
            with open(os.path.join(out, "%s.%s" % (self.name, ext)), "w") as f:
                f.write("\n".join(lines) + "\n")


def vec(v):
    return ", ".join(x if isinstance(x, str) else "%g" % x for x in v)


# Objects: (PRAY expression, POV-Ray object). Coordinates are strings or numbers.
def sphere(m, c, r):
    return ("sphere(%s, [%s], %s)" % (m, vec(c), r),
            "sphere { <%s>, %s material { %s } }" % (vec(c), r, m))


def box(m, lo, hi, maker=False):
    """Six half-spaces in PRAY (maker: PRAY's box), a box in POV-Ray: lo and hi are the lowest and
    highest corners."""
    if maker:
        return ("box(%s, [%s], [%s])" % (m, vec(lo), vec(hi)),
                "box { <%s>, <%s> material { %s } }" % (vec(lo), vec(hi), m))
    x0, y0, z0 = (str(v) for v in lo)
    x1, y1, z1 = (str(v) for v in hi)
    ray = ("(plane({m}, [{x1}, 0, 0], <1, 0, 0>) & plane({m}, [{x0}, 0, 0], <-1, 0, 0>)"
           " & plane({m}, [0, {y1}, 0], <0, 1, 0>) & plane({m}, [0, {y0}, 0], <0, -1, 0>)"
           " & plane({m}, [0, 0, {z1}], <0, 0, 1>) & plane({m}, [0, 0, {z0}], <0, 0, -1>))")
    return (ray.format(m=m, x0=x0, x1=x1, y0=y0, y1=y1, z0=z0, z1=z1),
            "box { <%s>, <%s> material { %s } }" % (vec(lo), vec(hi), m))


def rod(m, p0, p1, r):
    """A closed cylinder from p0 to p1: PRAY's infinite cylinder cut by two half-spaces."""
    a, b = vec(p0), vec(p1)
    return ("(cylinder({m}, [{a}], [{b}] - [{a}], {r}) & plane({m}, [{b}], [{b}] - [{a}])"
            " & plane({m}, [{a}], [{a}] - [{b}]))".format(m=m, a=a, b=b, r=r),
            "cylinder { <%s>, <%s>, %s material { %s } }" % (a, b, r, m))


def floor(m, z):
    return ("plane(%s, [0, 0, %g], <0, 0, 1>)" % (m, z), "plane { z, %g material { %s } }" % (z, m))


def placed(name, at):
    """A solid defined once (a variable of both files), moved to the point at."""
    return ("%s . [%s]" % (name, vec(at)), "object { %s translate <%s> }" % (name, vec(at)))


COLOURS = [("Red", (0.85, 0.25, 0.2)), ("Gold", (0.95, 0.75, 0.2)),
           ("Green", (0.25, 0.7, 0.35)), ("Blue", (0.3, 0.45, 0.9))]


def palette(t, names=("Red", "Gold", "Green", "Blue")):
    for n, c in COLOURS:
        if n in names:
            t.material(n, c, 0.5, tuple(0.12 * x for x in c), 40)
    t.material("White", (0.8, 0.78, 0.74), 0.3, (0.1, 0.1, 0.1), 20)
    t.material("Grey", (0.45, 0.46, 0.5), 0.1, (0.06, 0.06, 0.06), 5)


def around(c, h):
    """A coordinate uniform in [c - h, c + h) from the random number named by c's pair."""
    return "%g + %g*%s" % (-h, 2 * h, c)


def cloud(t, n, r, h, seed, at=(0, 0, 0)):
    """n balls of radius r, uniform in the cube of half side h around the point at."""
    t.let("S", str(seed))

    def body():
        t.rand("X", "Y", "Z")
        t.pick("M", "N", ["Red", "Gold", "Green", "Blue"])
        t.add(sphere("M", ["%g + %g*X" % (at[0] - h, 2 * h), "%g + %g*Y" % (at[1] - h, 2 * h),
                           "%g + %g*Z" % (at[2] - h, 2 * h)], "%g" % r), 0)
    t.loop("N", n, body)
    t.prims += n


def cloud_scene(name, what, n, r, seed=1):
    t = Twin(name, what)
    t.camera((0, -45, 12), (0, 0, 0), 13)
    t.background((0.2, 0.25, 0.35))
    palette(t)
    t.sun(1, (1, 2, -3))
    cloud(t, n, r, 10, seed)
    return t


def uniform(n, r):
    return cloud_scene("uniform-%dk" % (n // 1000),
                       "%d balls spread uniformly through a cube, a sun" % n, n, r)


def mixed():
    t = Twin("mixed-10k", "10000 balls, boxes and rods spread uniformly through a cube, a sun")
    t.camera((0, -45, 12), (0, 0, 0), 13)
    t.background((0.2, 0.25, 0.35))
    palette(t)
    t.sun(1, (1, 2, -3))
    t.let("S", "7")
    n = 10000

    def body():
        t.rand("X", "Y", "Z", "A", "B", "C")
        t.pick("M", "N", ["Red", "Gold", "Green", "Blue"])
        t.let("X", "-10 + 20*X")
        t.let("Y", "-10 + 20*Y")
        t.let("Z", "-10 + 20*Z")
        t.let("J", "N % 3", "mod(N, 3)")
        t.if_("J < 1")
        t.add(sphere("M", ["X", "Y", "Z"], "0.3"), 0)
        t.else_()
        t.if_("J < 2")
        t.add(box("M", ["X", "Y", "Z"], ["X + 0.2 + 0.4*A", "Y + 0.2 + 0.4*B", "Z + 0.2 + 0.4*C"]), 0)
        t.else_()
        t.add(rod("M", ["X", "Y", "Z"], ["X + A - 0.5", "Y + B - 0.5", "Z + 0.5"], "0.1"), 0)
        t.endif()
        t.endif()
    t.loop("N", n, body)
    t.prims += sum((1, 6, 3)[i % 3] for i in range(n))
    return t


def cluster():
    t = Twin("cluster-10k", "10000 small balls in a cube of side 2, in a plain 1000 units wide "
             "with 60 pillars")
    t.camera((0, -7, 4.5), (0, 0, 3), 1.6)
    t.background((0.55, 0.65, 0.8))
    palette(t)
    t.sun(1, (1, 2, -3))
    t.add(floor("Grey", 0), 1)
    t.let("S", "11")

    def pillars():
        t.rand("X", "Y")
        t.add(rod("White", ["-500 + 1000*X", "50 + 450*Y", "-1"], ["-500 + 1000*X", "50 + 450*Y", "40"],
                  "3"), 0)
    t.loop("N", 60, pillars)
    t.prims += 3 * 60
    cloud(t, 10000, 0.03, 1, 13, at=(0, 0, 3))
    return t


def far(n, r, moons):
    what = ("%d balls in a cube of side 20 and a few large balls 1000 units away, %s"
            % (n, "behind them in the view" if moons else "out of view, in every direction"))
    t = cloud_scene("far-%dk" % (n // 1000), what, n, r, seed=3)
    if moons:
        for c, rad in (((-280, 1000, -150), 40), ((270, 1050, -380), 50), ((0, 1100, -10), 30)):
            t.add(sphere("White", c, rad), 1)
    else:
        for c in ((1000, 0, 0), (-1000, 0, 0), (0, 1000, 0), (0, -1000, 0), (0, 0, 1000), (0, 0, -1000)):
            t.add(sphere("White", c, 1), 1)
    return t


def csg_wide(n, rmin, rmax):
    t = Twin("csg-wide-%d" % n, "a slab minus %d cutters: dimples (balls) and holes (cylinders)" % n)
    t.camera((0, -12, 10), (0, 0, -0.5), 6)
    t.background((0.2, 0.25, 0.35))
    palette(t, ("Red", "Blue"))
    t.sun(1, (1, 2, -3))
    t.put(None, "difference {")
    b = box("White", (-5, -5, -1), (5, 5, 0))
    t.put("All = " + b[0], b[1])
    t.prims += 6
    t.let("S", "5")

    def body():
        t.rand("X", "Y", "R")
        t.let("X", "-4.5 + 9*X")
        t.let("Y", "-4.5 + 9*Y")
        t.let("R", "%g + %g*R" % (rmin, rmax - rmin))
        t.let("J", "N % 2", "mod(N, 2)")
        t.if_("J < 1")
        t.add(sphere("Red", ["X", "Y", "0"], "R"), 0, op="-")
        t.else_()
        # POV-Ray's cylinder is longer than the slab is thick: its caps are never seen
        t.add(("cylinder(Blue, [X, Y, 0], <0, 0, 1>, R/2)",
               "cylinder { <X, Y, -3>, <X, Y, 3>, R/2 material { Blue } }"), 0, op="-")
        t.endif()
    t.loop("N", n, body)
    t.put(None, "}")
    t.prims += n
    return t


def keyboard(maker=False):
    """maker: the boxes made by PRAY's box instead of six half-spaces each (boxes-1k-box)."""
    t = Twin("boxes-1k" + ("-box" if maker else ""), "a keyboard: 1000 keys on a board, each key %s"
             % ("a box" if maker else "a box of six half-spaces"))
    t.camera((0, -35, 25), (0, 0, 0), 23)
    t.background((0.2, 0.25, 0.35))
    palette(t, ("Red",))
    t.sun(1, (1, 2, -3))
    per = 1 if maker else 6
    t.add(box("Grey", (-21, -13.5, -1), (21, 13.5, 0), maker), per)
    for name, m in (("KeyA", "White"), ("KeyB", "Red")):
        b = box(m, (-0.4, -0.4, 0), (0.4, 0.4, 0.4), maker)
        t.put("%s = %s" % (name, b[0]), "#declare %s = %s" % (name, b[1]))

    def column():
        def key():
            t.pick("B", "I + J*3", ["KeyA", "KeyA", "KeyB"])
            t.add(placed("B", ["-19.5 + I", "-12 + J", "0"]), 0)
        t.loop("J", 25, key)
    t.loop("I", 40, column)
    t.prims += per * 1000
    return t


def shelves(maker=False):
    """maker: the boxes made by PRAY's box instead of six half-spaces each (boxes-10k-box)."""
    t = Twin("boxes-10k" + ("-box" if maker else ""), "bookshelves: 20 shelves of 500 books, each book "
             "and board %s" % ("a box" if maker else "a box of six half-spaces"))
    t.camera((-12, -26, 13), (28, 0, 10), 12)
    t.background((0.2, 0.25, 0.35))
    palette(t)
    t.sun(1, (1, 2, -3))
    t.add(floor("Grey", 0), 1)
    t.let("S", "17")

    def shelf():
        t.let("Z", "1.2*L")
        t.add(box("White", ["-0.2", "0", "Z - 0.1"], ["62", "0.8", "Z"], maker), 0)
        t.let("X", "0")

        def book():
            t.rand("A", "B", "C")
            t.pick("M", "N + L", ["Red", "Gold", "Green", "Blue"])
            t.let("W", "0.06 + 0.12*A")
            t.add(box("M", ["X", "0.05", "Z"], ["X + W", "0.5 + 0.25*C", "Z + 0.6 + 0.4*B"], maker), 0)
            t.let("X", "X + W + 0.003")
        t.loop("N", 500, book)
    t.loop("L", 20, shelf)
    t.prims += (1 if maker else 6) * (20 + 10000)
    return t


def glass():
    t = Twin("glass", "glass and mirror balls among 100 small opaque balls on a floor, a sun and "
             "a lamp")
    t.camera((0, -12, 6), (0, 0, 0.5), 6)
    t.background((0.55, 0.65, 0.8))
    palette(t)
    t.material("Glass", (0, 0, 0), 0.7, (0, 0, 0), 80, mirror=0.1, clear=(0.9, 0.9, 0.9), ior=1.5)
    t.material("Mirror", (0.1, 0.1, 0.1), 0.5, (0, 0, 0), 50, mirror=0.8)
    t.sun(0.7, (1, 2, -3))
    t.lamp(0.5, (-3, -3, 6))
    t.add(floor("White", 0), 1)
    t.let("S", "19")

    def column():
        def cell():
            # one ball per cell of 1.2 x 1.2: glass, mirror or opaque; balls never overlap
            t.rand("X", "Y")
            t.let("X", "-5.4 + 1.2*I + 0.3*(X - 0.5)")
            t.let("Y", "-5.4 + 1.2*J + 0.3*(Y - 0.5)")
            t.let("J2", "(I + 3*J) % 7", "mod(I + 3*J, 7)")
            t.if_("J2 < 1")
            t.add(sphere("Glass", ["X", "Y", "0.42"], "0.42"), 0)
            t.else_()
            t.if_("J2 < 2")
            t.add(sphere("Mirror", ["X", "Y", "0.42"], "0.42"), 0)
            t.else_()
            t.pick("M", "I + J", ["Red", "Gold", "Green", "Blue"])
            t.add(sphere("M", ["X", "Y", "0.3"], "0.3"), 0)
            t.endif()
            t.endif()
        t.loop("J", 10, cell)
    t.loop("I", 10, column)
    t.prims += 100
    return t


def lights_scene(name, lamps):
    what = ("2000 balls and boxes over a floor, %s" %
            ("lit by 6 point lights among them" if lamps else "lit by the sun"))
    t = Twin(name, what)
    t.camera((0, -22, 12), (0, 0, 1.5), 10)
    t.background((0.2, 0.25, 0.35))
    palette(t)
    if lamps:
        for i in range(6):
            t.lamp(0.5, (-7.5 + 3 * i, (-3, 3)[i % 2], 2.5))
    else:
        t.sun(1, (1, 2, -3))
    t.add(floor("Grey", 0), 1)
    t.let("S", "23")
    n = 2000

    def body():
        t.rand("X", "Y", "Z", "A")
        t.pick("M", "N", ["Red", "Gold", "Green", "Blue"])
        t.let("X", "-10 + 20*X")
        t.let("Y", "-10 + 20*Y")
        t.let("Z", "6*Z")
        t.let("J", "N % 2", "mod(N, 2)")
        t.if_("J < 1")
        t.add(sphere("M", ["X", "Y", "Z + 0.3"], "0.3"), 0)
        t.else_()
        t.add(box("M", ["X", "Y", "Z"], ["X + 0.3 + 0.3*A", "Y + 0.4", "Z + 0.5"]), 0)
        t.endif()
    t.loop("N", n, body)
    t.prims += n // 2 * 7
    return t


# The procedural families: the sphere flake, the rings and the tree of the classic procedural
# benchmark scenes (Eric Haines' "Standard Procedural Databases"), built from their published
# descriptions. Their objects are computed here and written out one by one, in PRAY, in POV-Ray
# and (where NFF can say the same) in NFF for Tachyon.

def num(x):
    return "%.7g" % x


def unit(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / n, v[1] / n, v[2] / n)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def comb(*terms):
    """The sum of the terms (scale, vector)."""
    return tuple(sum(k * v[i] for k, v in terms) for i in range(3))


class Triple(Twin):
    """A scene of the procedural families: the PRAY program and the POV-Ray twin, and with
    nff=True an NFF twin for Tachyon. NFF has no loops: every object is written out, and the
    PRAY and POV-Ray files do the same, with the same numbers (7 significant digits).

    Tachyon reads NFF with two differences from pray's camera, both measured: its field of view
    is fixed (the view is half as wide as the distance to the point looked at, whatever NFF's
    angle says), and its picture is the mirror image of the one a right-handed camera takes. So
    every camera here has that width (view()), and the NFF file has every x coordinate negated
    (geometry, lights and camera), which mirrors the picture back. Tachyon then samples each
    pixel half a pixel from the centre that pray and POV-Ray sample: the same picture, moved by
    half a pixel."""

    def __init__(self, name, what, nff):
        Twin.__init__(self, name, what)
        self.nff = [] if nff else None
        self.fills, self.fill = {}, None

    def files(self):
        return Twin.files(self) + ((("nff", self.nff),) if self.nff is not None else ())

    def nput(self, *lines):
        if self.nff is not None:
            self.nff.extend(lines)

    def view(self, eye, look):
        d = math.sqrt(sum((a - b) ** 2 for a, b in zip(eye, look)))
        self.camera(eye, look, 0.5 * d)
        self.nput("v", "from %s %s %s" % (num(-eye[0]), num(eye[1]), num(eye[2])),
                  "at %s %s %s" % (num(-look[0]), num(look[1]), num(look[2])), "up 0 0 1",
                  "angle %s" % num(2 * math.degrees(math.atan(0.5))), "hither 0.001",
                  "resolution 512 512")

    def background(self, c):
        Twin.background(self, c)
        self.nput("b %s" % " ".join(num(x) for x in c))

    def lamp(self, i, p):
        Twin.lamp(self, i, p)
        self.nput("l %s %s %s %s %s %s" % (num(-p[0]), num(p[1]), num(p[2]), num(i), num(i), num(i)))

    def material(self, name, c, s, a, e, mirror=0, clear=None, ior=1):
        Twin.material(self, name, c, s, a, e, mirror, clear, ior)
        # NFF's fill: colour, diffuse and specular weights (the specular weight is also the
        # mirror's), shininess, transmittance, index of refraction
        self.fills[name] = "f %s 1 %s %s 0 1" % (" ".join(num(x) for x in c), num(mirror), num(e))

    def use(self, m):
        if self.fill != m:
            self.nput(self.fills[m])
            self.fill = m

    def ball(self, m, c, r):
        self.add(sphere(m, [num(x) for x in c], num(r)), 1)
        self.use(m)
        self.nput("s %s %s %s %s" % (num(-c[0]), num(c[1]), num(c[2]), num(r)))

    def bar(self, m, a, b, r):
        """A rod: PRAY's rod, POV-Ray's cylinder (both closed) and NFF's cylinder (open: every
        bar here ends inside a ball wider than it, so the ends are never seen)."""
        pa, pb = vec([num(x) for x in a]), vec([num(x) for x in b])
        self.add(("rod(%s, [%s], [%s], %s)" % (m, pa, pb, num(r)),
                  "cylinder { <%s>, <%s>, %s material { %s } }" % (pa, pb, num(r), m)), 1)
        self.use(m)
        self.nput("c", "%s %s %s %s" % (num(-a[0]), num(a[1]), num(a[2]), num(r)),
                  "%s %s %s %s" % (num(-b[0]), num(b[1]), num(b[2]), num(r)))

    def cone(self, m, a, ra, b, rb):
        """A cone, closed in PRAY and POV-Ray; no NFF (Tachyon draws NFF's cone as a cylinder)."""
        assert self.nff is None
        pa, pb = vec([num(x) for x in a]), vec([num(x) for x in b])
        self.add(("cone(%s, [%s], %s, [%s], %s)" % (m, pa, num(ra), pb, num(rb)),
                  "cone { <%s>, %s, <%s>, %s material { %s } }" % (pa, num(ra), pb, num(rb), m)), 1)

    def ground(self, m, half, z):
        """A square floor of side 2*half, its top at height z: a slab one unit thick in PRAY and
        POV-Ray (its sides and bottom are out of every view and every shadow here), its top
        as an NFF polygon."""
        lo, hi = (-half, -half, z - 1), (half, half, z)
        self.add(box(m, [num(x) for x in lo], [num(x) for x in hi], maker=True), 1)
        self.use(m)
        self.nput("p 4", *["%s %s %s" % (num(-x), num(y), num(z))
                           for x, y in ((-half, -half), (half, -half), (half, half), (-half, half))])


def flake(level):
    """The sphere flake: a ball with 9 balls of a third of its radius on it (6 around its
    equator, 3 above), each of them with 9 more in the same way, to the given level; on a floor
    24 units wide, under three lamps. Its balls are mirrors."""
    n = (9 ** (level + 1) - 1) // 8
    t = Triple("flake-%d" % level, "a sphere flake of %d levels, %d mirror balls, on a floor 24 "
               "units wide, three lamps" % (level, n), nff=True)
    t.view((2.1, -1.3, 1.7), (0, 0, 0))
    t.background((0.55, 0.65, 0.8))
    t.material("Chrome", (0.55, 0.5, 0.45), 0.5, (0.05, 0.05, 0.05), 40, mirror=0.5)
    t.material("Sand", (0.75, 0.7, 0.55), 0.1, (0.08, 0.08, 0.06), 5)
    for p in ((4, -3, 5), (-3, -4, 3), (1, 4, 6)):
        t.lamp(0.45, p)
    t.ground("Sand", 12, -0.5)
    dirs = [(0.0, math.radians(60 * i)) for i in range(6)] + \
           [(math.radians(50), math.radians(30 + 120 * i)) for i in range(3)]

    def grow(c, r, axis, u, k):
        t.ball("Chrome", c, r)
        if k == level:
            return
        w = cross(axis, u)
        for elev, az in dirs:
            d = comb((math.cos(elev) * math.cos(az), u), (math.cos(elev) * math.sin(az), w),
                     (math.sin(elev), axis))
            cos_ad = sum(axis[i] * d[i] for i in range(3))
            # the child's own axis points away from its parent; its azimuths start from the
            # direction of the parent's axis, seen from the child
            grow(comb((1, c), (4 * r / 3, d)), r / 3, d, unit(comb((1, axis), (-cos_ad, d))), k + 1)
    grow((0, 0, 0), 0.5, (0, 0, 1), (1, 0, 0), 0)
    assert t.prims == n + 1
    return t


def rings(layers):
    """The rings: a pyramid of rings standing upright, (layers - k)^2 of them in layer k, each
    made of 30 rods joined by 30 balls, facing along x and y by turns; on a floor, three lamps."""
    count = sum(k * k for k in range(1, layers + 1))
    t = Triple("rings-%d" % layers, "a pyramid of %d layers of rings, %d rings of 30 rods joined "
               "by 30 balls, on a floor, three lamps" % (layers, count), nff=True)
    w = 1.5 * (layers - 1) + 2.2
    look = (0, 0, round(0.4 * w, 3))
    e = unit((0.55, -1, 0.6))
    t.view(tuple(round(look[i] + 1.8 * w * e[i], 3) for i in range(3)), look)
    t.background((0.2, 0.25, 0.35))
    palette(t)
    for p in ((1.2, -1.6, 2), (-1.5, -0.8, 1.5), (0.5, 1.5, 2.5)):
        t.lamp(0.45, tuple(round(w * x, 3) for x in p))
    t.ground("Grey", 2 * w, 0)
    rad, rod_r, ball_r, segs = 1.0, 0.07, 0.1, 30
    colours = ["Red", "Gold", "Green", "Blue"]
    for k in range(layers):
        m = layers - k
        for i in range(m):
            for j in range(m):
                c = (1.5 * i + 0.75 * k - 0.75 * (layers - 1), 1.5 * j + 0.75 * k - 0.75 * (layers - 1),
                     rad + ball_r + 1.5 * k)
                e1 = (1, 0, 0) if (i + j + k) % 2 == 0 else (0, 1, 0)
                mat = colours[(i + 2 * j + 3 * k) % 4]
                pts = [comb((1, c), (rad * math.cos(2 * math.pi * s / segs), e1),
                            (rad * math.sin(2 * math.pi * s / segs), (0, 0, 1))) for s in range(segs)]
                for s in range(segs):
                    t.ball(mat, pts[s], ball_r)
                    t.bar(mat, pts[s], pts[(s + 1) % segs], rod_r)
    assert t.prims == 60 * count + 1
    return t


def tree(levels):
    """The tree: a trunk (a cone with a ball on its top) that forks into two branches, each of
    them forking in the same way, to the given number of levels; each branch shorter and thinner,
    the plane of each fork turned a quarter of a turn from the one before. On a floor, two lamps."""
    n = 2 ** levels - 1
    t = Triple("tree-%d" % levels, "a tree of %d levels: %d branches, each a cone with a ball on "
               "its end, on a floor, two lamps" % (levels, n), nff=False)
    parts = []
    alpha = math.radians(32)

    def branch(base, d, e, length, r0, k):
        r1 = 0.65 * r0
        top = comb((1, base), (length, d))
        parts.append((base, r0, top, r1))
        if k == levels:
            return
        wv = cross(d, e)
        for sgn in (1, -1):
            branch(top, unit(comb((math.cos(alpha), d), (sgn * math.sin(alpha), e))), wv,
                   0.78 * length, r1, k + 1)
    branch((0, 0, -0.1), (0, 0, 1), (1, 0, 0), 2.1, 0.18, 1)
    lo = [min(min(p[0][i], p[2][i]) for p in parts) for i in range(3)]
    hi = [max(max(p[0][i], p[2][i]) for p in parts) for i in range(3)]
    size = max(h - l for h, l in zip(hi, lo))
    look = tuple(round((l + h) / 2, 3) for l, h in zip(lo, hi))
    e = unit((0.6, -1, 0.3))
    t.view(tuple(round(look[i] + 1.5 * size * e[i], 3) for i in range(3)), look)
    t.background((0.55, 0.65, 0.8))
    t.material("Bark", (0.5, 0.35, 0.2), 0.2, (0.06, 0.04, 0.03), 10)
    t.material("Leaf", (0.3, 0.65, 0.25), 0.4, (0.04, 0.08, 0.03), 30)
    t.material("Grass", (0.45, 0.55, 0.3), 0.1, (0.06, 0.07, 0.04), 5)
    t.lamp(0.6, tuple(round(x * size, 3) for x in (1, -1.2, 2)))
    t.lamp(0.4, tuple(round(x * size, 3) for x in (-1.5, -0.5, 1.5)))
    t.ground("Grass", round(2 * size, 3), 0)
    for base, r0, top, r1 in parts:
        t.cone("Bark", base, r0, top, r1)
        t.ball("Leaf", top, r1)
    assert t.prims == 2 * n + 1
    return t


def scenes():
    yield uniform(1000, 0.5)
    yield uniform(10000, 0.25)
    yield uniform(100000, 0.12)
    yield mixed()
    yield cluster()
    yield far(1000, 0.5, True)
    yield far(10000, 0.25, False)
    yield csg_wide(100, 0.3, 0.8)
    yield csg_wide(1000, 0.12, 0.3)
    yield keyboard()
    yield keyboard(True)
    yield shelves()
    yield shelves(True)
    yield glass()
    yield lights_scene("lights-2k", True)
    yield lights_scene("sun-2k", False)
    for level in (3, 4, 5):
        yield flake(level)
    for layers in (4, 7, 12):
        yield rings(layers)
    for levels in (9, 12, 15):
        yield tree(levels)


def main():
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):  # (--help is no directory)
        sys.exit("usage: gen.py OUTDIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    names = []
    for t in scenes():
        t.write(out)
        names.append("%s %d" % (t.name, t.prims))
    with open(os.path.join(out, "scenes"), "w") as f:
        f.write("\n".join(names) + "\n")


if __name__ == "__main__":
    main()
