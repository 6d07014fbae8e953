#!/usr/bin/python3
"""Converts the npm package `bunny` (the Stanford bunny as JavaScript arrays) to configs/meshes/bunny.obj.

    mkdir /tmp/bunny && cd /tmp/bunny && npm pack bunny
    /usr/bin/python3 tools/convert_bunny.py /tmp/bunny/bunny-1.0.1.tgz configs/meshes/bunny.obj

The package's index.js holds `exports.positions=[[x,y,z],...];exports.cells=[[i,j,k],...]` with 0-based
vertex indices; the OBJ keeps the vertices, triangles and their orientation as they are (y is up, as
scanned). The script also says whether the mesh is closed: every edge shared by exactly two triangles that
run along it in opposite directions.
"""
import collections
import json
import re
import sys
import tarfile


def read_arrays(tgz_path):
    with tarfile.open(tgz_path) as tgz:
        source = tgz.extractfile("package/index.js").read().decode("ascii")
    arrays = dict(re.findall(r"exports\.(\w+)\s*=\s*(\[.*?\]\])", source, re.S))
    return json.loads(arrays["positions"]), json.loads(arrays["cells"])


def describe_closedness(cells):
    directed = collections.Counter()
    for a, b, c in cells:
        for edge in ((a, b), (b, c), (c, a)):
            directed[edge] += 1
    undirected = collections.Counter()
    for (a, b), n in directed.items():
        undirected[(min(a, b), max(a, b))] += n
    border = sum(1 for n in undirected.values() if n == 1)
    nonmanifold = sum(1 for n in undirected.values() if n > 2)
    misoriented = sum(1 for n in directed.values() if n > 1)
    closed = border == 0 and nonmanifold == 0 and misoriented == 0
    return (f"{len(undirected)} edges: {border} on a border, {nonmanifold} shared by more than two triangles, "
            f"{misoriented} run the same way in two triangles; the mesh is {'closed' if closed else 'open'}")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    positions, cells = read_arrays(sys.argv[1])
    with open(sys.argv[2], "w", encoding="ascii") as out:
        out.write("# The Stanford bunny (Stanford 3D Scanning Repository), from the npm package `bunny` 1.0.1\n")
        out.write("# by Mikola Lysenko; converted by tools/convert_bunny.py. See README.md in this folder.\n")
        out.write(f"# {len(positions)} vertices, {len(cells)} triangles; y is up.\n")
        for x, y, z in positions:
            out.write(f"v {x} {y} {z}\n")
        for a, b, c in cells:
            out.write(f"f {a + 1} {b + 1} {c + 1}\n")
    print(f"{sys.argv[2]}: {len(positions)} vertices, {len(cells)} triangles")
    print(describe_closedness(cells))


if __name__ == "__main__":
    main()
