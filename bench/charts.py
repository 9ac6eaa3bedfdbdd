#!/usr/bin/python3
"""bench/charts.py - speed against accuracy, and the acceleration benchmarks drawn.

Run by bench/charts.sh (`make charts`), which installs python3-matplotlib and builds the programs.
Renders a set of gallery scenes and measures, with one thread, the best of REPS runs made in
separate passes over all the settings of a measurement (more when the machine was busy):

  adaptive   render time against error for undersampling thresholds, at antialias 1, 4 and 8
  antialias  render time against error for antialias 1, 2, 3, 4, 8
  grid       time for grid resolutions (none, fixed, automatic); the images must be identical
  precision  the single-precision build (PRAY_REAL=float) against the double one
  threads    one thread against two
  table361   the thesis' Table 3.6.1 rebuilt (bench/run.sh's first table), one thread
  scaling    N random spheres (bench/spheres.ray, bench/run.sh's second table), one thread

Error is measured against a reference rendered with 16 x 16 samples per pixel (cached in
build/charts/ref/, keyed by the scene and pray's sources), on the 8-bit RGB images pray writes:

  PSNR   10 log10(255^2 / MSE), the mean squared error over all pixels and the three channels;
         "inf" when the images are equal.
  wrong  the share of pixels of which at least one channel differs from the reference by more
         than WRONG = 2 levels (of 255).

Prints the tables (Markdown), writes build/charts/results.json and build/charts/tables.md, and
draws docs/images/bench-*.png. Options: --quick (few scenes, small, one run: a check that the
script works; charts go to build/charts/quick/), --plot (redraw from results.json, no rendering),
--threads (measure the threads again, when the machine is quiet, into results.json, and redraw).
"""
import hashlib
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
from PIL import Image

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
os.chdir(ROOT)

QUICK = "--quick" in sys.argv
PLOT_ONLY = "--plot" in sys.argv
THREADS_ONLY = "--threads" in sys.argv
PRAY = os.environ.get("PRAY", "./pray")
PRAY_FLOAT = os.environ.get("PRAY_FLOAT", "build/pray_float")
WORK = "build/charts"
IMAGES = WORK + "/quick" if QUICK else "docs/images"

# The scenes: gallery examples with one frame each, from the cheapest to the slowest, together
# about 1 s of rendering per sample per pixel with one thread.
SCENES = ["csg", "cube", "fractal", "glass", "rabbit", "pc", "textures", "room", "glassab"]
SIZE = 256            # pixels along each side
REF_AA = 16           # the reference: 16 x 16 samples per pixel
REPS = 3              # best of REPS runs for every time ...
ONCE_AA = 8           # ... except antialias 8 (64 times the work of antialias 1), made once
DISTURBED = 0.25      # a run during which other work took more than this share of a core ...
EXTRA = 3             # ... is repeated, at most EXTRA more times, while it is the fastest
DEFAULT_ADAPTIVE = 0.02   # the threshold the manual recommends ("try 0.02"); the option's default is 0 = off
THRESHOLDS = [0, 0.005, 0.02, 0.05, 0.1, 0.2]
ADAPTIVE_AA = [1, 4, 8]
ANTIALIAS = [1, 2, 3, 4, 8]
GRIDS = [0, 8, 16, 32, 64, -1]   # voxels along the longest axis; 0 = none, -1 = automatic
THREAD_AA = 4         # the threads are compared on 4 x 4 samples per pixel (longer renders)
WRONG = 2             # a channel off by more than this (of 255) makes a pixel wrong
TABLE_SCENES = ["cube", "room", "fractal"]
SCALING_N = [16, 64, 256, 1024, 4096, 16384, 65536]
SCALING_BRUTE_MAX = 4096
if QUICK:
    SCENES = ["csg", "cube", "glass"]
    SIZE = 96
    REF_AA = 8
    REPS = 1
    THRESHOLDS = [0, 0.02, 0.1]
    ANTIALIAS = [1, 2, 4]
    GRIDS = [0, 16, -1]
    SCALING_N = [16, 256, 4096]
    SCALING_BRUTE_MAX = 256


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# ---- rendering ----

def parse_stats(text):
    """The numbers of a --stats report."""
    s = {}
    for line in text.splitlines():
        w = line.replace(",", " ").split()
        if not w:
            continue
        if w[0] == "time:":       # time: parse P s  prepare Q s  render R s on N threads
            s["parse"], s["prep"], s["render"] = float(w[2]), float(w[5]), float(w[8])
            s["threads"] = int(w[11])
        elif w[0] == "rays:":     # rays: primary P (of F without undersampling) shadow ...
            s["primary"] = float(w[2])
            s["primary_full"] = float(w[4]) if w[3] == "(of" else float(w[2])
        elif w[0] == "primitives:":
            s["prims"] = int(w[1])
        elif w[0] == "intersection" and w[1] == "tests":
            s["tests"] = float(w[2])
        elif w[0] == "actions:" and "skips" in w:
            s["frozen"] = float(w[w.index("skips") + 1].rstrip(")"))
        elif w[0] == "grid:":
            if w[1] == "none":
                s["grid"] = "none"
            else:                 # grid: X x Y x Z = V voxels  L distinct lists  A areas  B bytes
                s["grid"] = "%sx%sx%s" % (w[1], w[3], w[5]) if w[7] != "0" else "none"
                s["lists"] = int(w[9])
                s["gridbytes"] = float(w[14])
    return s


def render(scene, out, opts, prog=None, reps=1, brute=False, size=None, mem=False):
    """Render scene (a file) into out with options opts ({name: value}); the best of reps runs.
    Returns the statistics of the fastest run, with "others": the other work on the machine
    during it, in cores (all busy CPU time from /proc/stat minus pray's own, over the wall time); with mem, "peak": the largest resident set of the
    runs in KiB, measured by /usr/bin/time (a child of python would count python's own)."""
    prog = prog or PRAY
    size = size or SIZE
    cmd = [prog, "--quiet", "--stats", "-s", "%dx%d" % (size, size), "-o", out]
    for k, v in opts.items():
        cmd += ["-D", "%s=%s" % (k, v)]
    if brute:
        cmd.append("--brute")
    cmd.append(scene)
    memfile = WORK + "/mem.txt"
    if mem:
        cmd = ["/usr/bin/time", "-f", "%M", "-o", memfile] + cmd
    best = None
    peak = 0
    for _ in range(reps):
        busy0 = cpu_busy()
        t0 = time.time()
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        err = p.stderr.read().decode()
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.time() - t0
        busy = cpu_busy() - busy0
        code = os.waitstatus_to_exitcode(status)
        if code != 0:
            raise SystemExit("charts: %s failed (%d):\n%s" % (" ".join(cmd), code, err))
        s = parse_stats(err)
        # the other work on the machine during the run, in cores: all busy time minus ours
        s["others"] = max(0.0, (busy - ru.ru_utime - ru.ru_stime) / wall) if wall > 0 else 0.0
        if mem:
            with open(memfile) as f:
                peak = max(peak, int(f.read().split()[-1]))
        if best is None or s["render"] < best["render"]:
            best = s
    best["peak"] = peak
    return best


def cpu_busy():
    """Seconds of CPU time the whole machine has spent busy (/proc/stat), or 0."""
    try:
        with open("/proc/stat") as f:
            w = [float(x) for x in f.readline().split()[1:9]]
        return (sum(w) - w[3] - w[4]) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError):
        return 0.0


def scene_file(name):
    return name if name.endswith(".ray") else "examples/%s.ray" % name


def digest(*paths):
    h = hashlib.sha1()
    for p in paths:
        with open(p, "rb") as f:
            h.update(f.read())
    return h.hexdigest()[:12]


def reference(name):
    """The 16 x 16 supersampled reference, cached; rendered with every thread (the image does
    not depend on the number of threads)."""
    key = digest(scene_file(name), "pray.cpp", "pray.hpp")
    path = "%s/ref/%s-%d-%d-%s.ppm" % (WORK, name, SIZE, REF_AA, key)
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        for old in os.listdir(os.path.dirname(path)):
            if old.startswith("%s-%d-%d-" % (name, SIZE, REF_AA)):
                os.remove(os.path.join(os.path.dirname(path), old))
        log("reference %-9s %d x %d samples per pixel ..." % (name, REF_AA, REF_AA))
        t = time.time()
        render(scene_file(name), path + ".tmp.ppm", {"antialias": REF_AA, "threads": 0})
        os.rename(path + ".tmp.ppm", path)
        log("reference %-9s %.0f s" % (name, time.time() - t))
    return path


_images = {}


def pixels(path):
    if path not in _images:
        with Image.open(path) as im:
            _images[path] = np.asarray(im.convert("RGB"), dtype=np.int16)
    return _images[path]


def error(path, ref):
    """(PSNR in dB or inf, share of wrong pixels) of the image at path against ref."""
    a, b = pixels(path), pixels(ref)
    d = a - b
    mse = float(np.mean(d.astype(np.float64) ** 2))
    psnr = float("inf") if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)
    wrong = float(np.mean(np.abs(d).max(axis=2) > WRONG))
    return psnr, wrong


def same_bytes(a, b):
    with open(a, "rb") as f, open(b, "rb") as g:
        return f.read() == g.read()


# ---- the measurements ----

def timed(jobs, total=False):
    """Time jobs, a list of (key, args of render): REPS passes over the whole list, so that a
    disturbance of a few seconds hits one run of a setting rather than all of them; then up to
    EXTRA more runs of a setting while its fastest run was disturbed by other work. A job whose
    args have "once" runs in the first pass only. Returns {key: statistics of the fastest run},
    fastest by render time, or by pre-processing + render time with total."""
    def cost(x):
        return x["render"] + (x["prep"] if total else 0)
    best = {}
    peak = {}

    def run(key, kw):
        kw = dict(kw)
        kw.pop("once", None)
        x = render(**kw)
        peak[key] = max(peak.get(key, 0), x["peak"])
        if key not in best or cost(x) < cost(best[key]):
            best[key] = x
    for rep in range(REPS):
        for key, kw in jobs:
            if rep == 0 or not kw.get("once"):
                run(key, kw)
    for key, kw in jobs:
        for _ in range(EXTRA if REPS > 1 and not kw.get("once") else 0):
            if best[key]["others"] <= DISTURBED:
                break
            run(key, kw)
    for key in best:
        best[key]["peak"] = peak[key]
    return best


def measure():
    R = {"size": SIZE, "ref_aa": REF_AA, "reps": REPS, "wrong": WRONG, "default_adaptive": DEFAULT_ADAPTIVE,
         "scenes": SCENES, "machine": machine(), "adaptive": [], "antialias": [], "grid": [],
         "precision": [], "threads": [], "table361": [], "scaling": []}
    img = WORK + "/img"
    os.makedirs(img, exist_ok=True)
    refs = dict((n, reference(n)) for n in SCENES)
    one = {"threads": 1}

    def out(*k):
        return "%s/%s.ppm" % (img, "-".join(str(x) for x in k))

    log("adaptive thresholds and antialias levels")
    jobs = []
    for n in SCENES:
        for aa in sorted(set(ADAPTIVE_AA) | set(ANTIALIAS)):
            for t in (THRESHOLDS if aa in ADAPTIVE_AA else [0]):
                jobs.append(((n, aa, t), {"scene": scene_file(n), "out": out(n, "aa%d" % aa, "ad%g" % t),
                                          "opts": dict(one, antialias=aa, adaptive=t), "once": aa >= ONCE_AA}))
    T = timed(jobs)
    for n in SCENES:
        for aa in ADAPTIVE_AA:
            full = out(n, "aa%d" % aa, "ad0")
            for t in THRESHOLDS:
                s = T[(n, aa, t)]
                o = out(n, "aa%d" % aa, "ad%g" % t)
                p, w = error(o, refs[n])
                pf, wf = error(o, full)
                R["adaptive"].append({"scene": n, "aa": aa, "threshold": t, "time": s["render"],
                                      "rays": s["primary"] / s["primary_full"], "psnr": p, "wrong": w,
                                      "psnr_full": pf, "wrong_full": wf})
                log("  %-9s aa %d adaptive %-6g %7.3f s  %5.1f %% rays  %s dB  %.2f %% wrong" %
                    (n, aa, t, s["render"], 100 * s["primary"] / s["primary_full"], fmt_db(p), 100 * w))
        for aa in ANTIALIAS:
            p, w = error(out(n, "aa%d" % aa, "ad0"), refs[n])
            tm = T[(n, aa, 0)]["render"]
            R["antialias"].append({"scene": n, "aa": aa, "time": tm, "psnr": p, "wrong": w})
            log("  %-9s aa %d %7.3f s  %s dB  %.2f %% wrong" % (n, aa, tm, fmt_db(p), 100 * w))

    log("grid resolutions")
    jobs = [((n, g), {"scene": scene_file(n), "out": out(n, "grid%d" % g), "opts": dict(one, grid=g)})
            for n in SCENES for g in GRIDS]
    T = timed(jobs, total=True)
    for n in SCENES:
        for g in GRIDS:
            s = T[(n, g)]
            R["grid"].append({"scene": n, "grid": g, "layout": s.get("grid", "?"), "prep": s["prep"], "time": s["render"],
                              "tests": s.get("tests", 0), "same": same_bytes(out(n, "grid%d" % g), out(n, "grid-1"))})
            log("  %-9s grid %-4d %-12s prep %.3f render %7.3f s  same image: %s" %
                (n, g, s.get("grid", "?"), s["prep"], s["render"], R["grid"][-1]["same"]))

    log("float against double")
    jobs = []
    for n in SCENES:
        jobs.append(((n, "double"), {"scene": scene_file(n), "out": out(n, "double"), "opts": one}))
        jobs.append(((n, "float"), {"scene": scene_file(n), "out": out(n, "float"), "opts": one, "prog": PRAY_FLOAT}))
    T = timed(jobs)
    for n in SCENES:
        sd, sf = T[(n, "double")], T[(n, "float")]
        pd, wd = error(out(n, "double"), refs[n])
        pf, wf = error(out(n, "float"), refs[n])
        px, wx = error(out(n, "float"), out(n, "double"))
        R["precision"].append({"scene": n, "aa": 1, "time_double": sd["render"], "time_float": sf["render"],
                               "psnr_double": pd, "wrong_double": wd, "psnr_float": pf, "wrong_float": wf,
                               "psnr_fd": px, "wrong_fd": wx})
        log("  %-9s double %7.3f s %s dB, float %7.3f s %s dB; float against double %s dB, %.3f %% wrong" %
            (n, sd["render"], fmt_db(pd), sf["render"], fmt_db(pf), fmt_db(px), 100 * wx))

    R["threads"] = measure_threads()

    log("Table 3.6.1")
    settings = [("grid + freezing", {"grid": -1, "freeze": 1}, False), ("grid", {"grid": -1, "freeze": 0}, False),
                ("gridless + freezing", {"grid": 0, "freeze": 1}, False), ("gridless", {"grid": 0, "freeze": 0}, False),
                ("brute", {}, True)]
    jobs = [((n, i), {"scene": scene_file(n), "out": out("t361", n, i), "opts": dict(one, **o), "brute": brute,
                      "size": 256}) for n in TABLE_SCENES for i, (label, o, brute) in enumerate(settings)]
    T = timed(jobs)
    for n in TABLE_SCENES:
        for i, (label, o, brute) in enumerate(settings):
            s = T[(n, i)]
            R["table361"].append({"scene": n, "setting": label, "prep": s["prep"], "time": s["render"],
                                  "prims": s.get("prims", 0), "tests": s.get("tests", 0), "frozen": s.get("frozen", 0),
                                  "same": same_bytes(out("t361", n, i), out("t361", n, 0))})
            log("  %-8s %-20s %7.3f s  same image: %s" % (n, label, s["render"], R["table361"][-1]["same"]))

    log("scaling")
    with open("bench/spheres.ray") as f:
        body = f.read()
    jobs = []
    for N in SCALING_N:
        prog = "%s/spheres-%d.ray" % (WORK, N)
        with open(prog, "w") as f:
            f.write("N = %d\n" % N + body)
        jobs.append(((N, "grid"), {"scene": prog, "out": out("spheres", N, "g"), "opts": one, "size": 128, "mem": True}))
        if N <= SCALING_BRUTE_MAX:
            jobs.append(((N, "brute"), {"scene": prog, "out": out("spheres", N, "b"), "opts": one, "size": 128,
                                        "mem": True, "brute": True}))
    T = timed(jobs)
    for N in SCALING_N:
        g = T[(N, "grid")]
        row = {"n": N, "prep": g["prep"], "time": g["render"], "peak": g["peak"] / 1024.0,
               "struct": g.get("gridbytes", 0) / 1048576.0, "grid": g.get("grid", "none"), "brute": None,
               "brute_peak": None, "same": None}
        if (N, "brute") in T:
            b = T[(N, "brute")]
            row.update(brute=b["render"], brute_peak=b["peak"] / 1024.0,
                       same=same_bytes(out("spheres", N, "g"), out("spheres", N, "b")))
        os.remove("%s/spheres-%d.ray" % (WORK, N))
        R["scaling"].append(row)
        log("  N %6d prep %.3f render %.3f s, brute %s" % (N, g["prep"], g["render"], row["brute"]))
    return R


def measure_threads():
    """One thread against two on THREAD_AA x THREAD_AA samples, in interleaved passes; with the
    other work on the machine (in cores) during the fastest runs."""
    log("threads (load average %.2f)" % os.getloadavg()[0])
    jobs = []
    for n in SCENES:
        for t in (1, 2):
            jobs.append(((n, t), {"scene": scene_file(n), "out": "%s/img/%s-threads%d.ppm" % (WORK, n, t),
                                  "opts": {"threads": t, "antialias": THREAD_AA}}))
    T = timed(jobs)
    rows = []
    for n in SCENES:
        a, b = T[(n, 1)], T[(n, 2)]
        rows.append({"scene": n, "aa": THREAD_AA, "t1": a["render"], "t2": b["render"],
                     "others1": a["others"], "others2": b["others"], "same": same_bytes(
                         "%s/img/%s-threads1.ppm" % (WORK, n), "%s/img/%s-threads2.ppm" % (WORK, n))})
        log("  %-9s 1 thread %7.3f s, 2 threads %7.3f s: %.2f times (other work: %.2f, %.2f cores), same image: %s" %
            (n, a["render"], b["render"], a["render"] / b["render"], a["others"], b["others"], rows[-1]["same"]))
    return rows


def machine():
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    ver = subprocess.run([PRAY, "--version"], capture_output=True, text=True).stdout.strip()
    try:
        cxx = subprocess.run([os.environ.get("CXX", "c++"), "--version"], capture_output=True,
                             text=True).stdout.splitlines()[0]
    except (OSError, IndexError):
        cxx = "?"
    git = subprocess.run(["git", "log", "-1", "--format=%h", "--", "pray.cpp", "pray.hpp"], capture_output=True,
                         text=True).stdout.strip() or "?"
    if subprocess.run(["git", "diff", "--quiet", "--", "pray.cpp", "pray.hpp"]).returncode != 0:
        git += " with uncommitted changes"
    return {"cpu": cpu, "cores": os.cpu_count(), "load": os.getloadavg()[0], "pray": ver, "cxx": cxx,
            "date": time.strftime("%Y-%m-%d %H:%M"), "source": git}


# ---- tables ----

def fmt_db(p):
    return "inf" if math.isinf(p) else "%.1f" % p


def fmt_pct(w):
    if w == 0:
        return "0"
    if w < 0.0001:
        return "< 0.01"
    return "%.2f" % (100 * w) if w < 0.1 else "%.1f" % (100 * w)


def table(head, rows):
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" if i == 0 else "---:" for i in range(len(head))) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def geomean(xs):
    xs = [x for x in xs if x > 0]
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else float("nan")


def tables(R):
    T = []
    m = R["machine"]
    T.append("Machine: %s, %d cores, load %.2f at the start; %s; %s, pray.cpp of %s; %s; %d x %d, best of %d runs, "
             "one thread." % (m["cpu"], m["cores"], m["load"], m["cxx"], m["pray"], m.get("source", "?"), m["date"],
                              R["size"], R["size"], R["reps"]))
    d = R["default_adaptive"]
    for aa in sorted(set(r["aa"] for r in R["adaptive"])):
        rows = []
        for n in R["scenes"]:
            rs = [r for r in R["adaptive"] if r["scene"] == n and r["aa"] == aa]
            full = [r for r in rs if r["threshold"] == 0][0]
            for r in rs:
                rows.append([n if r is rs[0] else "", "off" if r["threshold"] == 0 else "%g" % r["threshold"],
                             "%.3f" % r["time"], "%.2f" % (full["time"] / r["time"]), "%.0f" % (100 * r["rays"]),
                             fmt_db(r["psnr"]), fmt_pct(r["wrong"]), fmt_db(r["psnr_full"]), fmt_pct(r["wrong_full"])])
        T.append("### Undersampling (adaptive), antialias %d\n\n" % aa + table(
            ["scene", "adaptive", "time (s)", "speed-up", "primary rays (%)", "PSNR (dB)", "wrong (%)",
             "PSNR vs full (dB)", "wrong vs full (%)"], rows))
    # the target: the default threshold against full sampling
    rows = []
    for aa in sorted(set(r["aa"] for r in R["adaptive"])):
        tf = ta = 0.0
        sp = []
        for n in R["scenes"]:
            rs = [r for r in R["adaptive"] if r["scene"] == n and r["aa"] == aa]
            full = [r for r in rs if r["threshold"] == 0][0]
            ad = [r for r in rs if r["threshold"] == d]
            if not ad:
                continue
            ad = ad[0]
            tf += full["time"]
            ta += ad["time"]
            sp.append(full["time"] / ad["time"])
            fast, good = full["time"] / ad["time"] >= 2, ad["psnr"] >= 40
            ok = "yes" if fast and good else "no (speed)" if good else "no (PSNR)" if fast else "no"
            rows.append([n, aa, "%.3f" % full["time"], "%.3f" % ad["time"], "%.2f" % (full["time"] / ad["time"]),
                         fmt_db(full["psnr"]), fmt_db(ad["psnr"]), fmt_db(ad["psnr_full"]), ok])
        if sp:
            rows.append(["**all (sum of times)**", aa, "%.3f" % tf, "%.3f" % ta, "%.2f" % (tf / ta), "", "", "", ""])
            rows.append(["**geometric mean**", aa, "", "", "%.2f" % geomean(sp), "", "", "", ""])
    T.append("### The target: adaptive %g against full sampling\n\n" % d + table(
        ["scene", "antialias", "full (s)", "adaptive %g (s)" % d, "speed-up", "PSNR full (dB)", "PSNR adaptive (dB)",
         "PSNR adaptive vs full (dB)", "≥ 2× and ≥ 40 dB"], rows))
    # at equal quality: the fastest full sampling and the fastest undersampling reaching 40 dB
    rows = []
    for n in R["scenes"]:
        full = [r for r in R["antialias"] if r["scene"] == n and r["psnr"] >= 40]
        ad = [r for r in R["adaptive"] if r["scene"] == n and r["threshold"] > 0 and r["psnr"] >= 40]
        f = min(full, key=lambda r: r["time"]) if full else None
        a = min(ad, key=lambda r: r["time"]) if ad else None
        rows.append([n, "antialias %d: %.3f s" % (f["aa"], f["time"]) if f else "—",
                     "antialias %d, adaptive %g: %.3f s" % (a["aa"], a["threshold"], a["time"]) if a else "—",
                     "%.2f" % (f["time"] / a["time"]) if f and a else "—"])
    T.append("### At equal quality: the fastest setting of at least 40 dB\n\n" + table(
        ["scene", "full sampling", "undersampling", "speed-up"], rows))
    rows = []
    levels = sorted(set(r["aa"] for r in R["antialias"]))
    for n in R["scenes"]:
        rs = dict((r["aa"], r) for r in R["antialias"] if r["scene"] == n)
        rows.append([n] + ["%.3f s, %s dB, %s %%" % (rs[a]["time"], fmt_db(rs[a]["psnr"]), fmt_pct(rs[a]["wrong"]))
                           for a in levels])
    T.append("### Antialias (time, PSNR, wrong pixels)\n\n" + table(["scene"] + [str(a) for a in levels], rows))
    grids = []
    for r in R["grid"]:
        if r["grid"] not in grids:
            grids.append(r["grid"])
    grids.sort(key=lambda g: (g == -1, g))
    rows = []
    for n in R["scenes"]:
        rs = dict((r["grid"], r) for r in R["grid"] if r["scene"] == n)
        row = [n]
        for g in grids:
            row.append("%.3f" % (rs[g]["prep"] + rs[g]["time"]) + ("" if rs[g]["same"] else " **differs**"))
        row.append(rs[-1]["layout"].replace("x", " × "))
        rows.append(row)
    T.append("### Grid resolution: pre-processing + render (s)\n\n" + table(
        ["scene"] + [grid_label(g) for g in grids] + ["automatic grid"], rows))
    rows = []
    for r in R["precision"]:
        rows.append([r["scene"], "%.3f" % r["time_double"], "%.3f" % r["time_float"],
                     "%.2f" % (r["time_double"] / r["time_float"]), fmt_db(r["psnr_double"]), fmt_db(r["psnr_float"]),
                     fmt_db(r["psnr_fd"]), fmt_pct(r["wrong_fd"])])
    T.append("### float against double (antialias 1)\n\n" + table(
        ["scene", "double (s)", "float (s)", "double / float", "PSNR double (dB)", "PSNR float (dB)",
         "PSNR float vs double (dB)", "wrong float vs double (%)"], rows))
    rows = []
    s1 = s2 = 0.0
    for r in R["threads"]:
        s1 += r["t1"]
        s2 += r["t2"]
        rows.append([r["scene"], "%.3f" % r["t1"], "%.3f" % r["t2"], "%.2f" % (r["t1"] / r["t2"]),
                     "%.2f" % r.get("others1", 0), "%.2f" % r.get("others2", 0),
                     {True: "yes", False: "**no**"}.get(r.get("same"), "?")])
    if R["threads"]:
        rows.append(["**all (sum of times)**", "%.3f" % s1, "%.3f" % s2, "%.2f" % (s1 / s2), "", "", ""])
        rows.append(["**geometric mean**", "", "", "%.2f" % geomean([r["t1"] / r["t2"] for r in R["threads"]]),
                     "", "", ""])
        T.append("### Threads (antialias %d)\n\n" % R["threads"][0]["aa"] + table(
            ["scene", "1 thread (s)", "2 threads (s)", "speed-up", "other work, 1 thread (cores)",
             "other work, 2 threads (cores)", "same image"], rows))
    rows = []
    for n in TABLE_SCENES:
        rs = [r for r in R["table361"] if r["scene"] == n]
        if rs:
            rows.append([n, rs[0]["prims"], "%.3f" % rs[0]["prep"]] +
                        ["%.3f" % r["time"] + ("" if r["same"] else " **differs**") for r in rs])
    T.append("### Table 3.6.1 rebuilt (256 x 256, one thread)\n\n" + table(
        ["scene", "primitives", "pre-processing", "grid + freezing", "grid", "gridless + freezing", "gridless", "brute"], rows))
    rows = []
    for r in R["scaling"]:
        rows.append([r["n"], "%.3f" % r["prep"], "%.3f" % r["time"], "%.1f" % r["peak"], "%.1f" % r["struct"],
                     r["grid"].replace("x", " × "), "—" if r["brute"] is None else "%.3f" % r["brute"] +
                     ("" if r["same"] else " **differs**")])
    ex = scaling_exponent(R["scaling"], "time")
    exb = scaling_exponent(R["scaling"], "brute")
    T.append("### Scaling (128 x 128, one thread)\n\n" + table(
        ["N", "pre-processing", "render, grid", "peak memory (MiB)", "structure (MiB)", "grid", "render, brute"], rows) +
        "\n\nFitted exponent of render time against N: grid %.2f, brute %.2f." % (ex, exb))
    return "\n\n".join(T) + "\n"


def grid_label(g):
    return "none" if g == 0 else ("automatic" if g == -1 else str(g))


def scaling_exponent(rows, key):
    pts = [(math.log(r["n"]), math.log(r[key])) for r in rows if r.get(key)]
    if len(pts) < 2:
        return float("nan")
    n = len(pts)
    sx = sum(p[0] for p in pts)
    sy = sum(p[1] for p in pts)
    sxx = sum(p[0] ** 2 for p in pts)
    sxy = sum(p[0] * p[1] for p in pts)
    return (n * sxy - sx * sy) / (n * sxx - sx * sx)


# ---- charts ----

def charts(R):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    plt.rcParams.update({"font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "legend.fontsize": 8,
                         "figure.dpi": 100, "savefig.dpi": 100})
    os.makedirs(IMAGES, exist_ok=True)
    scenes = R["scenes"]
    colours = dict((n, plt.cm.tab10(i % 10)) for i, n in enumerate(scenes))
    INF = 70.0   # where an exact image (infinite PSNR) is drawn

    def db(p):
        return min(p, INF)

    def save(fig, name):
        path = "%s/bench-%s.png" % (IMAGES, name)
        fig.savefig(path + ".tmp.png")
        plt.close(fig)
        # a palette image: a fraction of the size, no visible loss on these charts
        with Image.open(path + ".tmp.png") as im:
            im.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)
        os.remove(path + ".tmp.png")
        log("chart: %s (%d KB)" % (path, (os.path.getsize(path) + 1023) // 1024))

    # adaptive: time against PSNR and wrong pixels, a row for each antialias level
    aas = sorted(set(r["aa"] for r in R["adaptive"]))
    fig, axs = plt.subplots(len(aas), 2, figsize=(11, 3.9 * len(aas)), squeeze=False)
    for ax, aa in zip(axs, aas):
        for n in scenes:
            rs = sorted([r for r in R["adaptive"] if r["scene"] == n and r["aa"] == aa], key=lambda r: -r["threshold"])
            ax[0].plot([db(r["psnr"]) for r in rs], [r["time"] for r in rs], "-", marker=".", color=colours[n], label=n)
            ax[1].plot([100 * r["wrong"] for r in rs], [r["time"] for r in rs], "-", marker=".", color=colours[n])
            for r in rs:
                if r["threshold"] == R["default_adaptive"]:
                    ax[0].plot([db(r["psnr"])], [r["time"]], "o", mfc="none", mec="k", ms=7)
                    ax[1].plot([100 * r["wrong"]], [r["time"]], "o", mfc="none", mec="k", ms=7)
                if r["threshold"] == 0:
                    ax[0].plot([db(r["psnr"])], [r["time"]], "s", color=colours[n], ms=5)
                    ax[1].plot([100 * r["wrong"]], [r["time"]], "s", color=colours[n], ms=5)
        ax[0].axvline(40, color="grey", lw=0.8, ls=":")
        ax[0].set_xlabel("PSNR against the %d x %d reference (dB)" % (R["ref_aa"], R["ref_aa"]))
        ax[1].set_xlabel("wrong pixels (%%, a channel off by more than %d/255)" % R["wrong"])
        ax[1].set_xscale("log")
        ax[1].xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1, 2, 5)))
        ax[1].xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax[1].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        for a in ax:
            a.set_yscale("log")
            a.set_ylabel("render time (s, one thread)")
            a.set_title("antialias %d (%d sample%s per pixel)" % (aa, aa * aa, "s" if aa > 1 else ""))
    axs[0][1].legend(*axs[0][0].get_legend_handles_labels(), loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    thr = ", ".join("%g" % t for t in sorted(set(r["threshold"] for r in R["adaptive"])) if t)
    fig.suptitle("Undersampling (adaptive %s): square = full sampling, ring = %g; the larger the threshold, the faster"
                 % (thr, R["default_adaptive"]))
    fig.tight_layout()
    save(fig, "adaptive")

    # antialias
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.6))
    for n in scenes:
        rs = [r for r in R["antialias"] if r["scene"] == n]
        ax[0].plot([db(r["psnr"]) for r in rs], [r["time"] for r in rs], "-o", ms=3, color=colours[n], label=n)
        ax[1].plot([100 * r["wrong"] for r in rs], [r["time"] for r in rs], "-o", ms=3, color=colours[n])
        for r in rs:
            if n == scenes[-1]:
                ax[0].annotate("%d" % r["aa"], (db(r["psnr"]), r["time"]), textcoords="offset points", xytext=(4, -9), fontsize=7)
    ax[0].axvline(40, color="grey", lw=0.8, ls=":")
    ax[0].set_xlabel("PSNR against the %d x %d reference (dB)" % (R["ref_aa"], R["ref_aa"]))
    ax[1].set_xlabel("wrong pixels (%%, a channel off by more than %d/255)" % R["wrong"])
    ax[1].set_xscale("log")
    ax[1].xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1, 2, 5)))
    ax[1].xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax[1].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    for a in ax:
        a.set_yscale("log")
        a.set_ylabel("render time (s, one thread)")
    ax[0].legend(loc="upper left", ncol=2)
    fig.suptitle("Supersampling: antialias %s (N x N samples per pixel)" %
                 ", ".join(str(a) for a in sorted(set(r["aa"] for r in R["antialias"]))))
    fig.tight_layout()
    save(fig, "antialias")

    # grid resolutions
    grids = sorted(set(r["grid"] for r in R["grid"]), key=lambda g: (g == -1, g))
    fig, ax = plt.subplots(figsize=(8, 4.4))
    x = list(range(len(grids)))
    for n in scenes:
        rs = dict((r["grid"], r) for r in R["grid"] if r["scene"] == n)
        ax.plot(x, [rs[g]["prep"] + rs[g]["time"] for g in grids], "-o", ms=3, color=colours[n], label=n)
        bad = [i for i, g in enumerate(grids) if not rs[g]["same"]]
        if bad:
            ax.plot(bad, [rs[grids[i]]["prep"] + rs[grids[i]]["time"] for i in bad], "x", color="red", ms=9)
    ax.set_xticks(x)
    ax.set_xticklabels([grid_label(g) for g in grids])
    ax.set_yscale("log")
    ax.set_xlabel("grid: voxels along the longest axis")
    ax.set_ylabel("pre-processing + render (s, one thread)")
    ax.legend(ncol=3)
    ax.set_title("Grid resolution (antialias 1); every image equals the automatic grid's byte for byte")
    fig.tight_layout()
    save(fig, "grid")

    # float against double
    rs = [r for r in R["precision"] if r["aa"] == 1]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    x = np.arange(len(rs))
    ax[0].bar(x - 0.2, [r["time_double"] for r in rs], 0.4, label="double")
    ax[0].bar(x + 0.2, [r["time_float"] for r in rs], 0.4, label="float")
    ax[0].set_yscale("log")
    ax[0].set_ylabel("render time (s, one thread)")
    ax[0].set_title("time, antialias 1")
    ax[1].bar(x - 0.2, [db(r["psnr_double"]) for r in rs], 0.4, label="double vs reference")
    ax[1].bar(x + 0.2, [db(r["psnr_float"]) for r in rs], 0.4, label="float vs reference")
    ax[1].plot(x, [db(r["psnr_fd"]) for r in rs], "kD", ms=5, label="float vs double (%g = equal)" % INF)
    ax[1].set_ylabel("PSNR (dB)")
    ax[1].set_title("error, antialias 1")
    for a in ax:
        a.set_xticks(x)
        a.set_xticklabels([r["scene"] for r in rs], rotation=30)
        a.legend(fontsize=7)
    fig.suptitle("Single precision (PRAY_REAL=float) against double")
    fig.tight_layout()
    save(fig, "precision")

    # threads
    rs = R["threads"]
    fig, ax = plt.subplots(figsize=(8, 4))
    x = np.arange(len(rs) + 1)
    sp = [r["t1"] / r["t2"] for r in rs] + [sum(r["t1"] for r in rs) / sum(r["t2"] for r in rs)]
    ax.bar(x, sp, 0.6, color=["C0"] * len(rs) + ["C1"])
    for i, v in enumerate(sp):
        ax.annotate("%.2f" % v, (i, v), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=8)
    ax.axhline(1.8, color="red", lw=0.8, ls="--", label="target 1.8")
    ax.axhline(2.0, color="grey", lw=0.8, ls=":", label="ideal 2")
    ax.set_xticks(x)
    ax.set_xticklabels([r["scene"] for r in rs] + ["all"], rotation=30)
    ax.set_ylim(0, 2.3)
    ax.set_ylabel("speed-up, 2 threads against 1")
    ax.set_title("Threads: render time of one thread / two threads (antialias %d, %s cores)" %
                 (rs[0]["aa"], R["machine"]["cores"]))
    ax.legend(loc="lower right")
    fig.tight_layout()
    save(fig, "threads")

    # Table 3.6.1
    labels = []
    for r in R["table361"]:
        if r["setting"] not in labels:
            labels.append(r["setting"])
    tsc = [n for n in TABLE_SCENES if any(r["scene"] == n for r in R["table361"])]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.4), gridspec_kw={"width_ratios": [3, 2]})
    w = 0.8 / len(labels)
    for i, lab in enumerate(labels):
        v = [[r for r in R["table361"] if r["scene"] == n and r["setting"] == lab][0]["time"] for n in tsc]
        bars = ax[0].bar(np.arange(len(tsc)) + (i - (len(labels) - 1) / 2) * w, v, w, label=lab)
        for b, t in zip(bars, v):
            ax[0].annotate("%.2f" % t if t < 10 else "%.0f" % t, (b.get_x() + b.get_width() / 2, t),
                           textcoords="offset points", xytext=(0, 2), ha="center", fontsize=6)
    ax[0].set_yscale("log")
    ax[0].set_xticks(np.arange(len(tsc)))
    ax[0].set_xticklabels(["%s (%d primitives)" % (n, [r for r in R["table361"] if r["scene"] == n][0]["prims"]) for n in tsc])
    ax[0].set_ylabel("render time (s, 256 x 256, one thread)")
    ax[0].legend(fontsize=7)
    ax[0].set_title("render time by acceleration")
    gt = [[r for r in R["table361"] if r["scene"] == n and r["setting"] == labels[0]][0]["tests"] for n in tsc]
    bt = [[r for r in R["table361"] if r["scene"] == n and r["setting"] == labels[-1]][0]["tests"] for n in tsc]
    ax[1].bar(np.arange(len(tsc)) - 0.2, gt, 0.4, label="grid + freezing")
    ax[1].bar(np.arange(len(tsc)) + 0.2, bt, 0.4, label="brute")
    ax[1].set_yscale("log")
    ax[1].set_xticks(np.arange(len(tsc)))
    ax[1].set_xticklabels(tsc)
    ax[1].set_ylabel("ray/primitive intersection tests")
    ax[1].legend(fontsize=7)
    ax[1].set_title("intersection tests")
    fig.suptitle("Table 3.6.1 of the thesis, rebuilt on our scenes")
    fig.tight_layout()
    save(fig, "table361")

    # scaling
    S = R["scaling"]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    N = [r["n"] for r in S]
    ax[0].plot(N, [r["time"] for r in S], "-o", ms=3, label="render, grid (exponent %.2f)" % scaling_exponent(S, "time"))
    ax[0].plot(N, [r["prep"] for r in S], "-s", ms=3, label="pre-processing, grid")
    bs = [r for r in S if r["brute"]]
    ax[0].plot([r["n"] for r in bs], [r["brute"] for r in bs], "-^", ms=3,
               label="render, brute (exponent %.2f)" % scaling_exponent(S, "brute"))
    ax[0].set_ylabel("time (s, 128 x 128, one thread)")
    ax[0].set_title("time")
    ax[1].plot(N, [r["peak"] for r in S], "-o", ms=3, label="peak memory of the process, grid")
    ax[1].plot(N, [max(r["struct"], 1e-3) for r in S], "-s", ms=3, label="acceleration structure")
    ax[1].plot([r["n"] for r in bs], [r["brute_peak"] for r in bs], "-^", ms=3, label="peak memory, brute")
    ax[1].set_ylabel("MiB")
    ax[1].set_title("memory")
    for a in ax:
        a.set_xscale("log")
        a.set_xticks(N)
        a.set_xticklabels([str(v) for v in N])
        a.minorticks_off()
        a.set_yscale("log")
        a.set_xlabel("N (random spheres minus a sphere and a cylinder)")
        a.legend(fontsize=7)
    fig.suptitle("Scaling with the number of primitives (bench/spheres.ray)")
    fig.tight_layout()
    save(fig, "scaling")


def main():
    os.makedirs(WORK, exist_ok=True)
    res = WORK + ("/results-quick.json" if QUICK else "/results.json")
    if PLOT_ONLY or THREADS_ONLY:
        with open(res) as f:
            R = json.load(f)
        if THREADS_ONLY:
            R["threads"] = measure_threads()
            R["machine"]["threads_load"] = os.getloadavg()[0]
            with open(res, "w") as f:
                json.dump(R, f, indent=1)
    else:
        if os.getloadavg()[0] > 0.5:
            log("charts: the machine is busy (load average %.2f); the times will suffer" % os.getloadavg()[0])
        t = time.time()
        R = measure()
        R["seconds"] = time.time() - t
        with open(res, "w") as f:
            json.dump(R, f, indent=1)
    text = tables(R)
    print(text)
    with open(WORK + ("/tables-quick.md" if QUICK else "/tables.md"), "w") as f:
        f.write(text)
    charts(R)
    if "seconds" in R and not PLOT_ONLY:
        log("charts: measured in %.0f s" % R["seconds"])


if __name__ == "__main__":
    main()
