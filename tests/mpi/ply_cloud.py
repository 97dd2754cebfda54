#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Usage: ply_cloud.py MESH.ply CLOUD.ply [--camera]

Writes the vertices of a binary little-endian PLY mesh as a PLY cloud: the
vertex element alone, as it is, and with --camera the fixed-size camera
element PCL's cloud writer appends. The MPI tool reads such clouds in parts.
"""
import struct
import sys

SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2,
         "int16": 2, "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4,
         "float": 4, "float32": 4, "double": 8, "float64": 8}
CAMERA = ["view_px", "view_py", "view_pz", "x_axisx", "x_axisy", "x_axisz", "y_axisx",
          "y_axisy", "y_axisz", "z_axisx", "z_axisy", "z_axisz"]


def main(source, target, camera):
    with open(source, "rb") as stream:
        data = stream.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in lines:
        sys.exit(f"{source}: not a binary little-endian PLY file")
    header, count, record, in_vertex, elements = [], 0, 0, False, 0
    for line in lines:
        words = line.split() or [""]
        if words[0] == "element":
            elements += 1
            in_vertex = words[1] == "vertex"
            if in_vertex:
                if elements != 1:
                    sys.exit(f"{source}: the vertices are not the first element")
                count = int(words[2])
        elif words[0] == "property" and in_vertex:
            if words[1] == "list":
                sys.exit(f"{source}: the vertices have a list property")
            record += SIZES[words[1]]
        elif words[0] == "end_header":
            continue
        if words[0] in ("ply", "format", "comment") or in_vertex:
            header.append(line)
    if camera:
        header.append("element camera 1")
        header += [f"property float {name}" for name in CAMERA]
    header.append("end_header")
    with open(target, "wb") as stream:
        stream.write(("\n".join(header) + "\n").encode("ascii"))
        stream.write(data[end:end + count * record])
        if camera:
            stream.write(struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1))


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4) or sys.argv[3:] not in ([], ["--camera"]):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:] == ["--camera"])
