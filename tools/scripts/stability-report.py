#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The stability suite's table and plot (make stability).

Reads DIR/cases.tsv and DIR/trace-*.tsv that the stability tests write with
IRDM_STAB_OUT=DIR, prints a Markdown table of every case (also DIR/table.md)
and plots the force and the work on the object of the worst cases (the
largest peak force against its limit) into DIR/worst.png.
"""
import csv
import os
import re
import sys

COLS = ["case", "ticks", "max_f", "limit_f", "held_f", "static_f", "w_min", "w_max", "e_tol",
        "nonfinite", "subnormal", "refusal", "refusal_tick", "ns_first", "ns_last", "note"]


def slug(name):
    return re.sub(r"[^A-Za-z0-9]", "_", name)


def read_cases(d):
    with open(os.path.join(d, "cases.tsv")) as f:
        return [dict(zip(COLS, row)) for row in csv.reader(f, delimiter="\t")]


def table(rows):
    out = ["| case | ticks | max abs(F) N | limit N | held N | static N | min W J | max W J "
           "| NaN/Inf | subnormal | refusal | ns/tick first/last |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|"]
    for r in rows:
        ref = "-" if r["refusal"] == "-" else "%s (tick %s)" % (r["refusal"], r["refusal_tick"])
        out.append("| %s | %s | %.4g | %.4g | %.6g | %s | %.3g | %.3g | %s | %s | %s | %.0f / %.0f |" % (
            r["case"], r["ticks"], float(r["max_f"]), float(r["limit_f"]), float(r["held_f"]),
            "-" if r["static_f"] == "nan" else "%.6g" % float(r["static_f"]),
            float(r["w_min"]), float(r["w_max"]), r["nonfinite"], r["subnormal"], ref,
            float(r["ns_first"]), float(r["ns_last"])))
    return "\n".join(out) + "\n"


def plot(d, rows, n=4):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    worst = sorted(rows, key=lambda r: -float(r["max_f"]) / float(r["limit_f"]))[:n]
    fig, ax = plt.subplots(2, len(worst), figsize=(4.2 * len(worst), 6.5), squeeze=False)
    for i, r in enumerate(worst):
        path = os.path.join(d, "trace-%s.tsv" % slug(r["case"]))
        if not os.path.exists(path):
            continue
        t, f, w = [], [], []
        with open(path) as fh:
            for line in fh:
                if line[0] in "#t":
                    continue
                a, b, c = line.split("\t")
                t.append(float(a))
                f.append(float(b))
                w.append(float(c))
        ax[0][i].plot(t, f, lw=0.8)
        ax[0][i].axhline(float(r["limit_f"]), color="r", ls="--", lw=0.8, label="asserted limit")
        ax[0][i].set_title("%s\nmax %.4g N / limit %.4g N" % (r["case"], float(r["max_f"]),
                                                             float(r["limit_f"])), fontsize=8)
        ax[0][i].set_ylabel("sum |F| (N)")
        ax[0][i].legend(fontsize=7)
        ax[1][i].plot(t, w, lw=0.8, color="g")
        ax[1][i].axhline(0, color="k", lw=0.5)
        ax[1][i].set_ylabel("work on the object W (J)")
        ax[1][i].set_xlabel("t (s)")
        ax[1][i].set_title("min W %.3g J" % float(r["w_min"]), fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "worst.png"), dpi=110)


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "out/stability"
    rows = read_cases(d)
    md = table(rows)
    with open(os.path.join(d, "table.md"), "w") as f:
        f.write(md)
    sys.stdout.write(md)
    plot(d, rows)
    print("\nwrote %s/table.md and %s/worst.png" % (d, d))


if __name__ == "__main__":
    main()
