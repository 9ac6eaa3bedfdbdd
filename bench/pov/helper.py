#!/usr/bin/env python3
"""bench/pov/helper.py - the helpers of bench/pov.sh (see docs/povray.md).

  helper.py flat SCENE.ray SCENE.pov  print a copy of SCENE.ray with flat colours
  helper.py compare PRAY.png POV.png [DIFF.png]
                                      print the share of pixels whose colours differ
  helper.py time RUNS LOG COMMAND...  run COMMAND RUNS times (output to LOG.out); write to LOG
                                      "cpu wall" in seconds of the run with the least CPU time
                                      (user + system, from the kernel's accounting, so finer
                                      than /usr/bin/time's hundredths)

The flat colours are written once, in SCENE.pov, as lines
    #declare NAME = FlatColour(<r, g, b>)
NAME is a variable of SCENE.ray. If the .ray defines NAME as a lighting model
(`NAME = phong(...)`), the definition becomes `NAME = color({r, g, b})`; if it defines NAME
as a primitive (`NAME = plane(White, ...)`), the primitive's model argument becomes that
colour. Every model of the .ray must get a colour and every colour must be used, so the two
files cannot drift apart. A line may end in a comment `// ray: TEXT`: a name TEXT is the .ray's
variable (for a name POV-Ray cannot take, such as Flat); any other TEXT is a model written
inline in the .ray, such as `phong({0.9, 0.2, 0.2}, {0.3}, 20)`, and each place where it
occurs becomes the colour. The background becomes black, as on POV-Ray's side. The lights
stay: color() surfaces ignore them.
"""
import re
import sys

MAKERS = ("phong", "mirror", "transparent", "color", "tiff", "tiffbump", "move")
TOLERANCE = 24  # per channel, out of 255: the colours are 51 apart, quantisation is 1 or 2


def flat_colours(pov):
    """The colours of the named models, and those of the inline ones (text: colour)."""
    cols = {}
    inline = {}
    for line in open(pov):
        m = re.match(r"\s*#declare\s+(\w+)\s*=\s*FlatColour\(<([^>]*)>\)\s*(?://\s*ray:\s*(.*\S))?", line)
        if m:
            col = ", ".join(x.strip() for x in m.group(2).split(","))
            text = m.group(3)
            if text is None:
                cols[m.group(1)] = col
            elif re.match(r"\w+$", text):
                cols[text] = col
            else:
                inline[text] = col
    if not cols and not inline:
        sys.exit("helper.py: no FlatColour lines in %s" % pov)
    return cols, inline


def first_argument_end(text, start):
    """Index of the comma ending the first argument of a call whose '(' is at start - 1."""
    depth = 0
    for i in range(start, len(text)):
        c = text[i]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            return i
    return -1


def flat_ray(ray, pov):
    cols, inline = flat_colours(pov)
    used = set()
    out = []
    for n, line in enumerate(open(ray), 1):
        for text, col in inline.items():
            if text in line:
                line = line.replace(text, "color({%s})" % col)
                used.add(text)
        m = re.match(r"(\s*)(\w+)(\s*=\s*)(\w+)\s*\(", line)
        if re.match(r"\s*background\b", line):
            line = "background {0}\n"
        elif m and m.group(2) in cols:
            name, col = m.group(2), cols[m.group(2)]
            if m.group(4) in MAKERS:
                line = "%s%s = color({%s})\n" % (m.group(1), name, col)
            else:
                end = first_argument_end(line, m.end())
                if end < 0:
                    sys.exit("%s:%d: cannot find the model argument of %s" % (ray, n, name))
                line = line[:m.end()] + "color({%s})" % col + line[end:]
            used.add(name)
        elif m and m.group(4) in MAKERS:
            sys.exit("%s:%d: the model %s has no FlatColour in %s" % (ray, n, m.group(2), pov))
        out.append(line)
    missing = sorted((set(cols) | set(inline)) - used)
    if missing:
        sys.exit("helper.py: %s defines no %s" % (ray, ", ".join(missing)))
    sys.stdout.write("".join(out))


def compare(a, b, diff=None):
    from PIL import Image
    ia = Image.open(a).convert("RGB")
    ib = Image.open(b).convert("RGB")
    if ia.size != ib.size:
        sys.exit("helper.py: %s and %s differ in size" % (a, b))
    pa, pb = ia.load(), ib.load()
    w, h = ia.size
    bad = 0
    mark = Image.new("RGB", ia.size) if diff else None
    for y in range(h):
        for x in range(w):
            p, q = pa[x, y], pb[x, y]
            if max(abs(p[0] - q[0]), abs(p[1] - q[1]), abs(p[2] - q[2])) > TOLERANCE:
                bad += 1
                if mark:
                    mark.putpixel((x, y), (255, 255, 255))
            elif mark:
                mark.putpixel((x, y), tuple(c // 4 for c in p))
    if mark:
        mark.save(diff)
    print("%d of %d pixels differ (%.3f %%)" % (bad, w * h, 100.0 * bad / (w * h)))


def timed(runs, log, cmd):
    import resource
    import subprocess
    import time

    def cpu_of_children():
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    best = None
    for _ in range(int(runs)):
        before = cpu_of_children()
        start = time.perf_counter()
        with open(log + ".out", "w") as out:
            status = subprocess.call(cmd, stdout=out, stderr=subprocess.STDOUT)
        wall = time.perf_counter() - start
        cpu = cpu_of_children() - before
        if status != 0:
            sys.stderr.write(open(log + ".out").read()[-3000:])
            sys.exit("helper.py: failed (status %d): %s" % (status, " ".join(cmd)))
        if best is None or cpu < best[0]:
            best = (cpu, wall)
    with open(log, "w") as f:
        f.write("%.4f %.4f\n" % best)


def main(argv):
    if len(argv) == 4 and argv[1] == "flat":
        flat_ray(argv[2], argv[3])
    elif len(argv) >= 5 and argv[1] == "time":
        timed(argv[2], argv[3], argv[4:])
    elif len(argv) in (4, 5) and argv[1] == "compare":
        compare(*argv[2:])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
