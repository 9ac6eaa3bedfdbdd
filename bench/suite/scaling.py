#!/usr/bin/env python3
"""bench/suite/scaling.py - time and peak memory against the number of primitives, pray and
POV-Ray 3.7 side by side (make scaling; docs/benchmarks.md, "Scaling against POV-Ray").

  scaling.py [--size N] [--runs K] [--max N] [--chart PNG]
  scaling.py --plot PNG     redraw the chart from the last run's figures (build/scaling.json)

The scenes are the suite's uniform family (bench/suite/gen.py): N balls spread through a cube of
side 20 under a sun, their radius shrinking as N^(-1/3) so that they fill the same share of the
cube, for N from 10^3 to 10^6 (--max: the largest N). Each is rendered by ./pray and by POV-Ray,
one thread, no anti-aliasing, N x N pixels (--size, default 512). For each run the whole
process's CPU time (user + system, best of --runs, default 1) and its peak resident memory are
read by GNU time (/usr/bin/time, Debian package time). The largest scene is rendered once more by pray under a
1 GiB limit of address space, and must give the same image.

Prints a Markdown table and the fitted exponents of time and memory against N, and keeps the
figures in build/scaling.json; with --chart, draws both against N (needs matplotlib).
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
import gen  # noqa: E402

SAVED = os.path.join(ROOT, "build", "scaling.json")
COUNTS = [1000, 3000, 10000, 30000, 100000, 300000, 1000000]
CAP = 1 << 30  # the address-space limit of the last run (bytes)


def label(n):
    return "%dk" % (n // 1000)


def run(cmd, cwd, runs, limit=None):
    """Best CPU time (s) and the peak resident memory of that run (MiB) of cmd; None on failure.
    Measured by GNU time: a child of Python would count Python's own memory from before exec."""
    best = None
    if limit:
        cmd = ["sh", "-c", 'ulimit -v %d && exec "$0" "$@"' % (limit >> 10)] + cmd
    log = os.path.join(cwd, "time.log")
    for _ in range(runs):
        with open(os.devnull, "w") as null:
            status = subprocess.call(["/usr/bin/time", "-o", log, "-f", "%U %S %M"] + cmd, cwd=cwd, stdout=null,
                                     stderr=null)
        if status != 0:
            sys.stderr.write("scaling: %s failed\n" % " ".join(cmd))
            return None
        u, s, kib = open(log).read().split()[-3:]
        cpu, peak = float(u) + float(s), float(kib) / 1024.0
        if best is None or cpu < best[0]:
            best = (cpu, peak)
    return best


def pray_cmd(pray, size, name, image):
    # (a loop that makes 10^6 balls runs more statements than maxsteps allows by default)
    return [pray, "--quiet", "--threads", "1", "-D", "antialias=1", "-D", "maxsteps=100000000",
            "-s", "%dx%d" % (size, size), "-o", image, name + ".ray"]


def exponent(ns, ys):
    """The slope of log y against log n (least squares)."""
    pts = [(math.log(n), math.log(y)) for n, y in zip(ns, ys) if y and y > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def chart(rows, size, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ns = [r["n"] for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, name, mark in (("pray", "pray", "-o"), ("pov", "POV-Ray 3.7", "-^")):
        got = [r for r in rows if r[key]]
        xs = [r["n"] for r in got]
        t = [r[key][0] for r in got]
        m = [r[key][1] for r in got]
        ax[0].plot(xs, t, mark, ms=3, label="%s (exponent %.2f)" % (name, exponent(xs, t)))
        ax[1].plot(xs, m, mark, ms=3, label="%s (exponent %.2f)" % (name, exponent(xs, m)))
    ax[0].set_ylabel("CPU seconds, whole process (%d x %d, one thread)" % (size, size))
    ax[0].set_title("time")
    ax[1].set_ylabel("peak resident memory (MiB)")
    ax[1].set_title("memory")
    for a in ax:
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xticks(ns)
        a.set_xticklabels([label(n) for n in ns])
        a.minorticks_off()
        a.set_xlabel("N balls in a cube (the suite's uniform family)")
        a.legend(fontsize=8)
    fig.suptitle("Scaling with the number of primitives: pray against POV-Ray")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main(argv):
    size, runs, most, png = 512, 1, COUNTS[-1], None
    args = argv[1:]
    if len(args) == 2 and args[0] == "--plot":
        with open(SAVED) as f:
            saved = json.load(f)
        chart(saved["rows"], saved["size"], args[1])
        return 0
    while args:
        if args[0] in ("--size", "--runs", "--max", "--chart") and len(args) > 1:
            if args[0] == "--chart":
                png = os.path.abspath(args[1])
            else:
                v = int(args[1])
                size, runs, most = (v, runs, most) if args[0] == "--size" else \
                    (size, v, most) if args[0] == "--runs" else (size, runs, v)
            args = args[2:]
        else:
            sys.exit(__doc__)
    pray = os.path.join(ROOT, "pray")
    pov = shutil.which("povray")
    if not pov:
        sys.stderr.write("scaling: povray is not installed; pray only\n")
    out = tempfile.mkdtemp()
    try:
        shutil.copy(os.path.join(ROOT, "bench", "pov", "pray.inc"), out)
        rows = []
        print("pray against POV-Ray: %d x %d, one thread, no anti-aliasing; CPU seconds (user + system, "
              "best of %d) and peak resident memory (MiB) of the whole process\n" % (size, size, runs))
        print("| N | pray s | POV-Ray s | POV/pray | pray MiB | POV-Ray MiB |")
        print("|---|---|---|---|---|---|")
        for n in [c for c in COUNTS if c <= most]:
            t = gen.cloud_scene("uniform-%s" % label(n), "%d balls spread uniformly through a cube, a sun" % n,
                                n, float("%.4g" % (0.5 * (1000.0 / n) ** (1 / 3.0))))
            t.write(out)
            name = t.name
            r = {"n": n, "name": name}
            r["pray"] = run(pray_cmd(pray, size, name, name + ".ppm"), out, runs)
            r["pov"] = pov and run([pov, "+I%s.pov" % name, "+O%s-pov.ppm" % name, "+W%d" % size, "+H%d" % size,
                                    "-A", "+WT1", "-D", "+FP", "File_Gamma=1.0"], out, runs)
            rows.append(r)
            p, v = r["pray"], r["pov"]
            print("| %s | %s | %s | %s | %s | %s |" % (
                label(n), "%.3f" % p[0] if p else "failed", "%.3f" % v[0] if v else "-",
                "%.1f" % (v[0] / p[0]) if p and v and p[0] > 0 else "-", "%.1f" % p[1] if p else "-", "%.1f" % v[1] if v else "-"))
            sys.stdout.flush()
        ok = [r for r in rows if r["pray"]]
        for key, name in (("pray", "pray"), ("pov", "POV-Ray")):
            got = [r for r in rows if r[key]]
            if got:
                print("\n%s: time grows as N^%.2f, peak memory as N^%.2f" % (
                    name, exponent([r["n"] for r in got], [r[key][0] for r in got]),
                    exponent([r["n"] for r in got], [r[key][1] for r in got])), end="")
        print()
        last = rows[-1]["name"]
        capped = run(pray_cmd(pray, size, last, last + "-cap.ppm"), out, 1, CAP)
        same = capped and open(os.path.join(out, last + ".ppm"), "rb").read() == \
            open(os.path.join(out, last + "-cap.ppm"), "rb").read()
        print("%s under a %d MiB limit of address space: %s" % (
            last, CAP >> 20, "rendered, the same image (peak %.1f MiB)" % capped[1] if same else "FAILED"))
        os.makedirs(os.path.dirname(SAVED), exist_ok=True)
        with open(SAVED, "w") as f:
            json.dump({"size": size, "rows": ok}, f, indent=1)
        if png:
            chart(ok, size, png)
        return 0 if same and len(ok) == len(rows) else 1
    finally:
        shutil.rmtree(out)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
