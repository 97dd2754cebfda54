#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Regenerate the sample data in data/ from the shared data collection.

Usage: python3 scripts/make_sample_data.py [SHARED_DATA_DIR] [-o OUT_DIR]

SHARED_DATA_DIR defaults to ../shared/data relative to the repository root,
OUT_DIR to data/ in the repository. Pure standard library (no numpy).

Outputs:
  bunny.pcd      vertices of stanford_bunny/reconstruction/bun_zipper.ply,
                 in file order, PCD v0.7 binary, x y z float32
  bun_zipper.ply the same mesh as binary_little_endian PLY (float x y z,
                 list uchar int vertex_indices); vertex positions are the
                 same float32 values as in bunny.pcd
  bun000.pcd     vertices of the raw scan stanford_bunny/data/bun000.ply
                 (the range_grid element is dropped), PCD v0.7 binary
  bun0.pcd       byte copy of pcl/bun0.pcd
"""

import argparse
import os
import shutil
import struct
import sys

from ply_header import read_ply_header

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_ascii_ply(path):
    """Parses an ASCII PLY file.

    Returns (elements, data) where data maps element name to a list of rows;
    a row is a list of the property values as strings (list properties are
    kept as a Python list of strings)."""
    with open(path, "rb") as handle:
        raw = handle.read()
    fmt, elements, body = read_ply_header(raw, path)
    if fmt != "ascii":
        raise ValueError(f"{path}: expected an ASCII PLY, got format {fmt}")
    # The body is a stream of whitespace-separated tokens; list lengths
    # decide how many tokens a row takes.
    tokens = raw[body:].decode("ascii").split()
    data = {}
    pos = 0
    for element in elements:
        rows = []
        for _ in range(element.count):
            row = []
            for _, ptype in element.properties:
                if isinstance(ptype, tuple):
                    n = int(tokens[pos])
                    row.append(tokens[pos + 1:pos + 1 + n])
                    pos += 1 + n
                else:
                    row.append(tokens[pos])
                    pos += 1
            rows.append(row)
        data[element.name] = rows
    if pos != len(tokens):
        raise ValueError(f"{path}: {len(tokens) - pos} trailing tokens after the last element")
    return elements, data


def xyz_float32(rows, path):
    """Packs the first three columns of each row as little-endian float32."""
    out = bytearray()
    pack = struct.Struct("<3f").pack
    for row in rows:
        out += pack(float(row[0]), float(row[1]), float(row[2]))
    if len(out) != 12 * len(rows):
        raise ValueError(f"{path}: packing error")
    return bytes(out)


def vertex_xyz(elements, data, path):
    vertex = next((e for e in elements if e.name == "vertex"), None)
    if vertex is None:
        raise ValueError(f"{path}: no vertex element")
    names = [name for name, _ in vertex.properties]
    if names[:3] != ["x", "y", "z"]:
        raise ValueError(f"{path}: vertex properties start with {names[:3]}, expected x y z")
    return vertex.count, xyz_float32(data["vertex"], path)


def write_pcd_xyz(path, count, xyz_bytes):
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\n"
        "VERSION 0.7\n"
        "FIELDS x y z\n"
        "SIZE 4 4 4\n"
        "TYPE F F F\n"
        "COUNT 1 1 1\n"
        f"WIDTH {count}\n"
        "HEIGHT 1\n"
        "VIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {count}\n"
        "DATA binary\n"
    )
    with open(path, "wb") as handle:
        handle.write(header.encode("ascii"))
        handle.write(xyz_bytes)


def write_binary_ply_mesh(path, count, xyz_bytes, faces, comment):
    header = (
        "ply\n"
        "format binary_little_endian 1.0\n"
        f"comment {comment}\n"
        f"element vertex {count}\n"
        "property float x\n"
        "property float y\n"
        "property float z\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\n"
        "end_header\n"
    )
    body = bytearray()
    for face in faces:
        n = len(face)
        if n > 255:
            raise ValueError(f"face with {n} vertices does not fit a uchar count")
        indices = [int(i) for i in face]
        for i in indices:
            if not 0 <= i < count:
                raise ValueError(f"face index {i} out of range (vertex count {count})")
        body += struct.pack(f"<B{n}i", n, *indices)
    with open(path, "wb") as handle:
        handle.write(header.encode("ascii"))
        handle.write(xyz_bytes)
        handle.write(body)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("shared_data", nargs="?",
                        default=os.path.join(REPO_ROOT, "..", "shared", "data"),
                        help="the shared data folder (default: ../shared/data from the repo root)")
    parser.add_argument("-o", "--output", default=os.path.join(REPO_ROOT, "data"),
                        help="output folder (default: data/ in the repo)")
    args = parser.parse_args(argv)

    src = os.path.abspath(args.shared_data)
    out = os.path.abspath(args.output)
    if not os.path.isdir(src):
        print(f"error: shared data folder not found: {src}", file=sys.stderr)
        return 1
    os.makedirs(out, exist_ok=True)

    # 1. Reference mesh -> bunny.pcd + bun_zipper.ply (binary).
    zipper = os.path.join(src, "stanford_bunny", "reconstruction", "bun_zipper.ply")
    elements, data = read_ascii_ply(zipper)
    count, xyz = vertex_xyz(elements, data, zipper)
    face_element = next((e for e in elements if e.name == "face"), None)
    if face_element is None:
        raise ValueError(f"{zipper}: no face element")
    faces = [row[0] for row in data["face"]]
    write_pcd_xyz(os.path.join(out, "bunny.pcd"), count, xyz)
    write_binary_ply_mesh(os.path.join(out, "bun_zipper.ply"), count, xyz, faces,
                          "Stanford bunny zipper reconstruction (Stanford Computer Graphics Laboratory)")
    print(f"bunny.pcd: {count} points; bun_zipper.ply: {count} vertices, {len(faces)} faces")

    # 2. Raw range scan -> bun000.pcd (vertices only).
    scan = os.path.join(src, "stanford_bunny", "data", "bun000.ply")
    elements, data = read_ascii_ply(scan)
    count, xyz = vertex_xyz(elements, data, scan)
    write_pcd_xyz(os.path.join(out, "bun000.pcd"), count, xyz)
    print(f"bun000.pcd: {count} points")

    # 3. PCL's sparse bunny, byte for byte.
    shutil.copyfile(os.path.join(src, "pcl", "bun0.pcd"), os.path.join(out, "bun0.pcd"))
    print("bun0.pcd: copied")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
