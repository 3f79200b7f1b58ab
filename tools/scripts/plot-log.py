#!/usr/bin/python3
"""Plot an irdm-fw telemetry log, exported with `irdm log export LOG -o LOG.csv`:
  PREFIX-force.png    force on the object against time, one panel per device
                      (components and magnitude, N)
  PREFIX-latency.png  wake-up latency histogram (log x, ns)
  PREFIX-compute.png  compute-time histogram (log x, ns)
Percentiles in the legends are nearest-rank over the exported ticks.
usage: plot-log.py LOG.csv PREFIX [title]"""
import csv
import math
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        sys.exit(f"plot-log: {path}: no records")
    head = rows[0]
    cols = {name: [r[k] for r in rows[1:]] for k, name in enumerate(head)}
    return head, cols


def nearest_rank(sorted_v, p):
    k = max(1, math.ceil(p * len(sorted_v)))
    return sorted_v[k - 1]


def plot_force(head, cols, dst, title):
    t = np.array(cols["t_s"], dtype=float)
    devices = sorted({name.split("_")[0] for name in head if name.endswith("_fx_n")})
    if not devices:
        sys.exit("plot-log: no device columns (dN_fx_n) in the CSV")
    fig, axes = plt.subplots(len(devices), 1, figsize=(8, 3.2 * len(devices) + 1),
                             sharex=True, squeeze=False)
    for ax, d in zip(axes[:, 0], devices):
        f = np.array([cols[f"{d}_f{a}_n"] for a in "xyz"], dtype=float)
        for a, name in enumerate("xyz"):
            ax.plot(t, f[a], lw=0.8, label=f"{d} f{name}")
        ax.plot(t, np.sqrt((f ** 2).sum(axis=0)), "k", lw=1.2, label=f"{d} |f|")
        ax.set_ylabel("force on the object (N)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].set_title(title)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    plt.close(fig)


def plot_hist(values, what, dst, title):
    v = np.sort(np.array(values, dtype=float))
    pos = v[v > 0]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    stats = ", ".join(f"{name} {nearest_rank(v, p):.0f}" for name, p in
                      (("p50", 0.5), ("p99", 0.99), ("p99.9", 0.999), ("max", 1.0)))
    if len(pos):
        lo, hi = pos[0], pos[-1]
        bins = np.logspace(math.log10(lo), math.log10(hi * 1.0001) if hi > lo else math.log10(lo) + 1, 60)
        counts, _, _ = ax.hist(pos, bins=bins, label=f"{len(v)} ticks: {stats} ns")
        ax.set_xscale("log")
        ax.set_yscale("log")      # the rare slow ticks are what matters
        ax.set_ylim(0.8, 5 * max(counts))   # room for the legend above the bars
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no sample above 0 ns", ha="center", transform=ax.transAxes)
    hidden = len(v) - len(pos)
    ax.set_xlabel(f"{what} (ns)")
    ax.set_ylabel("ticks")
    ax.set_title(title + (f" ({hidden} ticks at or below 0 ns not shown)" if hidden else ""))
    ax.grid(True, alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) < 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help") else 2)
    src, prefix = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else src
    head, cols = read(src)
    out = [f"{prefix}-force.png", f"{prefix}-latency.png", f"{prefix}-compute.png"]
    plot_force(head, cols, out[0], title)
    plot_hist(cols["wake_latency_ns"], "wake-up latency", out[1], "wake-up latency")
    plot_hist(cols["compute_ns"], "compute time", out[2], "compute time")
    for o in out:
        print(f"plot-log: wrote {o}")


if __name__ == "__main__":
    main()
