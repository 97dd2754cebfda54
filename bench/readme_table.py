#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Helpers of bench/make_readme_table.sh (Python 3 standard library only).

  readme_table.py mesh2ply MESH OUT.ply
      Any .off or .ply triangle/polygon mesh to a binary PLY with float32
      x y z and triangles (polygons fan-triangulated). The same file is then
      the cloud (its vertices) and the reference, so positions match exactly.
  readme_table.py sample MESH.ply OUT.xyz COUNT SEED
      COUNT area-uniform points on a mesh written by mesh2ply, random.Random(SEED).
  readme_table.py table WORK_DIR README.md [PICTURE]
      Reads WORK_DIR/datasets.tsv and each WORK_DIR/<id>/results.csv and
      rewrites README.md between <!-- bench-table:begin --> and
      <!-- bench-table:end -->; PICTURE is the path of the bunny's picture.
  readme_table.py compare OLD.md NEW.md
      Compares the tables of two READMEs, ignoring time, time ratio and
      memory; exit status 1 when anything else differs.
"""
import bisect
import csv
import os
import random
import struct
import sys

# The PLY header parser lives with the other scripts.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))
from ply_header import read_ply_header  # noqa: E402

BEGIN = "<!-- bench-table:begin -->"
END = "<!-- bench-table:end -->"
METHODS = ["pcl_ms", "gp3", "poisson", "afsr"]
# Columns that change from run to run (compare skips them).
VOLATILE = {"time [s]", "× AFSR", "peak memory [MB]"}


def die(message):
    sys.exit("error: " + message)


# ---------------------------------------------------------------- meshes

PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
             "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I",
             "uint32": "I", "float": "f", "float32": "f", "double": "d", "float64": "d"}


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    try:
        fmt, header, body = read_ply_header(data, path)
    except ValueError as error:
        die(str(error))
    # (name, count, [(property, list count code or None, value code)])
    elements = [(element.name, element.count,
                 [(name, PLY_TYPES[kind[1]], PLY_TYPES[kind[2]]) if isinstance(kind, tuple)
                  else (name, None, PLY_TYPES[kind]) for name, kind in element.properties])
                for element in header]
    vertices, triangles = [], []
    if fmt == "ascii":
        tokens = data[body:].split()
        pos = 0

        def take(code):
            nonlocal pos
            pos += 1
            return float(tokens[pos - 1]) if code in "fd" else int(tokens[pos - 1])
    else:  # binary: read_ply_header knows no other formats
        order = "<" if fmt == "binary_little_endian" else ">"
        pos = body

        def take(code):
            nonlocal pos
            value = struct.unpack_from(order + code, data, pos)[0]
            pos += struct.calcsize(code)
            return value
    for name, count, properties in elements:
        for _ in range(count):
            values = {}
            for prop, count_code, code in properties:
                if count_code:
                    values[prop] = [take(code) for _ in range(take(count_code))]
                else:
                    values[prop] = take(code)
            if name == "vertex":
                vertices.append((values["x"], values["y"], values["z"]))
            elif name == "face":
                corners = values.get("vertex_indices", values.get("vertex_index", []))
                triangles += [(corners[0], corners[i], corners[i + 1])
                              for i in range(1, len(corners) - 1)]
    return vertices, triangles


def read_off(path):
    lines = []
    with open(path) as f:
        for line in f:
            words = line.split("#")[0].split()
            if words:
                lines.append(words)
    if not lines or not lines[0][0].endswith("OFF"):
        die(path + ": not an OFF file")
    header = lines[0][1:] or lines[1]
    rest = lines[1:] if lines[0][1:] else lines[2:]
    nv, nf = int(header[0]), int(header[1])
    vertices = [tuple(float(w) for w in words[:3]) for words in rest[:nv]]
    triangles = []
    for words in rest[nv:nv + nf]:
        corners = [int(w) for w in words[1:1 + int(words[0])]]
        triangles += [(corners[0], corners[i], corners[i + 1]) for i in range(1, len(corners) - 1)]
    return vertices, triangles


def mesh2ply(source, target):
    vertices, triangles = read_off(source) if source.lower().endswith(".off") else read_ply(source)
    if not triangles:
        die(source + ": no faces")
    with open(target, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nelement face %d\n"
                 "property list uchar int vertex_indices\nend_header\n"
                 % (len(vertices), len(triangles))).encode("ascii"))
        f.write(b"".join(struct.pack("<3f", *v) for v in vertices))
        f.write(b"".join(struct.pack("<B3i", 3, *t) for t in triangles))


def sample(mesh, target, count, seed):
    vertices, triangles = read_ply(mesh)
    cumulative, total = [], 0.0
    for a, b, c in triangles:
        a, b, c = vertices[a], vertices[b], vertices[c]
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        total += (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5
        cumulative.append(total)
    rng = random.Random(seed)
    with open(target, "w") as f:
        for _ in range(count):
            t = min(bisect.bisect_left(cumulative, rng.random() * total), len(triangles) - 1)
            s, r = rng.random(), rng.random()
            if s + r > 1:
                s, r = 1 - s, 1 - r
            a, b, c = (vertices[i] for i in triangles[t])
            f.write("%.9g %.9g %.9g\n" % tuple(a[i] + s * (b[i] - a[i]) + r * (c[i] - a[i])
                                                for i in range(3)))


# ---------------------------------------------------------------- table

LABELS = {"pcl_ms": "pcl_ms", "gp3": "PCL GP3", "poisson": "PCL Poisson", "afsr": "CGAL AFSR"}
HEADER = ["data set", "points", "method", "time [s]", "× AFSR", "peak memory [MB]", "recall",
          "boundary loops", "non-manifold edges / vertices", "components", "orientable",
          "mesh → GT mean [%]", "mesh → GT max [%]", "GT → mesh max [%]"]


def number(row, key):
    text = row.get(key, "")
    return float(text) if text not in ("", None) else None


def percent(value, digits):
    if value is None:
        return "–"
    return "inf" if value == float("inf") else "%.*f" % (digits, 100 * value)


def dataset_rows(work, spec):
    """Table rows of one data set (spec: a line of datasets.tsv)."""
    results = os.path.join(work, spec["id"], "results.csv")
    runs = {}
    if os.path.exists(results):
        with open(results, newline="") as f:
            runs = {row["method"]: row for row in csv.DictReader(f)}
    points = next((r["input_points"] for r in runs.values() if r.get("input_points")), "")
    afsr = runs.get("afsr", {})
    afsr_time = number(afsr, "time_s") if afsr.get("status") == "ok" else None
    rows = []
    for method in METHODS:
        first = not rows
        cells = ["**%s**" % spec["label"] if first else "",
                 "{:,}".format(int(points)) if first and points else "", LABELS[method]]
        run = runs.get(method)
        if run is None or run.get("status") != "ok":
            reason = "failed" if run is not None or runs else \
                "failed (pcl_ms_compare exit %s)" % spec["status"]
            rows.append(cells + [reason] + ["–"] * (len(HEADER) - 4))
            continue
        time = number(run, "time_s")
        gt = spec["gt"] == "yes"
        # Recall needs the mesh's vertices to be input points matching the
        # reference's vertices (not Poisson's new vertices).
        recall = number(run, "recall") if spec["recall"] == "yes" and number(
            run, "input_points_used") else None
        cells += [
            "%.2f" % time,
            "%.2f" % (time / afsr_time) if afsr_time else "–",
            "%.1f" % number(run, "peak_above_start_mb"),
            "%.2f %%" % (100 * recall) if recall is not None else "–",
            run["boundary_loops"],
            "%s / %s" % (run["non_manifold_edges"], run["non_manifold_vertices"]),
            run["components"],
            "yes" if run["orientable"] == "1" else "no",
            percent(number(run, "to_reference_mean"), 3) if gt else "–",
            percent(number(run, "to_reference_max"), 2) if gt else "–",
            percent(number(run, "from_reference_max"), 2) if gt else "–",
        ]
        rows.append(cells)
    return rows


def markdown_row(cells):
    return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"


def build_section(work, picture):
    with open(os.path.join(work, "datasets.tsv"), newline="") as f:
        specs = list(csv.DictReader(f, delimiter="\t", quoting=csv.QUOTE_NONE))
    lines = [BEGIN,
             "<!-- Generated by bench/make_readme_table.sh; edits here are overwritten. -->", "",
             "Data sets (ground truth = GT):", ""]
    for spec in specs:
        lines.append("- **%s**: %s. %s" % (spec["label"], spec["input"], spec["why"]))
    lines += ["", markdown_row(HEADER), "|" + "---|" * len(HEADER)]
    for spec in specs:
        lines += [markdown_row(cells) for cells in dataset_rows(work, spec)]
    lines += ["",
              "Time is wall-clock seconds of the method alone (GP3 and Poisson include normal "
              "estimation and orientation), single-threaded; × AFSR divides it by CGAL AFSR's "
              "time in the same run. Peak memory is the method's child process's peak above "
              "its resident memory at the start. Recall is the share of GT triangles "
              "recovered exactly, given only where the cloud is the GT's vertices (Poisson "
              "makes new vertices, so it has none). Distances are percentages of the GT's "
              "bounding-box diagonal: mesh → GT mean and max measure surface the method "
              "invented, GT → mesh max the largest part of the GT it missed. Every other "
              "metric is in `results.md` of each data set's output directory."]
    if picture:
        lines += ["", "The bunny, as `pcl_ms_compare` draws it (boundary edges blue, "
                  "non-manifold edges red):", "", "![%s](%s)" % ("bunny side by side", picture)]
    lines.append(END)
    return "\n".join(lines)


def split_readme(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    begin, end = text.find(BEGIN), text.find(END)
    if begin < 0 or end < begin:
        die("%s: markers %s and %s not found" % (path, BEGIN, END))
    return text[:begin], text[begin:end + len(END)], text[end + len(END):]


def table(work, readme, picture):
    before, _, after = split_readme(readme)
    with open(readme, "w", encoding="utf-8") as f:
        f.write(before + build_section(work, picture) + after)


def stable_cells(section):
    """Every table row of a section with the volatile columns blanked."""
    rows, header = [], None
    for line in section.splitlines():
        if not line.startswith("|") or line.startswith("|---"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        if header is None:
            header = cells
            continue
        rows.append([c for name, c in zip(header, cells) if name not in VOLATILE])
    return rows


def compare(old, new):
    a, b = stable_cells(split_readme(old)[1]), stable_cells(split_readme(new)[1])
    differences = [(x, y) for x, y in zip(a, b) if x != y]
    if len(a) != len(b):
        print("row counts differ: %d and %d" % (len(a), len(b)))
    for x, y in differences:
        print("- " + " | ".join(x) + "\n+ " + " | ".join(y))
    if differences or len(a) != len(b) or not a:
        return 1
    print("%d rows match apart from time and memory" % len(a))
    return 0


def main(argv):
    if len(argv) == 4 and argv[1] == "mesh2ply":
        mesh2ply(argv[2], argv[3])
    elif len(argv) == 6 and argv[1] == "sample":
        sample(argv[2], argv[3], int(argv[4]), int(argv[5]))
    elif len(argv) in (4, 5) and argv[1] == "table":
        table(argv[2], argv[3], argv[4] if len(argv) == 5 else "")
    elif len(argv) == 4 and argv[1] == "compare":
        return compare(argv[2], argv[3])
    else:
        sys.exit(__doc__)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
