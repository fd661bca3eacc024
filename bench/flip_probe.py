#!/usr/bin/env python3
"""flip_probe.py - what flipping edges on the surface across the seams would gain.

    bench/flip_probe.py MESH.ply REPORT.json OUT.ply [--scope all|chunk|seam|layer]

Reads an ascii output of the stratmesh tool (--ascii) and its --report, flips the mesh's
edges on the surface by the rules of the library's surface_flips (header, "flips on the
surface"), and writes the result as ascii PLY for a mesh checker. The library flips each layer's
own edges before the bands exist; this probe measures what the same rules would do with
more of the surface in reach, after the bands are stitched:

    all    every edge between two triangles
    chunk  edges whose two triangles are in one chunk: a layer with the band below it (the
           part of the surface add_group builds at once, and the stream hands out at once)
    seam   edges whose two triangles are in one chunk and each a band's or at a point of
           the layer's bottom loop: the stretch a chunk emits last (see chunk_is_sound)
    layer  edges inside one layer that do not join two of its loop points (about what the
           library already does, with normals from whole fans)

A triangle's layer comes from its corners' heights along the report's axis against the
layers' tops; a triangle with corners in two layers is a band's, in the chunk of the upper;
the loops are the corners of the bands' triangles.
An edge ab between triangles abp and baq becomes pq when the angles at p and q sum to more
than 180 degrees and pq bends the surface at most 3 times what ab did, or when pq bends it
3 times less (bend: |(b - a) . (n_b - n_a)|, vertex normals the mean of the unit triangle
normals, estimated anew for the first 4 sweeps); and only if pq is not an edge already,
neither new triangle's widest angle passes 150 degrees (unless the old ones' did more),
and both new normals are within 26 degrees of the old pair's mean (the library also takes
sharper flips when no triangle around the quad is crossed; the probe does not). At most 8
sweeps. Pure Python: a minute or two for 20,000 points. Prints the flips per sweep.
"""
import bisect
import json
import math
import sys

BEND_VETO = 3.0
BEND_GAIN = 3.0
WIDEST_COSINE = -0.86602540378443865  # 150 degrees
GENTLE_COSINE = 0.9
SWEEPS = 8
NORMAL_SWEEPS = 4


def read_ascii_ply(path):
    with open(path) as f:
        text = f.read()
    header, body = text.split("end_header\n", 1)
    vertices = int(header.split("element vertex ")[1].split()[0])
    faces = int(header.split("element face ")[1].split()[0])
    lines = body.split("\n")
    points = [tuple(map(float, lines[i].split()[:3])) for i in range(vertices)]
    triangles = []
    for i in range(faces):
        fields = lines[vertices + i].split()
        if fields[0] != "3":
            sys.exit("flip_probe.py: %s: a face that is not a triangle" % path)
        triangles.append([int(fields[1]), int(fields[2]), int(fields[3])])
    return points, triangles


def write_ascii_ply(path, points, triangles):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(points))
        f.write("property double x\nproperty double y\nproperty double z\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n"
                % len(triangles))
        for p in points:
            f.write("%.17g %.17g %.17g\n" % p)
        for t in triangles:
            f.write("3 %d %d %d\n" % tuple(t))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    length = math.sqrt(dot(a, a))
    return (a[0] / length, a[1] / length, a[2] / length) if length > 0 else (0.0, 0.0, 0.0)


def main():
    args = sys.argv[1:]
    scope = "all"
    if "--scope" in args:
        k = args.index("--scope")
        scope = args[k + 1]
        del args[k:k + 2]
    if len(args) != 3 or scope not in ("all", "chunk", "seam", "layer"):
        sys.exit(__doc__.split("\n\n")[1])
    points, triangles = read_ascii_ply(args[0])
    report = json.load(open(args[1]))
    axis = report["axis"]["direction"]
    tops = [layer["top"] for layer in report["layers"]][:-1]
    layer_of = [bisect.bisect_right(tops, dot(p, axis)) for p in points]
    on_band = set()  # the points of band triangles: the loops
    for t in triangles:
        if len({layer_of[v] for v in t}) > 1:
            on_band.update(t)

    def normal(t):
        a, b, c = (points[v] for v in t)
        return cross(sub(b, a), sub(c, a))

    def widest_cosine(t):
        widest = 1.0
        for k in range(3):
            p, q, r = (points[t[(k + j) % 3]] for j in range(3))
            u, w = sub(q, p), sub(r, p)
            lengths = math.sqrt(dot(u, u) * dot(w, w))
            widest = min(widest, dot(u, w) / lengths if lengths > 0 else -1.0)
        return widest

    def angle(p, a, b):
        u, w = sub(points[a], points[p]), sub(points[b], points[p])
        return math.atan2(math.sqrt(dot(cross(u, w), cross(u, w))), dot(u, w))

    def chunk_of(t):
        return max(layer_of[v] for v in t)

    def at_seam(t):
        top = chunk_of(t)
        return len({layer_of[v] for v in t}) > 1 or any(
            v in on_band and layer_of[v] == top for v in t)

    def in_scope(t, u, a, b):
        if scope == "all":
            return True
        if scope in ("chunk", "seam") and chunk_of(t) != chunk_of(u):
            return False
        if scope == "chunk":
            return True
        if scope == "seam":
            return at_seam(t) and at_seam(u)
        return len({layer_of[v] for v in t + u}) == 1 and not (a in on_band and b in on_band)

    total = 0
    for sweep in range(SWEEPS):
        if sweep < NORMAL_SWEEPS:
            sums = [(0.0, 0.0, 0.0)] * len(points)
            for t in triangles:
                n = unit(normal(t))
                for v in t:
                    s = sums[v]
                    sums[v] = (s[0] + n[0], s[1] + n[1], s[2] + n[2])
            normals = [unit(s) for s in sums]
        owner = {}
        neighbours = {}
        for i, t in enumerate(triangles):
            for k in range(3):
                a, b = t[k], t[(k + 1) % 3]
                owner[(a, b)] = i
                neighbours.setdefault(a, set()).add(b)
                neighbours.setdefault(b, set()).add(a)
        changed = set()
        flips = 0
        for (a, b), i in list(owner.items()):
            j = owner.get((b, a))
            if a > b or j is None or i in changed or j in changed:
                continue
            t, u = triangles[i], triangles[j]
            if not in_scope(t, u, a, b):
                continue
            p = next(v for v in t if v != a and v != b)
            q = next(v for v in u if v != a and v != b)
            if p == q or q in neighbours[p]:
                continue
            if min(dot(normals[v], normals[v]) for v in (a, b, p, q)) == 0:
                continue
            bend_before = abs(dot(sub(points[b], points[a]), sub(normals[b], normals[a])))
            bend_after = abs(dot(sub(points[q], points[p]), sub(normals[q], normals[p])))
            if angle(p, a, b) + angle(q, b, a) > math.pi * (1 + 1e-9):
                if bend_after > BEND_VETO * bend_before:
                    continue
            elif not BEND_GAIN * bend_after < bend_before:
                continue
            first, second = [p, a, q], [q, b, p]
            mean = unit(tuple(x + y for x, y in zip(unit(normal(t)), unit(normal(u)))))
            n1, n2 = unit(normal(first)), unit(normal(second))
            if dot(n1, mean) < GENTLE_COSINE or dot(n2, mean) < GENTLE_COSINE:
                continue
            widest_after = min(widest_cosine(first), widest_cosine(second))
            if widest_after < WIDEST_COSINE and widest_after < min(widest_cosine(t),
                                                                   widest_cosine(u)):
                continue
            triangles[i], triangles[j] = first, second
            changed.update((i, j))
            neighbours[a].discard(b)
            neighbours[b].discard(a)
            neighbours[p].add(q)
            neighbours[q].add(p)
            flips += 1
        print("sweep %d: %d flips" % (sweep, flips))
        total += flips
        if flips == 0:
            break
    print("flips %d (scope %s)" % (total, scope))
    write_ascii_ply(args[2], points, triangles)


if __name__ == "__main__":
    main()
