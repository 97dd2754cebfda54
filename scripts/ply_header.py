# SPDX-License-Identifier: GPL-3.0-or-later
"""The header of a PLY file, shared by the project's scripts (standard
library only). Each script reads the body its own way."""

FORMATS = ("ascii", "binary_little_endian", "binary_big_endian")


class PlyElement:
    def __init__(self, name, count):
        self.name = name
        self.count = count
        self.properties = []  # (name, type) or (name, ("list", count_type, item_type))


def read_ply_header(data, path):
    """Parses the header at the start of `data` (the file's bytes).

    Returns (format, elements, body_offset). Raises ValueError when the file
    is not a PLY, the header does not end, a property comes before any
    element or the format is unknown."""
    if data.split(b"\n", 1)[0].strip() != b"ply":
        raise ValueError(f"{path}: not a PLY file")
    end = data.find(b"end_header")
    if end < 0:
        raise ValueError(f"{path}: header has no end_header")
    elements, fmt = [], None
    for line in data[:end].decode("ascii", "replace").splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append(PlyElement(words[1], int(words[2])))
        elif words[0] == "property":
            if not elements:
                raise ValueError(f"{path}: property before any element")
            if words[1] == "list":
                elements[-1].properties.append((words[4], ("list", words[2], words[3])))
            else:
                elements[-1].properties.append((words[2], words[1]))
    if fmt not in FORMATS:
        raise ValueError(f"{path}: unknown PLY format {fmt}")
    newline = data.find(b"\n", end)
    return fmt, elements, len(data) if newline < 0 else newline + 1
