#!/usr/bin/python3
"""Plot fir-tail-compare.sh's replays: the z force of the exact model, the
r^s-damped FIR and the windowed FIR over 12 s (top), and each FIR's error
against the exact force (bottom, log scale).
usage: plot-fir-tail.py DIR OUT.png"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def fz(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    col = rows[0].index("c1_fz")
    return [float(r[0]) for r in rows[1:]], [float(r[col]) for r in rows[1:]]


def main():
    d, dst = sys.argv[1], sys.argv[2]
    t, ex = fz(d + "/exact.csv")
    runs = [("FIR 500, tail damped by r^s (old)", fz(d + "/rs.csv")[1]),
            ("FIR 500 + window:1000 (new)", fz(d + "/window.csv")[1])]
    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    a.plot(t, ex, "k", lw=1.5, label="exact (all modes)")
    for name, f in runs:
        a.plot(t, f, lw=1, label=name)
    a.set_ylabel("z force on the object (N)")
    a.set_ylim(2.5 * ex[-1], -0.2 * ex[-1])      # the held force and its ringing
    a.legend(fontsize=8)
    a.grid(True, alpha=0.3)
    for name, f in runs:
        b.semilogy(t, [abs(x - y) + 1e-16 for x, y in zip(f, ex)], lw=1, label=name)
    b.axvline(1.0, color="grey", ls=":", lw=1)
    b.set_xlabel("t (s): 1 cm held from t = 0; the FIR head is T = 500 samples = 1 s")
    b.set_ylabel("|F - F exact| (N)")
    b.legend(fontsize=8)
    b.grid(True, alpha=0.3)
    fig.suptitle("Paper's cuboid at 4x4x8 cells, 2 ms, top centre pushed 1 cm and held")
    fig.tight_layout()
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main()
