#!/usr/bin/env python3
"""branch_profile.py - where a cloud parts into branches along z.

    bench/branch_profile.py CLOUD.ply [--gap D] [--slab T] [--json]

The other half of the branching experiment of branch_split.py (README, "Known
limitations"): cuts the cloud (x, y, z of the vertex element) into slabs T high along z
and counts each slab's pieces: the connected parts of its points when points closer than
D join (single linkage, as branch_split.py; D defaults to 4 times the median distance from
a point to its nearest neighbour, T to 2 D). A piece counts when it holds at least 20
points and a twentieth of its slab's (of its side's, below): a few stray points do not
make a branch. Prints the profile, one line per run of slabs with the same count, bottom
up, and the heights where the cloud parts: the lowest slab boundary above which the points
make two pieces or more (the branches above: branch_split.py HEIGHT), and the highest
below which they do (branch_split.py HEIGHT --below); every boundary is tried. With
--json, one JSON line instead. E.g. on the horned bust (horned_bust.py), whose horns leave the skull at
z = 2.85 (bench/README.md has what it finds on the other clouds):

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


def parting_heights(points, gap, profile):
    """The lowest slab boundary such that the points above it make two pieces or more, and
    the highest such that the points below it do (None where there is none), each with
    the pieces' point counts. Every boundary is tried: the lowest points may be one
    branch alone (a condyle that reaches lower than the other)."""
    found = []
    boundaries = [bottom for bottom, _, _ in profile[1:]]
    for side, order in (("above", boundaries), ("below", list(reversed(boundaries)))):
        best = None
        for height in order:
            part = [p for p in points if (p[2] >= height) == (side == "above")]
            pieces = counted_pieces(part, gap)
            if len(pieces) >= 2:
                best = (height, [len(piece) for piece in pieces])
                break
        found.append(best)
    return found


def main(argv):
    options = {"--gap": None, "--slab": None}
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
    profile = slab_pieces(points, gap, slab)
    above, below = parting_heights(points, gap, profile)
    if as_json:
        print(json.dumps({"gap": gap, "slab": slab, "parts_above": above, "parts_below": below,
                          "profile": [[b, t, n] for b, t, n in profile]}))
        return 0
    print("gap %.4g, slabs %.4g high" % (gap, slab))
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
