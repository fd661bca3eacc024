#!/usr/bin/env python3
"""branch_profile.py - where a cloud parts into branches along z.

    bench/branch_profile.py CLOUD.ply [--gap D] [--slab T] [--step S] [--json]

The other half of the branching experiment of branch_split.py: cuts the cloud (x, y, z of the vertex element) into slabs T high along z
and counts each slab's pieces: the connected parts of its points when points closer than
D join (single linkage, as branch_split.py; D defaults to 4 times the median distance from
a point to its nearest neighbour, T to 2 D). A piece counts when it holds at least 20
points and a twentieth of its slab's (of its side's, below): a few stray points do not
make a branch. Prints the profile, one line per run of slabs with the same count, bottom
up, and the heights where the cloud parts, tried every S (default D / 2): the lowest
above which the points make two branches or more (branch_split.py HEIGHT), and the
highest below which they do (branch_split.py HEIGHT --below), every piece there a branch:
one that starts at the cut and goes on from it, its section too (see is_branch). With
--json, one JSON line instead. E.g. on the horned bust (horned_bust.py), whose horns
leave the skull at z = 2.85:

    bench/branch_profile.py horned.ply
    bench/branch_split.py horned.ply HEIGHT split.ply -- --axis z --layers 8

Needs python3 only.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from branch_split import SMALLEST_PIECE, median_spacing, pieces_of  # noqa: E402
from order_probe import read_ply  # noqa: E402


def slab_pieces(points, gap, slab):
    """(bottom, top, pieces) of each slab of height `slab`, bottom up."""
    low = min(p[2] for p in points)
    high = max(p[2] for p in points)
    count = max(1, int(math.ceil((high - low) / slab)))
    members = [[] for _ in range(count)]
    for p in points:
        members[min(count - 1, int((p[2] - low) / slab))].append(p)
    profile = []
    for k, slab_points in enumerate(members):
        pieces = len(counted_pieces(slab_points, gap))
        profile.append((low + k * slab, low + (k + 1) * slab if k + 1 < count else high,
                        pieces))
    return profile


def counted_pieces(points, gap):
    """The pieces of the points that count (at least 20 points and a twentieth of them),
    largest first."""
    least = max(SMALLEST_PIECE, len(points) / 20)
    return [piece for piece in pieces_of(points, gap) if len(piece) >= least]


def is_branch(points, cut, gap):
    """Whether a piece of these points starts at the cut (its nearest point within a gap of
    it), goes on from it (its farthest a gap or more away) and its section goes on too: the
    centroids of its points within a gap of the cut and within the next gap are less than
    two gaps apart (across z)."""
    distances = [abs(p[2] - cut) for p in points]
    if not (min(distances) <= gap and max(distances) >= gap):
        return False
    slices = [[p for p, d in zip(points, distances) if k * gap <= d < (k + 1) * gap]
              for k in range(2)]
    if not slices[1]:
        return True
    centroids = [[sum(p[c] for p in slice_) / len(slice_) for c in range(2)]
                 for slice_ in slices]
    return math.dist(*centroids) < 2 * gap


def parting_heights(points, gap, step):
    """The lowest height, of those `step` apart from the lowest point up, such that the
    points above it make two pieces or more and every one a branch (see is_branch), and the
    highest such that the points below it do (None where there is none), each with the
    pieces' point counts; cuts within two gaps of the cloud's end are not tried. Each of
    is_branch's rules answers a false parting: a piece that begins farther away is a patch
    that a hole in the scan cut off (the top of the femur's head), one that ends within a
    gap a bump (63 points of the kitten within a third of a gap above z = 0.15), one whose
    section jumps a cap joined to a branch (the crown of the horned bust, above z = 2.787,
    with its left horn; above 2.814 the crown is a piece of its own, a patch, and that cut
    is not taken either: its tube would be the crown's); and a side thinner than two gaps
    is the rim at the cloud's end, which falls apart into arcs. The steps are finer than
    the slabs: the femur's condyles part only between slab boundaries."""
    low = min(p[2] for p in points)
    high = max(p[2] for p in points)
    heights = [low + k * step for k in range(1, int((high - low) / step) + 1)]
    found = []
    for side, order in (("above", heights), ("below", list(reversed(heights)))):
        best = None
        for height in order:
            part = [p for p in points if (p[2] >= height) == (side == "above")]
            if max(abs(p[2] - height) for p in part) < 2 * gap:
                continue
            pieces = counted_pieces(part, gap)
            if len(pieces) >= 2 and all(is_branch([part[i] for i in piece], height, gap)
                                        for piece in pieces):
                best = (height, [len(piece) for piece in pieces])
                break
        found.append(best)
    return found


def main(argv):
    options = {"--gap": None, "--slab": None, "--step": None}
    as_json = "--json" in argv
    if as_json:
        argv.remove("--json")
    for flag in options:
        if flag in argv:
            i = argv.index(flag)
            if i + 1 >= len(argv):
                print(__doc__.split("\n\n")[1], file=sys.stderr)
                return 2
            options[flag] = float(argv[i + 1])
            argv = argv[:i] + argv[i + 2:]
    if len(argv) != 1:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    points, _ = read_ply(argv[0])
    gap = options["--gap"] or 4 * median_spacing(points)
    slab = options["--slab"] or 2 * gap
    step = options["--step"] or gap / 2
    profile = slab_pieces(points, gap, slab)
    above, below = parting_heights(points, gap, step)
    if as_json:
        print(json.dumps({"gap": gap, "slab": slab, "step": step, "parts_above": above,
                          "parts_below": below,
                          "profile": [[b, t, n] for b, t, n in profile]}))
        return 0
    print("gap %.4g, slabs %.4g high, cuts tried %.4g apart" % (gap, slab, step))
    run_start = 0
    for k in range(1, len(profile) + 1):
        if k == len(profile) or profile[k][2] != profile[run_start][2]:
            print("  z %.4g to %.4g: %d piece%s" % (profile[run_start][0], profile[k - 1][1],
                                                   profile[run_start][2],
                                                   "" if profile[run_start][2] == 1 else "s"))
            run_start = k
    for side, found in (("above", above), ("below", below)):
        print("parts %s z = %s" % (side, "none" if found is None else "%.4g (pieces of %s points)"
                                   % (found[0], ", ".join(str(n) for n in found[1]))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
