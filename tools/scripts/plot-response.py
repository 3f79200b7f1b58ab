#!/usr/bin/python3
"""Plot an `irdm image export` CSV: the diagonal of R[s] (displacement per
newton held for one sample) and its running sum (the step response, which
settles to the static compliance).  usage: plot-response.py IN.csv OUT.png"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    src, dst = sys.argv[1], sys.argv[2]
    with open(src, newline="") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
    t = [r[1] for r in data]
    node = head[2].split("_")[0]
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for axis, name in enumerate("xyz"):
        col = head.index(f"{node}_u{name}_f{name}")
        r = [row[col] for row in data]
        step, acc = [], 0.0
        for v in r:
            acc += v
            step.append(acc)
        ax[0].plot(t, r, label=f"R_{name}{name}")
        ax[1].plot(t, step, label=f"sum R_{name}{name} (step response)")
    ax[0].set_ylabel("m/N per sample")
    ax[1].set_ylabel("m/N")
    ax[1].set_xlabel("t (s)")
    ax[0].set_title(f"{src}: response at {node} to its own force")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print(f"plot-response: wrote {dst}")


if __name__ == "__main__":
    main()
