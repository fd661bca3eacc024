#!/usr/bin/env python3
"""horned_bust.py - a synthetic bust with ears and horns, sampled as a point cloud.

    bench/horned_bust.py POINTS OUT.ply [--seed S] [--no-horns]

Writes POINTS points (binary little-endian PLY, float32 x, y, z), spread evenly by area
over the outer surface of a union of solids standing along +z: a neck (a cylinder of
radius 0.45 from z = 0 to 1.2, open below), a head (an ellipsoid of radii 0.8, 0.9, 1.0
about (0, 0, 1.85)), two ears (flat ellipsoids on the head's sides) and two horns (tubes
tapering from radius 0.215 to 0.015 along curves that leave the top of the head at
x = +-0.4, z = 2.45 and rise to x = +-0.95, z = 3.55). Points inside another solid are
left out, so the cloud samples the union's surface, as a scan of the object would.
With --no-horns, the same bust without them: the head closes over the top.

It is the kind of real scan the method is judged on ("busts with ears and horns") where
the object branches: above the skull the cross-section is two separate horns. A second,
denser cloud (another seed) meshed by a reference tool stands in for the true surface,
for example (bench/README.md):

    bench/horned_bust.py 20000 horned.ply
    bench/horned_bust.py 400000 horned_dense.ply --seed 2
    build/bench/stratmesh_afr_peer horned_dense.ply -o horned_reference.off
    bench/quality_vs_afr.sh --ref horned_reference.off horned.ply -- --axis z

Pure Python (no numpy): about 40 s for 400,000 points.
"""
import math
import random
import struct
import sys

NECK_RADIUS, NECK_TOP = 0.45, 1.2
HEAD_CENTRE, HEAD_RADII = (0.0, 0.0, 1.85), (0.8, 0.9, 1.0)
EARS = [((side * 0.78, 0.05, 1.8), (0.14, 0.28, 0.38)) for side in (-1, 1)]
HORN_STEPS = 400


def horn_centre(side, t):
    """The horn's centre line at t in [0, 1]: from the head's top out and up."""
    return (side * (0.40 + 0.55 * t ** 1.5), 0.0, 2.45 + 1.1 * t)


def horn_radius(t):
    return 0.20 * (1 - t) + 0.015


def inside_ellipsoid(p, centre, radii):
    return sum(((p[k] - centre[k]) / radii[k]) ** 2 for k in range(3)) < 1


def inside_neck(p):
    return p[0] ** 2 + p[1] ** 2 < NECK_RADIUS ** 2 and 0 < p[2] < NECK_TOP


def horn_polyline(side):
    return [(horn_centre(side, i / HORN_STEPS), horn_radius(i / HORN_STEPS))
            for i in range(HORN_STEPS + 1)]


def inside_horn(p, polyline):
    """Within the tube: nearer a centre-line sample than its radius (the samples are
    0.003 apart, far below the radius)."""
    if p[2] < 2.2:
        return False
    for c, r in polyline:
        if (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2 < r * r:
            return True
    return False


def unit_vector(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-9:
            return [x / n for x in v]


def ellipsoid_sampler(centre, radii):
    """Even by area: a direction u on the unit sphere is kept with probability
    proportional to the area element of x = centre + radii * u."""
    a, b, c = radii
    most = max(b * c, a * c, a * b)

    def sample(rng):
        while True:
            u = unit_vector(rng)
            weight = math.sqrt((b * c * u[0]) ** 2 + (a * c * u[1]) ** 2 + (a * b * u[2]) ** 2)
            if rng.random() * most < weight:
                return tuple(centre[k] + radii[k] * u[k] for k in range(3))
    return sample


def neck_sample(rng):
    angle = rng.uniform(0, 2 * math.pi)
    return (NECK_RADIUS * math.cos(angle), NECK_RADIUS * math.sin(angle),
            rng.uniform(0, NECK_TOP))


def horn_sampler(side):
    """Even by area up to the tube's bending: t kept with probability proportional to
    radius(t) * |centre'(t)|."""
    def speed(t):
        a, b = horn_centre(side, max(t - 1e-4, 0)), horn_centre(side, min(t + 1e-4, 1))
        return math.dist(a, b) / (min(t + 1e-4, 1) - max(t - 1e-4, 0))
    most = max(horn_radius(i / 100) * speed(i / 100) for i in range(101))

    def sample(rng):
        while True:
            t = rng.random()
            if rng.random() * most < horn_radius(t) * speed(t):
                break
        c = horn_centre(side, t)
        ahead = horn_centre(side, min(t + 1e-4, 1))
        behind = horn_centre(side, max(t - 1e-4, 0))
        d = [ahead[k] - behind[k] for k in range(3)]
        n = math.sqrt(sum(x * x for x in d))
        d = [x / n for x in d]
        # d lies in the xz plane: y and d x y span the circle around it.
        e1 = (d[2], 0.0, -d[0])
        angle = rng.uniform(0, 2 * math.pi)
        r = horn_radius(t)
        return (c[0] + r * (math.cos(angle) * e1[0]), r * math.sin(angle),
                c[2] + r * (math.cos(angle) * e1[2]))
    return sample


def ellipsoid_area(radii):
    """Knud Thomsen's approximation (within about 1%)."""
    a, b, c = radii
    q = 1.6075
    return 4 * math.pi * (((a * b) ** q + (a * c) ** q + (b * c) ** q) / 3) ** (1 / q)


def horn_area(side):
    steps = 1000
    return sum(2 * math.pi * horn_radius((i + 0.5) / steps) *
               math.dist(horn_centre(side, i / steps), horn_centre(side, (i + 1) / steps))
               for i in range(steps))


def solids(with_horns):
    """(sampler, inside test, area) of each solid."""
    horns = {side: horn_polyline(side) for side in (-1, 1)}
    parts = [(neck_sample, inside_neck, 2 * math.pi * NECK_RADIUS * NECK_TOP),
             (ellipsoid_sampler(HEAD_CENTRE, HEAD_RADII),
              lambda p: inside_ellipsoid(p, HEAD_CENTRE, HEAD_RADII), ellipsoid_area(HEAD_RADII))]
    for centre, radii in EARS:
        parts.append((ellipsoid_sampler(centre, radii),
                      lambda p, c=centre, r=radii: inside_ellipsoid(p, c, r), ellipsoid_area(radii)))
    for side in (-1, 1) if with_horns else ():
        parts.append((horn_sampler(side), lambda p, h=horns[side]: inside_horn(p, h), horn_area(side)))
    return parts


def main():
    args = sys.argv[1:]
    seed = 1
    with_horns = "--no-horns" not in args
    args = [a for a in args if a != "--no-horns"]
    if "--seed" in args:
        at = args.index("--seed")
        seed = int(args[at + 1])
        del args[at:at + 2]
    if len(args) != 2:
        sys.exit(__doc__.split("\n\n")[1])
    count, path = int(args[0]), args[1]
    rng = random.Random(seed)
    parts = solids(with_horns)
    total = sum(area for _, _, area in parts)
    points = []
    # Each solid in turn, a share by its area; what lies inside another solid is dropped,
    # and the rounds go on until the union's surface holds `count` points.
    while len(points) < count:
        batch = []
        for i, (sample, _, area) in enumerate(parts):
            for _ in range(max(1, round(count * area / total / 8))):
                p = sample(rng)
                if not any(inside(p) for j, (_, inside, _) in enumerate(parts) if j != i):
                    batch.append(p)
        rng.shuffle(batch)
        points.extend(batch[:count - len(points)])
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n"
                 % len(points)).encode())
        f.write(b"".join(struct.pack("<3f", *p) for p in points))


if __name__ == "__main__":
    main()
