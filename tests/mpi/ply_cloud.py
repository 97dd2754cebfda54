#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Usage: ply_cloud.py MESH.ply CLOUD.ply [--camera [WIDTH HEIGHT]]

Writes the vertices of a binary little-endian PLY mesh as a PLY cloud: the
vertex element alone, as it is, and with --camera the fixed-size camera
element PCL's cloud writer appends, whose viewport (WIDTH x HEIGHT, by
default the vertex count x 1) PCL's reader takes as the cloud's rows. The
MPI tool reads such clouds in parts.
"""
import struct
import sys

SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2,
         "int16": 2, "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4,
         "float": 4, "float32": 4, "double": 8, "float64": 8}
CAMERA = ["view_px", "view_py", "view_pz", "x_axisx", "x_axisy", "x_axisz", "y_axisx",
          "y_axisy", "y_axisz", "z_axisx", "z_axisy", "z_axisz", "focal", "scalex", "scaley",
          "centerx", "centery"]


def main(source, target, camera, viewport):
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
        header += ["property int viewportx", "property int viewporty"]
        header += ["property float k1", "property float k2"]
    header.append("end_header")
    with open(target, "wb") as stream:
        stream.write(("\n".join(header) + "\n").encode("ascii"))
        stream.write(data[end:end + count * record])
        if camera:
            width, height = viewport or (count, 1)
            stream.write(struct.pack("<17f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0))
            stream.write(struct.pack("<2i2f", width, height, 0, 0))


if __name__ == "__main__":
    options = sys.argv[3:]
    if len(sys.argv) < 3 or options[:1] not in ([], ["--camera"]) or len(options) not in (0, 1, 3):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], bool(options),
         (int(options[1]), int(options[2])) if len(options) == 3 else None)
