#!/usr/bin/python3
"""Plots accuracy against run time from the CSV that `thaw bench accuracy` writes.

usage: plot_accuracy.py table.csv out.png

The CSV has one row per resolution per metric, with the header
    case,res,particles,steps,wall_s,metric,value,reference,error,gate
The plot shows each metric's error (log scale) against wall time (log scale), one line per metric
through its resolutions, each point labelled with its resolution and particle count, and each metric's
gate (the largest error the validation accepts) as a dashed line in the metric's colour.
"""

import csv
import math
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # headless: CI and servers have no display
import matplotlib.pyplot as plt  # noqa: E402  (must follow the backend choice)

COLUMNS = ["case", "res", "particles", "steps", "wall_s", "metric", "value", "reference", "error", "gate"]


def read_rows(path):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"{path}: missing columns: {', '.join(missing)}")
        rows = []
        for line, row in enumerate(reader, start=2):
            try:
                rows.append({
                    "case": row["case"],
                    "res": row["res"],
                    "particles": int(float(row["particles"])),
                    "wall_s": float(row["wall_s"]),
                    "metric": row["metric"],
                    # The sign of an error says nothing on a log scale; its size is what is compared.
                    "error": abs(float(row["error"])),
                    "gate": float(row["gate"]) if row["gate"].strip() else None,
                })
            except ValueError as e:
                sys.exit(f"{path}:{line}: {e}")
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


def short_count(n):
    if n >= 1_000_000:
        return f"{n / 1_000_000:.3g}M"
    if n >= 1_000:
        return f"{n / 1_000:.3g}k"
    return str(n)


def plot(rows, out_path):
    by_metric = defaultdict(list)
    for r in rows:
        by_metric[r["metric"]].append(r)

    # Log axes cannot show zero: an exact result is drawn at the floor and marked as such.
    positive = [r["error"] for r in rows if r["error"] > 0]
    floor = min(positive) / 10 if positive else 1e-12

    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=120)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (metric, points) in enumerate(by_metric.items()):
        colour = colours[i % len(colours)]
        points.sort(key=lambda r: r["wall_s"])
        xs = [r["wall_s"] for r in points]
        ys = [r["error"] if r["error"] > 0 else floor for r in points]
        ax.plot(xs, ys, "o-", color=colour, label=metric)
        for r, x, y in zip(points, xs, ys):
            text = f"res {r['res']}, {short_count(r['particles'])} particles"
            if r["error"] == 0:
                text += " (error 0)"
            ax.annotate(text, (x, y), textcoords="offset points", xytext=(5, 5), fontsize=7, color=colour)
        gates = {r["gate"] for r in points if r["gate"] is not None and r["gate"] > 0}
        for gate in sorted(gates):
            ax.axhline(gate, color=colour, linestyle="--", linewidth=1, label=f"{metric} gate {gate:g}")

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.margins(x=0.2)  # room for the labels right of the last points
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("error against reference")
    cases = list(dict.fromkeys(r["case"] for r in rows))
    ax.set_title(f"{', '.join(cases)}: accuracy against run time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_path)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__.strip().splitlines()[2])
    plot(read_rows(argv[1]), argv[2])


if __name__ == "__main__":
    main(sys.argv)
