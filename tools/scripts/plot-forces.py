#!/usr/bin/python3
"""Plot an `irdm replay` CSV: each contact's force on the object (N) against
time, and the device's force (its negative) magnitude.
usage: plot-forces.py FORCES.csv OUT.png [title]"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    src, dst = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else src
    with open(src, newline="") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
    t = [r[0] for r in data]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, name in enumerate(head):
        if name.startswith("c") and "_f" in name:
            ax.plot(t, [r[k] for r in data], label=name + " (N, on the object)", lw=1)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("force (N)")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print(f"plot-forces: wrote {dst}")


if __name__ == "__main__":
    main()
