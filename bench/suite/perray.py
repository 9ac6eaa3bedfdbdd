#!/usr/bin/env python3
"""bench/suite/perray.py - draw pray's intersection tests per ray against the number of
primitives, one point per scene of the suite (docs/benchmarks.md, "The suite").

  perray.py TABLE PNG

TABLE is what bench/suite/run.sh printed (its columns scene, prims, pray, tests/ray, ...; any
line that is not a scene's is skipped). The scenes are grouped by family (the name without its
sizes, the gallery as one family), each family a marker, on logarithmic axes, with the line of
10 tests per ray; the scenes of 20 tests per ray or more but the gallery's are named. Needs matplotlib (Debian package python3-matplotlib).
"""
import sys


def family(name):
    """The scene's name without its sizes (the parts that start with a digit)."""
    if name.startswith("gallery-"):
        return "gallery"
    return "-".join(w for w in name.split("-") if not w[:1].isdigit()) or name


def read(path):
    rows = []
    for line in open(path):
        f = line.split()
        if len(f) < 4 or f[0] in ("scene", "geometric"):
            continue
        try:
            prims, perray = int(f[1]), float(f[3])
        except ValueError:
            continue
        if perray > 0:
            rows.append((f[0], prims, perray))
    return rows


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    rows = read(argv[1])
    if not rows:
        sys.exit("perray.py: no scenes in %s" % argv[1])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fams = []
    for name, _, _ in rows:
        if family(name) not in fams:
            fams.append(family(name))
    markers = "os^Dv<>pPXh*d"
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for i, fam in enumerate(fams):
        pts = [(p, t) for name, p, t in rows if family(name) == fam]
        ax.scatter([p for p, _ in pts], [t for _, t in pts], marker=markers[i % len(markers)],
                   color=plt.cm.tab20(i % 20), label=fam, s=36)
    named = sorted((p, t, name) for name, p, t in rows if t >= 20 and not name.startswith("gallery-"))
    for k, (p, t, name) in enumerate(named):  # by turns above and below, so neighbours stay apart
        ax.annotate(name, (p, t), textcoords="offset points", xytext=(5, -10 if k % 2 else 3),
                    fontsize=7)
    ax.axhline(10, color="grey", linestyle="--", linewidth=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("primitives")
    ax.set_ylabel("intersection tests per ray")
    ax.set_title("pray: intersection tests per ray (all rays) against primitives")
    ax.legend(fontsize=7, ncol=2, loc="upper left")
    ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=100)


if __name__ == "__main__":
    main(sys.argv)
