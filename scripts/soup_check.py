#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Polygon-soup check of pcl_ms_reconstruct's preferred initial triangles.

Usage: python3 scripts/soup_check.py MESH.off [-tool build/pcl_ms_reconstruct]
                                      [-wrong 0.1] [-seed 14] [-keep DIR]

Replaces a fraction (default 10 %) of the mesh's triangles by wrong ones, as
tests/test_soup.cpp does for the bunny: 60 % of them join three vertices at
least a tenth of the bounding-box diagonal apart (they cross the surface),
20 % are the other diagonal of a quad of two right triangles (they overlap
both) and 20 % repeat a right triangle in another corner order. Then it runs

  pcl_ms_reconstruct MESH.off out.obj -initial soup.off -initial_mode preferred

(the mesh's vertices are the cloud), and the same with the default fixed
mode, and prints the triangles kept of each kind, precision and recall
against the original mesh and the times. Pure standard library.
"""

import argparse
import math
import os
import random
import subprocess
import sys
import tempfile
import time


def read_off(path):
    with open(path) as f:
        words = f.read().split()
    if words[0] != "OFF":
        sys.exit(path + ": not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    at = 4
    vertices = []
    for _ in range(nv):
        vertices.append(tuple(float(w) for w in words[at:at + 3]))
        at += 3
    faces = []
    for _ in range(nf):
        n = int(words[at])
        corners = [int(w) for w in words[at + 1:at + 1 + n]]
        at += 1 + n
        for k in range(1, n - 1):  # fan-triangulate, as the tools do
            faces.append((corners[0], corners[k], corners[k + 1]))
    return vertices, faces


def write_off(path, vertices, faces):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(vertices), len(faces)))
        for v in vertices:
            f.write("%.9g %.9g %.9g\n" % v)
        for t in faces:
            f.write("3 %d %d %d\n" % t)


def read_obj_faces(path):
    faces = []
    with open(path) as f:
        for line in f:
            if line.startswith("f "):
                faces.append(tuple(int(w.split("/")[0]) - 1 for w in line.split()[1:4]))
    return faces


def key(t):
    return tuple(sorted(t))


def make_soup(vertices, faces, fraction, seed):
    rng = random.Random(seed)
    order = list(range(len(faces)))
    rng.shuffle(order)
    wrong = int(len(faces) * fraction)
    replaced = set(order[:wrong])
    right = [faces[i] for i in range(len(faces)) if i not in replaced]
    on_edge = {}
    for i, t in enumerate(right):
        for k in range(3):
            on_edge.setdefault(key((t[k], t[(k + 1) % 3])), []).append(i)
    used = sorted({v for t in faces for v in t})
    low = [min(vertices[v][a] for v in used) for a in range(3)]
    high = [max(vertices[v][a] for v in used) for a in range(3)]
    far = 0.1 * math.dist(low, high)
    soup = list(faces)
    crossing, overlapping = [], []
    for n, i in enumerate(order[:wrong]):
        kind = n % 10
        if kind < 6:
            while True:
                t = tuple(rng.choice(used) for _ in range(3))
                if all(math.dist(vertices[t[k]], vertices[t[(k + 1) % 3]]) >= far
                       for k in range(3)):
                    break
            crossing.append(t)
        elif kind < 8:
            while True:
                a, b, c = right[rng.randrange(len(right))]
                across = on_edge[key((a, c))]
                if len(across) != 2:
                    continue
                second = [right[j] for j in across if key(right[j]) != key((a, b, c))]
                if not second:
                    continue
                d = [v for v in second[0] if v not in (a, c)][0]
                t = (a, b, d)
                break
            overlapping.append(t)
        else:
            c = right[rng.randrange(len(right))]
            t = (c[2], c[1], c[0])
        soup[i] = t
    return soup, right, crossing, overlapping


def run(tool, arguments):
    start = time.monotonic()
    done = subprocess.run([tool] + arguments, capture_output=True, text=True)
    return done, time.monotonic() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("mesh")
    parser.add_argument("-tool", default=os.path.join(os.path.dirname(__file__), "..", "build",
                                                      "pcl_ms_reconstruct"))
    parser.add_argument("-wrong", type=float, default=0.1)
    parser.add_argument("-seed", type=int, default=14)
    parser.add_argument("-keep", help="write soup.off and the outputs here")
    args = parser.parse_args()

    vertices, faces = read_off(args.mesh)
    soup, right, crossing, overlapping = make_soup(vertices, faces, args.wrong, args.seed)
    work = args.keep or tempfile.mkdtemp(prefix="pcl_ms_soup_")
    os.makedirs(work, exist_ok=True)
    soup_path = os.path.join(work, "soup.off")
    write_off(soup_path, vertices, soup)
    print("%s: %d vertices, %d triangles; soup: %d right, %d crossing, %d overlapping, %d repeats"
          % (args.mesh, len(vertices), len(faces), len(right), len(crossing), len(overlapping),
             len(soup) - len(right) - len(crossing) - len(overlapping)))

    original = {key(t) for t in faces}
    plain_out = os.path.join(work, "plain.obj")
    done, plain_seconds = run(args.tool, [args.mesh, plain_out, "-q"])
    if done.returncode != 0:
        sys.exit(done.stderr)
    plain = read_obj_faces(plain_out)
    plain_correct = sum(key(t) in original for t in plain)
    print("plain:     %d triangles, precision %.2f %%, recall %.2f %%, %.2f s"
          % (len(plain), 100.0 * plain_correct / len(plain), 100.0 * plain_correct / len(faces),
             plain_seconds))

    out = os.path.join(work, "preferred.obj")
    done, seconds = run(args.tool, [args.mesh, out, "-initial", soup_path, "-initial_mode",
                                    "preferred"])
    if done.returncode != 0:
        sys.exit(done.stderr)
    mesh = read_obj_faces(out)
    output = {key(t) for t in mesh}
    correct = sum(key(t) in original for t in mesh)
    right_kept = sum(key(t) in output for t in right)
    print("preferred: %d triangles, precision %.2f %%, recall %.2f %%, %.2f s; right kept "
          "%d of %d (%.2f %%), crossing kept %d of %d, overlapping kept %d of %d"
          % (len(mesh), 100.0 * correct / len(mesh), 100.0 * correct / len(faces), seconds,
             right_kept, len(right), 100.0 * right_kept / len(right),
             sum(key(t) in output for t in crossing), len(crossing),
             sum(key(t) in output for t in overlapping), len(overlapping)))
    for line in done.stdout.splitlines():
        if "initial" in line or "boundary loops" in line or "components" in line:
            print("  " + line.strip())

    done, _ = run(args.tool, [args.mesh, os.path.join(work, "fixed.obj"), "-initial", soup_path,
                              "-q"])
    print("fixed:     exit %d, %s" % (done.returncode, done.stderr.strip()))


if __name__ == "__main__":
    main()
