#!/usr/bin/env python3
"""error_by_layer.py - where a mesh's distance to a reference surface lies, layer by layer.

    bench/error_by_layer.py MESH REPORT.json REFERENCE [--box X0,Y0,Z0,X1,Y1,Z1]...

MESH is the stratmesh tool's output as ascii PLY (`--ascii`) or OFF, REPORT.json its
`--report` (the axis and the layers' ranges), REFERENCE an OFF, ascii PLY or OBJ mesh of the
true surface. Every triangle of MESH is given the mean distance of its centroid and edge
midpoints to the reference (exact point-triangle distances, the candidates found through
points sampled on the reference), and counted in the layer holding its three
vertices, or in the band between layers when they lie in more than one. Prints, per layer and
for the bands: triangles, share of the mesh's area, share of the area-weighted distance, and
the mean distance (area-weighted, relative to the reference's diagonal, as a mesh checker's
mean_out_to_ref); then the share of area and of distance that the triangles farther than
0.5% and 1% of the diagonal carry; with --box (repeatable), the same for the triangles
whose centroid lies in one of the boxes (corners in the mesh's coordinates) and for the
rest. For example (bench/README.md):

    stratmesh femur.ply -o femur_out.ply --ascii --report femur.json
    bench/error_by_layer.py femur_out.ply femur.json femur_reference.off

Pure Python (no numpy): 10 to 20 s for a cloud of a few thousand points (a few thousand
triangles each way); 6 minutes for the bundled bust against a reference of its
300,000-point scan.
"""
import json
import math
import sys


def read_mesh(path):
    """Vertices and triangles (polygons fanned) of an ascii PLY, OFF or OBJ file."""
    with open(path, "r", errors="replace") as f:
        text = f.read()
    if text.startswith("ply"):
        header, body = text.split("end_header", 1)
        if "format ascii" not in header:
            sys.exit(f"{path}: binary PLY; write it with --ascii")
        counts = {}
        for line in header.splitlines():
            words = line.split()
            if words[:1] == ["element"]:
                counts[words[1]] = int(words[2])
        lines = body.strip().splitlines()
        nv = counts.get("vertex", 0)
        vertices = [tuple(map(float, l.split()[:3])) for l in lines[:nv]]
        faces = [list(map(int, l.split()[1:])) for l in lines[nv:nv + counts.get("face", 0)]]
    elif text.startswith("OFF"):
        words = text[3:].split()
        nv, nf = int(words[0]), int(words[1])
        at = 3
        vertices = [tuple(map(float, words[at + 3 * i: at + 3 * i + 3])) for i in range(nv)]
        at += 3 * nv
        faces = []
        for _ in range(nf):
            k = int(words[at])
            faces.append(list(map(int, words[at + 1: at + 1 + k])))
            at += 1 + k
    else:
        vertices, faces = [], []
        for line in text.splitlines():
            words = line.split()
            if words[:1] == ["v"]:
                vertices.append(tuple(map(float, words[1:4])))
            elif words[:1] == ["f"]:
                faces.append([int(w.split("/")[0]) - 1 for w in words[1:]])
    triangles = [(f[0], f[k], f[k + 1]) for f in faces for k in range(1, len(f) - 1)]
    return vertices, triangles


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def area(a, b, c):
    return 0.5 * norm(cross(sub(b, a), sub(c, a)))


def diagonal(vertices):
    low = [min(v[k] for v in vertices) for k in range(3)]
    high = [max(v[k] for v in vertices) for k in range(3)]
    return norm(sub(high, low))


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def point_triangle_distance(p, a, b, c):
    """Distance from p to triangle abc: the nearest point by the Voronoi region of p
    (a corner, an edge or the face), from the barycentric signs."""
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    if d1 <= 0 and d2 <= 0:
        return norm(ap)
    bp = sub(p, b)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    if d3 >= 0 and d4 <= d3:
        return norm(bp)
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        t = d1 / (d1 - d3)
        return norm(sub(ap, tuple(t * x for x in ab)))
    cp = sub(p, c)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    if d6 >= 0 and d5 <= d6:
        return norm(cp)
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        t = d2 / (d2 - d6)
        return norm(sub(ap, tuple(t * x for x in ac)))
    va = d3 * d6 - d5 * d4
    if va <= 0 and d4 - d3 >= 0 and d5 - d6 >= 0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return norm(sub(bp, tuple(t * (c[k] - b[k]) for k in range(3))))
    scale = 1 / (va + vb + vc)
    v, w = vb * scale, vc * scale
    return norm(sub(ap, tuple(v * ab[k] + w * ac[k] for k in range(3))))


class NearestSurface:
    """Distance to a triangle mesh: every triangle sampled on a barycentric lattice at most
    `spacing` apart, the samples in a uniform grid. The nearest sample, d0 away, bounds the
    search: the true nearest point has a sample of its own triangle within `spacing`, so
    the triangles of the samples within d0 + spacing hold it, and their exact distances
    decide."""

    def __init__(self, vertices, triangles, spacing):
        self.vertices, self.triangles, self.spacing = vertices, triangles, spacing
        self.cell = 2 * spacing
        self.cells = {}
        for index, t in enumerate(triangles):
            a, b, c = (vertices[i] for i in t)
            longest = max(norm(sub(a, b)), norm(sub(b, c)), norm(sub(c, a)))
            m = max(1, math.ceil(longest / spacing))
            for i in range(m + 1):
                for j in range(m + 1 - i):
                    u, v = i / m, j / m
                    q = tuple((1 - u - v) * a[k] + u * b[k] + v * c[k] for k in range(3))
                    self.cells.setdefault(self.key(q), []).append((q, index))

    def key(self, p):
        return tuple(math.floor(x / self.cell) for x in p)

    def samples_within(self, p, reach):
        low = self.key(tuple(x - reach for x in p))
        high = self.key(tuple(x + reach for x in p))
        for i in range(low[0], high[0] + 1):
            for j in range(low[1], high[1] + 1):
                for k in range(low[2], high[2] + 1):
                    yield from self.cells.get((i, j, k), ())

    def distance(self, p):
        reach = self.cell
        nearest = math.inf
        while nearest > reach and reach < 1e300:  # grow until a sample lies within reach
            nearest = min((norm(sub(p, q)) for q, _ in self.samples_within(p, reach)),
                          default=math.inf)
            reach *= 2
        candidates = {index for q, index in self.samples_within(p, nearest + self.spacing)
                      if norm(sub(p, q)) <= nearest + self.spacing}
        return min(point_triangle_distance(p, *(self.vertices[i] for i in self.triangles[t]))
                   for t in candidates)


def parse_boxes(args):
    """Removes each `--box X0,Y0,Z0,X1,Y1,Z1` from args; returns the boxes."""
    boxes = []
    while "--box" in args:
        at = args.index("--box")
        if at + 1 >= len(args):
            sys.exit(__doc__)
        try:
            numbers = [float(x) for x in args[at + 1].split(",")]
        except ValueError:
            numbers = []
        if len(numbers) != 6:
            sys.exit("--box takes six numbers: X0,Y0,Z0,X1,Y1,Z1")
        boxes.append((numbers[:3], numbers[3:]))
        del args[at:at + 2]
    return boxes


def in_boxes(p, boxes):
    return any(all(low[k] <= p[k] <= high[k] for k in range(3)) for low, high in boxes)


def main():
    args = sys.argv[1:]
    boxes = parse_boxes(args)
    if len(args) != 3:
        sys.exit(__doc__)
    vertices, triangles = read_mesh(args[0])
    with open(args[1]) as f:
        report = json.load(f)
    ref_vertices, ref_triangles = read_mesh(args[2])
    diag = diagonal(ref_vertices)
    surface = NearestSurface(ref_vertices, ref_triangles, diag / 400)

    axis = report["axis"]["direction"]
    cuts = [layer["bottom"] for layer in report["layers"]] + [report["layers"][-1]["top"]]

    def layer_of(v):
        h = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2]
        for k in range(len(cuts) - 2, -1, -1):
            if h >= cuts[k]:
                return k
        return 0

    layer = [layer_of(v) for v in vertices]
    groups = {}  # layer index, or "bands": [triangles, area, area * distance]
    tails = {0.005: [0.0, 0.0], 0.01: [0.0, 0.0]}
    boxed = [0, 0.0, 0.0]  # triangles whose centroid lies in a --box, their area, area * distance
    total_area = total_error = 0.0
    for t in triangles:
        a, b, c = (vertices[i] for i in t)
        probes = [tuple((a[k] + b[k] + c[k]) / 3 for k in range(3))]
        probes += [tuple((p[k] + q[k]) / 2 for k in range(3)) for p, q in ((a, b), (b, c), (c, a))]
        d = sum(surface.distance(p) for p in probes) / len(probes) / diag
        s = area(a, b, c)
        layers = {layer[i] for i in t}
        g = groups.setdefault(layers.pop() if len(layers) == 1 else "bands", [0, 0.0, 0.0])
        g[0] += 1
        g[1] += s
        g[2] += s * d
        total_area += s
        total_error += s * d
        if boxes and in_boxes(probes[0], boxes):
            boxed[0] += 1
            boxed[1] += s
            boxed[2] += s * d
        for limit, sums in tails.items():
            if d > limit:
                sums[0] += s
                sums[1] += s * d

    print(f"mean distance {total_error / total_area:.6f} of the reference's diagonal ({diag:.6g})")
    print("part                       triangles  area  distance  mean")
    for name in sorted((k for k in groups if k != "bands")) + ["bands"]:
        if name not in groups:
            continue
        n, s, e = groups[name]
        label = "bands between layers" if name == "bands" else \
            f"layer {name} [{cuts[name]:.4g}, {cuts[name + 1]:.4g}]"
        print(f"{label:<26} {n:9d} {s / total_area:5.3f} {e / total_error:9.3f}  {e / s:.6f}")
    if boxes:
        n, s, e = boxed
        mean = f"{e / s:.6f}" if s > 0 else "-"
        print(f"{'in the boxes':<26} {n:9d} {s / total_area:5.3f} {e / total_error:9.3f}  {mean}")
        rest = total_area - s
        mean = f"{(total_error - e) / rest:.6f}" if rest > 0 else "-"
        print(f"{'outside them':<26} {len(triangles) - n:9d} {rest / total_area:5.3f} "
              f"{(total_error - e) / total_error:9.3f}  {mean}")
    for limit, (s, e) in tails.items():
        print(f"triangles farther than {limit:.3f}: {s / total_area:.3f} of the area, "
              f"{e / total_error:.3f} of the distance")


if __name__ == "__main__":
    main()
