#!/usr/bin/python3
"""Pareto plots of an `irdm report` CSV: each representation's worst
relative RMS force error over the scenarios against its tick time (median,
worst scenario) and against its image bytes, and the step's settled error
(from tick 100 on) against the tick time; the stable ones' Pareto front
drawn, the unstable ones as crosses, the paper's setting starred; errors
over 1000 % drawn at the top edge.
usage: plot-report.py REPORT-NAME.csv OUT-PREFIX
writes OUT-PREFIX-tick.png, OUT-PREFIX-bytes.png, and OUT-PREFIX-settled.png
if the configuration has the step (the floating one has not)"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


TOP = 10.0      # errors above are drawn at the top edge


def load(path):
    """One entry per (repr, dt): worst force error, worst tick median, bytes, stable."""
    reps, paper = {}, None
    with open(path) as f:
        for r in csv.DictReader(f):
            key = (r["repr"], float(r["dt_ms"]))
            e = reps.setdefault(key, {"err": 0.0, "tick": 0.0, "bytes": int(r["image_bytes"]),
                                      "stable": True, "settled": float("nan")})
            e["err"] = min(TOP, max(e["err"], float(r["force_err"])))
            if r["scenario"] == "step":
                e["settled"] = min(TOP, float(r["force_err_after100"]))
            e["tick"] = max(e["tick"], float(r["tick_median_us"]))
            e["stable"] &= r["cert_stable"] == "1" and r["run_bounded"] == "1"
            if r["paper"] == "1":
                paper = key
    return reps, paper


def pareto(points):
    """Points no other point beats in both coordinates, by x."""
    front, best = [], float("inf")
    for x, y in sorted(points):
        if y < best:
            front.append((x, y))
            best = y
    return front


def plot(reps, xkey, xlabel, out, paper, ykey="err",
         ylabel="relative RMS force error, worst scenario, whole run"):
    fig, ax = plt.subplots(figsize=(8, 5.5))
    colours = {1.0: "tab:blue", 2.0: "tab:orange"}
    for (name, dt), e in sorted(reps.items()):
        c = colours.get(dt, "tab:green")
        fir = name.startswith("fir")
        if e["stable"]:
            ax.plot(e[xkey], e[ykey], "^" if fir else "o", color=c, ms=6)
        else:
            ax.plot(e[xkey], e[ykey], "x", color="tab:red", ms=7)
        ax.annotate(name, (e[xkey], e[ykey]), fontsize=6, xytext=(3, 2),
                    textcoords="offset points")
    for dt, c in colours.items():
        front = pareto([(e[xkey], e[ykey]) for (n, d), e in reps.items()
                        if d == dt and e["stable"]])
        if front:
            ax.step(*zip(*front), where="post", color=c, lw=1,
                    label="stable, dt %g ms: Pareto front" % dt)
    if paper in reps:
        e = reps[paper]
        ax.plot(e[xkey], e[ykey], "*", color="black", ms=16, mfc="none",
                label="the paper's setting (%s, %g ms)" % paper)
    ax.plot([], [], "x", color="tab:red", label="unstable recursion")
    ax.plot([], [], "^", color="grey", label="FIR")
    ax.plot([], [], "o", color="grey", label="modal")
    ax.axhline(0.01, color="grey", lw=0.5, ls="--")
    ax.axhline(0.001, color="grey", lw=0.5, ls=":")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    reps, paper = load(sys.argv[1])
    if not reps:
        sys.exit("plot-report.py: %s: no rows" % sys.argv[1])
    plot(reps, "tick", "force tick, median (us, worst scenario)", sys.argv[2] + "-tick.png", paper)
    plot(reps, "bytes", "image bytes", sys.argv[2] + "-bytes.png", paper)
    if any(e["settled"] == e["settled"] for e in reps.values()):
        plot(reps, "tick", "force tick, median (us, worst scenario)", sys.argv[2] + "-settled.png",
             paper, "settled", "relative RMS force error, the step from tick 100 on")


if __name__ == "__main__":
    main()
