#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The topology table of scripts/topology_table.sh (Python 3 standard library only).

  topology_table.py OUT_DIR
      Reads OUT_DIR/clouds/truth.csv (bench/make_synthetic_clouds) and each
      OUT_DIR/<name>/results.csv (pcl_ms_compare) and prints one markdown row
      per cloud for the truth and one per method that was run.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from readme_table import LABELS, markdown_row  # noqa: E402

HEADER = ["cloud", "points", "method", "components", "boundary loops",
          "non-manifold edges / vertices", "Euler χ", "orientable", "topology right"]
# (truth.csv column, results.csv column) that must agree for "topology right".
COMPARED = [("components", "components"), ("boundary_loops", "boundary_loops"),
            ("euler_characteristic", "euler_characteristic"), ("orientable", "orientable")]


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def yes_no(flag):
    return "yes" if flag == "1" else "no"


def cloud_rows(out_dir, truth):
    rows = [["**%s**" % truth["name"], "{:,}".format(int(truth["points"])), "truth",
             truth["components"], truth["boundary_loops"], "0 / 0",
             truth["euler_characteristic"], yes_no(truth["orientable"]), ""]]
    results = os.path.join(out_dir, truth["name"], "results.csv")
    runs = read_csv(results) if os.path.exists(results) else []
    if not runs:
        rows.append(["", "", "–", "no results.csv"] + ["–"] * (len(HEADER) - 4))
    for run in runs:
        label = LABELS.get(run["method"], run["method"])
        if run.get("status") != "ok":
            rows.append(["", "", label, "failed: " + run.get("error", "")] +
                        ["–"] * (len(HEADER) - 4))
            continue
        right = all(truth[t] == run[r] for t, r in COMPARED) and \
            run["non_manifold_edges"] == "0" and run["non_manifold_vertices"] == "0"
        rows.append(["", "", label, run["components"], run["boundary_loops"],
                     "%s / %s" % (run["non_manifold_edges"], run["non_manifold_vertices"]),
                     run["euler_characteristic"], yes_no(run["orientable"]),
                     "yes" if right else "no"])
    return rows


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        sys.exit(__doc__)
    out_dir = argv[1]
    truth_path = os.path.join(out_dir, "clouds", "truth.csv")
    if not os.path.exists(truth_path):
        sys.exit("error: %s not found" % truth_path)
    print(markdown_row(HEADER))
    print("|" + "---|" * len(HEADER))
    for truth in read_csv(truth_path):
        for cells in cloud_rows(out_dir, truth):
            print(markdown_row(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
