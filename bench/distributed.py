#!/usr/bin/python3
"""bench/distributed.py - draws what bench/distributed.sh measured, and what it means for many nodes.

  bench/distributed.sh > build/distributed.md
  python3 bench/distributed.py build/distributed.md docs/images/bench-distributed.png

Left: the speed-up of every way of bench/distributed.sh's table against pray on one thread, by
the number of processes (threads for pray itself), on the machine that measured it.
Right: the speed-up on P processes that the cost model of docs/distributed.md gives,

    T(P) = T_run + T_prepare * b + T_render / P + T_gather + T_write

with T_run and T_prepare from the table's `pray --stats` line, T_render the rest of the time of
one thread, b = 1 preparation per process (a pray-mpi worker's bands of a frame share one), the
gather of 12 bytes a pixel over 10 Gbit/s without overlap and one writer at 500 MB/s (8-bit
TIFF, 3 bytes a pixel), for the image measured and for the same scene 16 times wider and higher.
Needs matplotlib.
"""
import re
import sys

BANDS = 1            # preparations per process and image: a pray-mpi worker's bands share one
NET = 10e9 / 8       # bytes a second into rank 0
DISK = 500e6         # bytes a second written by the one writer


def read(path):
    ways, stats, size, cpus = [], None, None, 0
    for line in open(path):
        m = re.match(r"\|\s*([^|]+?)\s*\|\s*(\d+)\s*\|\s*([\d.]+)\s*\|\s*([\d.]+)\s*\|", line)
        if m:
            ways.append((m.group(1), int(m.group(2)), float(m.group(3))))
        m = re.search(r"parse ([\d.]+) s, prepare ([\d.]+) s, render ([\d.]+) s", line)
        if m:
            stats = [float(x) for x in m.groups()]
        m = re.search(r"; (\d+) processors", line)
        if m:
            cpus = int(m.group(1))
        m = re.search(r" at (\d+)x(\d+)", line)
        if m and size is None:
            size = int(m.group(1)) * int(m.group(2))
    if not ways or stats is None or size is None or not cpus:
        sys.exit("%s: not the output of bench/distributed.sh" % path)
    return ways, stats, size, cpus


def model(t_one, stats, pixels, scale, procs):
    t_run, t_prep = stats[0], stats[1]
    t_render = (t_one - t_run - t_prep) * scale
    fixed = t_run + t_prep * BANDS + 12.0 * pixels * scale / NET + 3.0 * pixels * scale / DISK
    whole = t_run + t_prep + t_render + 3.0 * pixels * scale / DISK
    return [whole / (fixed + t_render / p) for p in procs]


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    ways, stats, pixels, cpus = read(argv[1])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    base = ways[0][2]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, mark, name in (("pray,", "o", "pray --threads"), ("GNU parallel", "s", "GNU parallel, --part K/N + --join"),
                            ("pray-mpi", "^", "pray-mpi (rank 0 gathers)")):
        got = [(int(re.search(r"(\d+) thread", way).group(1)) if key == "pray," else n, base / wall)
               for way, n, wall in ways if way.startswith(key)]
        ax[0].plot([g[0] for g in got], [g[1] for g in got], "-" + mark, ms=5, label=name)
    ax[0].axhline(cpus, color="grey", lw=0.8, ls=":")
    ax[0].text(1.05, cpus * 1.015, "%d processors" % cpus, fontsize=8, color="grey")
    ax[0].set_xlabel("processes (threads for pray)")
    ax[0].set_ylabel("speed-up against one thread")
    ax[0].set_title("measured on %d processors (%d pixels)" % (cpus, pixels))
    ax[0].set_ylim(0, cpus * 1.25)
    ax[0].legend(fontsize=8)
    procs = [2 ** k for k in range(11)]
    for scale, name in ((1, "this image"), (256, "16 x wider and higher")):
        ax[1].plot(procs, model(base, stats, pixels, scale, procs), "-o", ms=3, label=name)
    ax[1].plot(procs, procs, ":", color="grey", lw=0.8, label="P")
    ax[1].set_xscale("log", base=2)
    ax[1].set_yscale("log", base=2)
    ax[1].set_xlabel("processes P")
    ax[1].set_ylabel("speed-up T(1) / T(P)")
    ax[1].set_title("on paper: the cost model of docs/distributed.md")
    ax[1].set_xticks(procs)
    ax[1].set_xticklabels([str(p) for p in procs])
    ax[1].set_yticks(procs)
    ax[1].set_yticklabels([str(p) for p in procs])
    ax[1].minorticks_off()
    ax[1].legend(fontsize=8)
    fig.suptitle("One image over many processes (bench/distributed.sh)")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=90)


if __name__ == "__main__":
    main(sys.argv)
