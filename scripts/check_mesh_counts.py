#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Independent recount of what pcl_ms_compare reports for one mesh.

Reads a mesh PLY written by pcl_ms_compare and the reference PLY, counts with
numpy alone (no pcl_ms code) the reference triangles recovered (vertex
positions matched exactly), triangles in the reference, edges, boundary and
non-manifold edges, non-manifold vertices, boundary loops and components,
and compares them with the method's row of results.csv.

    python3 scripts/check_mesh_counts.py compare_out/afsr.ply data/bun_zipper.ply \\
        --csv compare_out/results.csv --method afsr

Exit status 0 when every count agrees, 1 when one differs, 2 on bad input.
A manual acceptance check: it needs numpy and is not part of CI.
"""

import argparse
import csv
import sys

import numpy as np

from ply_header import read_ply_header

SCALARS = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path):
    """Vertex positions (float64, n x 3) and triangles (int64, m x 3) of a PLY."""
    with open(path, "rb") as f:
        data = f.read()
    fmt, header, offset = read_ply_header(data, path)
    body = data[offset:]
    # name, count, props: (property, value type, list index type or None)
    elements = [{"name": element.name, "count": element.count,
                 "props": [(name, SCALARS[kind[1]], SCALARS[kind[2]]) if isinstance(kind, tuple)
                           else (name, SCALARS[kind], None)
                           for name, kind in element.properties]}
                for element in header]
    order = "<" if fmt != "binary_big_endian" else ">"
    tokens = body.split() if fmt == "ascii" else None
    at = 0
    vertices = triangles = None
    for element in elements:
        props, count = element["props"], element["count"]
        if fmt == "ascii":
            rows = []
            for _ in range(count):
                row = []
                for _, _, index_type in props:
                    if index_type is None:
                        row.append(float(tokens[at]))
                        at += 1
                    else:
                        n = int(tokens[at])
                        row.append([int(t) for t in tokens[at + 1:at + 1 + n]])
                        at += 1 + n
                rows.append(row)
            values = {name: [r[k] for r in rows] for k, (name, _, _) in enumerate(props)}
        elif all(index_type is None for _, _, index_type in props):
            dtype = np.dtype([(name, order + t) for name, t, _ in props])
            table = np.frombuffer(body, dtype=dtype, count=count, offset=at)
            at += dtype.itemsize * count
            values = {name: table[name] for name, _, _ in props}
        else:  # lists: walk the records (count type, then that many indices)
            values = {name: [] for name, _, _ in props}
            for _ in range(count):
                for name, t, index_type in props:
                    if index_type is None:
                        size = np.dtype(t).itemsize
                        values[name].append(np.frombuffer(body, order + t, 1, at)[0])
                        at += size
                    else:
                        n = int(np.frombuffer(body, order + t, 1, at)[0])
                        at += np.dtype(t).itemsize
                        values[name].append(np.frombuffer(body, order + index_type, n, at))
                        at += np.dtype(index_type).itemsize * n
        if element["name"] == "vertex":
            vertices = np.column_stack([np.asarray(values[c], dtype=np.float64) for c in "xyz"])
        elif element["name"] == "face":
            name = next(n for n, _, index_type in props if index_type is not None)
            faces = []
            for polygon in values[name]:
                polygon = [int(i) for i in polygon]
                faces.extend([polygon[0], polygon[k], polygon[k + 1]]
                             for k in range(1, len(polygon) - 1))
            triangles = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if vertices is None or triangles is None:
        raise ValueError(f"{path}: needs vertex and face elements")
    if len(triangles) and (triangles.min() < 0 or triangles.max() >= len(vertices)):
        raise ValueError(f"{path}: a face indexes a missing vertex")
    return vertices, triangles


def position_keys(mesh_vertices, reference_vertices):
    """One integer per distinct position, shared by both meshes."""
    both = np.vstack([mesh_vertices, reference_vertices])
    _, ids = np.unique(both, axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    return ids[:len(mesh_vertices)], ids[len(mesh_vertices):]


def triangle_sets(triangles, ids):
    """Sorted position triples of the triangles with three distinct positions."""
    triples = np.sort(ids[triangles], axis=1)
    return [tuple(t) for t in triples if t[0] != t[1] and t[1] != t[2]]


class UnionFind:
    def __init__(self, size):
        self.parent = list(range(size))

    def find(self, x):
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a, b):
        a, b = self.find(a), self.find(b)
        if a != b:
            self.parent[max(a, b)] = min(a, b)


def topology(vertices, triangles):
    """Edge, manifold, boundary and component counts over vertex indices."""
    faces = [tuple(t) for t in triangles.tolist() if len(set(t)) == 3]
    edge_faces = {}
    for f, (a, b, c) in enumerate(faces):
        for u, v in ((a, b), (b, c), (c, a)):
            edge_faces.setdefault((min(u, v), max(u, v)), []).append(f)
    boundary = [e for e, fs in edge_faces.items() if len(fs) == 1]
    non_manifold = {e for e, fs in edge_faces.items() if len(fs) > 2}

    # Components: triangles joined through shared edges.
    components = UnionFind(len(faces))
    for fs in edge_faces.values():
        for f in fs[1:]:
            components.union(fs[0], f)
    component_count = len({components.find(f) for f in range(len(faces))})

    # Non-manifold vertices: on no non-manifold edge, yet their triangles
    # form more than one fan (triangles joined through edges at the vertex).
    on_bad_edge = {v for e in non_manifold for v in e}
    around = {}
    for f, face in enumerate(faces):
        for v in face:
            around.setdefault(v, []).append(f)
    pinched = 0
    for v, fs in around.items():
        if v in on_bad_edge or len(fs) == 1:
            continue
        local = {f: k for k, f in enumerate(fs)}
        fans = UnionFind(len(fs))
        for f in fs:
            for w in faces[f]:
                if w != v:
                    for g in edge_faces[(min(v, w), max(v, w))]:
                        fans.union(local[f], local[g])
        pinched += len({fans.find(k) for k in range(len(fs))}) > 1

    # Boundary loops: components of the boundary-edge graph; the same as
    # loops when no vertex has more than two boundary edges.
    boundary_vertices = sorted({v for e in boundary for v in e})
    index = {v: k for k, v in enumerate(boundary_vertices)}
    loops = UnionFind(len(boundary_vertices))
    degree = {}
    for u, v in boundary:
        loops.union(index[u], index[v])
        degree[u] = degree.get(u, 0) + 1
        degree[v] = degree.get(v, 0) + 1
    loop_count = len({loops.find(k) for k in range(len(boundary_vertices))})
    simple = all(d == 2 for d in degree.values())

    referenced = len(around)
    return {
        "triangles": len(triangles),
        "referenced_vertices": referenced,
        "edges": len(edge_faces),
        "boundary_edges": len(boundary),
        "non_manifold_edges": len(non_manifold),
        "non_manifold_vertices": pinched,
        "boundary_loops": loop_count if simple else None,
        "components": component_count,
        "euler_characteristic": referenced - len(edge_faces) + len(faces),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh")
    parser.add_argument("reference")
    parser.add_argument("--csv", help="results.csv of pcl_ms_compare")
    parser.add_argument("--method", help="row of results.csv to compare with (e.g. afsr)")
    args = parser.parse_args()
    try:
        vertices, triangles = read_ply(args.mesh)
        reference_vertices, reference_triangles = read_ply(args.reference)
    except (OSError, ValueError, KeyError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2

    ids, reference_ids = position_keys(vertices, reference_vertices)
    ours = triangle_sets(triangles, ids)
    theirs = triangle_sets(reference_triangles, reference_ids)
    our_set, reference_set = set(ours), set(theirs)
    recovered = sum(t in our_set for t in theirs)
    in_reference = sum(t in reference_set for t in ours)
    counts = topology(vertices, triangles)
    counts.update({
        "reference_triangles": len(reference_triangles),
        "recovered_reference_triangles": recovered,
        "triangles_in_reference": in_reference,
        "recall": recovered / len(reference_triangles) if len(reference_triangles) else 0.0,
        "precision": in_reference / len(triangles) if len(triangles) else 0.0,
    })

    row = None
    if args.csv:
        with open(args.csv, newline="") as f:
            rows = [r for r in csv.DictReader(f) if r["method"] == args.method]
        if len(rows) != 1:
            print(f"error: {args.csv} has no row for method {args.method!r}", file=sys.stderr)
            return 2
        row = rows[0]

    print(f"{'count':32} {'independent':>14} {'pcl_ms_compare':>16}")
    agree = True
    for key, value in counts.items():
        reported = row.get(key, "") if row else ""
        shown = "n/a (not simple)" if value is None else (
            f"{value:.9f}" if isinstance(value, float) else str(value))
        mark = ""
        if row and value is not None and reported != "":
            same = (abs(float(reported) - value) <= 1e-8 if isinstance(value, float)
                    else int(float(reported)) == value)
            mark = "  ok" if same else "  DIFFERENT"
            agree = agree and same
        print(f"{key:32} {shown:>14} {reported:>16}{mark}")
    if row:
        print("all counts agree" if agree else "counts differ")
    return 0 if agree else 1


if __name__ == "__main__":
    sys.exit(main())
