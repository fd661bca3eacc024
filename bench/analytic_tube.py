#!/usr/bin/env python3
"""analytic_tube.py - a star-shaped tube cloud with a reference mesh of its true surface.

    bench/analytic_tube.py SHAPE POINTS NOISE SEED CLOUD.ply REFERENCE.off

SHAPE is the radius around the z axis, z in [0, 6]:
    bumpy  r = 1 + 0.25 sin(5 t) cos(z)          (the test suite's bumpy tube)
    wavy   r = 1 + 0.3 sin(3 t) sin(2 z) + 0.2 cos(7 t)
    cyl    r = 1
    vase   r = 1 + 0.6 sin(1.2 z)                   (smooth, of revolution)
    cone   r = 2 - 0.3 z                            (ruled: straight generatrices)
The cloud is POINTS points spread evenly over the surface's area (rejection on the area
element), each moved radially by Gaussian noise of standard deviation NOISE; ascii PLY with
float x, y, z. The reference is the surface on a 720 x 600 grid of (t, z), closed around
the axis and open at both ends (864,000 triangles, ascii OFF). For bench/quality_vs_afr.sh:

    bench/analytic_tube.py wavy 20000 0 1 wavy.ply wavy.off
    bench/quality_vs_afr.sh --ref wavy.off wavy.ply -- --axis z --layers 8 --threads 1
"""
import math
import random
import sys

HEIGHT = 6.0
RADII = {
    "bumpy": lambda t, z: 1 + 0.25 * math.sin(5 * t) * math.cos(z),
    "wavy": lambda t, z: 1 + 0.3 * math.sin(3 * t) * math.sin(2 * z) + 0.2 * math.cos(7 * t),
    "cyl": lambda t, z: 1.0,
    "vase": lambda t, z: 1 + 0.6 * math.sin(1.2 * z),
    "cone": lambda t, z: 2 - 0.3 * z,
}


def area_element(radius, t, z, step=1e-5):
    """|dP/dt x dP/dz| for P = (r cos t, r sin t, z)."""
    r = radius(t, z)
    r_t = (radius(t + step, z) - r) / step
    r_z = (radius(t, z + step) - r) / step
    return math.sqrt(r * r * (1 + r_z * r_z) + r_t * r_t)


def main(argv):
    if len(argv) != 7 or argv[1] not in RADII:
        sys.stderr.write(__doc__)
        return 2
    radius = RADII[argv[1]]
    count, noise, seed = int(argv[2]), float(argv[3]), int(argv[4])
    rng = random.Random(seed)
    # The largest area element over a fine grid bounds the rejection test.
    bound = 1.05 * max(area_element(radius, 2 * math.pi * i / 360, HEIGHT * j / 60)
                       for i in range(360) for j in range(61))
    points = []
    while len(points) < count:
        t, z = rng.uniform(0, 2 * math.pi), rng.uniform(0, HEIGHT)
        if rng.random() * bound > area_element(radius, t, z):
            continue
        r = radius(t, z) + (rng.gauss(0, noise) if noise > 0 else 0)
        points.append((r * math.cos(t), r * math.sin(t), z))
    with open(argv[5], "w") as out:
        out.write("ply\nformat ascii 1.0\nelement vertex %d\n" % count)
        out.write("property float x\nproperty float y\nproperty float z\nend_header\n")
        out.writelines("%.7g %.7g %.7g\n" % p for p in points)
    around, rows = 720, 600
    with open(argv[6], "w") as out:
        out.write("OFF\n%d %d 0\n" % (around * (rows + 1), 2 * around * rows))
        for j in range(rows + 1):
            z = HEIGHT * j / rows
            for i in range(around):
                t = 2 * math.pi * i / around
                r = radius(t, z)
                out.write("%.9g %.9g %.9g\n" % (r * math.cos(t), r * math.sin(t), z))
        for j in range(rows):
            for i in range(around):
                a, b = j * around + i, j * around + (i + 1) % around
                out.write("3 %d %d %d\n3 %d %d %d\n" % (a, b, b + around, a, b + around, a + around))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
