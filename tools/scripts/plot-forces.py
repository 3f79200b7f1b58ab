#!/usr/bin/python3
"""Plot an `irdm replay` CSV (or `irdm render`'s DIR/forces.csv), as the paper's
force plots (Fig. 6 and 10): each contact's force on the object (N) against
time, its components above and its magnitude below, with the contact's last
touch (the release) marked; the device renders the negative.  Node columns
(--nodes: n<N>_ux..) add a panel of their displacement: the object ringing
after the release, where the force is zero.
usage: plot-forces.py FORCES.csv OUT.png [title]"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def main():
    if len(sys.argv) < 3:
        sys.exit("plot-forces: usage: " + __doc__.strip().split("usage: ")[-1])
    src, dst = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else src
    with open(src, newline="") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], np.array([[float(x) for x in r] for r in rows[1:]])
    if data.size == 0:
        sys.exit(f"plot-forces: {src}: no samples")
    t = data[:, 0]
    contacts = sorted({name.split("_")[0] for name in head if name.startswith("c") and "_f" in name})
    nodes = sorted({name.rsplit("_", 1)[0] for name in head if name.startswith("n") and "_u" in name},
                   key=lambda n: int(n[1:]))[:4]
    fig, axes = plt.subplots(3 if nodes else 2, 1, figsize=(8, 9 if nodes else 6.5), sharex=True)
    ax, axm = axes[0], axes[1]
    for c in contacts:
        cols = [head.index(f"{c}_f{a}") for a in "xyz"]
        for k, a in zip(cols, "xyz"):
            ax.plot(t, data[:, k], label=f"{c} f{a}", lw=1)
        mag = np.linalg.norm(data[:, cols], axis=1)
        axm.plot(t, mag, label=f"{c} |F|", lw=1.2)
        touching = np.nonzero(mag > 0)[0]
        if len(touching) and touching[-1] + 1 < len(t):
            t_off = t[touching[-1] + 1]
            for a in axes:
                a.axvline(t_off, color="grey", ls="--", lw=0.8)
            axm.annotate(f"{c} released at {t_off:.3f} s", (t_off, mag.max() * 0.9), fontsize=8,
                         xytext=(5, 0), textcoords="offset points")
    for n in nodes:
        for a in "xyz":
            u = data[:, head.index(f"{n}_u{a}")] * 1e3
            if np.abs(u).max() > 0:
                axes[2].plot(t, u, label=f"node {n[1:]} u{a}", lw=1)
    if nodes:
        axes[2].set_ylabel("displacement (mm)")
    ax.set_ylabel("force on the object (N)")
    ax.set_title(title)
    axm.set_ylabel("|force| (N)")
    axes[-1].set_xlabel("t (s)")
    for a in axes:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print(f"plot-forces: wrote {dst}")


if __name__ == "__main__":
    main()
