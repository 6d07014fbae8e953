#!/usr/bin/python3
"""One plot of error against wall time for several `thaw bench accuracy` runs of a case (e.g. one per
solver): the worst error over the gated metrics at each resolution, against the run's wall seconds.

    tools/compare_accuracy.py [--metric NAME] OUT.png LABEL=DIR/CASE-accuracy.csv [LABEL=...]

With --metric, the curve is that metric's error alone (e.g. the cavity's nusselt_hot).
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def worst_by_res(path, metric=None):
    rows = defaultdict(lambda: [0.0, 0.0, 0])  # res -> [wall_s, worst error/gate... , particles]
    worst = defaultdict(float)
    for r in csv.DictReader(open(path)):
        res = int(r["res"])
        rows[res][0] = float(r["wall_s"])
        rows[res][2] = int(r["particles"])
        # Positions as relative errors; the shift is not an error in Z, so it is left out of the curve.
        if metric is not None:
            if r["metric"] == metric:
                worst[res] = float(r["error"])
        elif "shift_dT" not in r["metric"]:
            worst[res] = max(worst[res], float(r["error"]))
    return sorted((res, rows[res][0], worst[res], rows[res][2]) for res in rows)


def main(out, specs, metric=None):
    fig, ax = plt.subplots(figsize=(6, 4))
    for spec in specs:
        label, path = spec.split("=", 1)
        pts = worst_by_res(path, metric)
        ax.plot([p[1] for p in pts], [100 * p[2] for p in pts], "o-", label=label)
        for res, wall, err, _ in pts:
            ax.annotate(f"res {res}", (wall, 100 * err), textcoords="offset points", xytext=(4, 4), fontsize=7)
        print(label + ": " + ", ".join(f"res {r}: {w:.2f} s, {100 * e:.1f} %" for r, w, e, _ in pts))
    ax.set_xscale("log")
    ax.set_xlabel("wall seconds")
    ax.set_ylabel(f"relative error of {metric} [%]" if metric else "worst relative error of the gated metrics [%]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote " + out)


if __name__ == "__main__":
    args = sys.argv[1:]
    metric = None
    if args and args[0] == "--metric":
        if len(args) < 2:
            sys.exit(__doc__)
        metric, args = args[1], args[2:]
    if len(args) < 2:
        sys.exit(__doc__)
    main(args[0], args[1:], metric)
