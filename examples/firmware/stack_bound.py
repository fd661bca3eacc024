#!/usr/bin/env python3
"""Worst-case stack depth of stratmesh's entry points, from GCC's -fcallgraph-info=su.

Reads the .ci files (VCG graphs: one node per function with its frame size, one edge per
call site), walks the call graph from each public entry point and prints the deepest path.
Fails on recursion (a cycle), on a frame of dynamic size, when an entry point's depth is
above --limit, or when no function of the graphs is an entry point (the wrong files, or a
renamed function: nothing would have been checked). Calls out of the library (memcpy, sqrt, frexp, ...: leaf functions of the C
library) and indirect calls (the caller's progress callback) are listed, not counted: add
the C library's leaf frames and your callback's depth to the figure.

  stack_bound.py [--limit BYTES] FILE.ci...
"""
import re
import sys

NODE = re.compile(r'node: \{ title: "([^"]*)" label: "((?:[^"\\]|\\.)*)"(.*)\}')
EDGE = re.compile(r'edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"')
FRAME = re.compile(r'(\d+) bytes \(([^)]*)\)')
ENTRY_POINTS = ("reconstruct", "delaunay_2d", "stream_push", "stream_close", "incircle", "orient2d")


def main(argv):
    limit = None
    files = []
    i = 0
    while i < len(argv):
        if argv[i] == "--limit":
            limit = int(argv[i + 1])
            i += 2
        else:
            files.append(argv[i])
            i += 1
    frames, names, kinds, edges = {}, {}, {}, {}
    for path in files:
        with open(path, encoding="utf-8") as f:
            for line in f:
                m = NODE.match(line)
                if m:
                    title, label = m.group(1), m.group(2)
                    names[title] = label.split("\\n")[0]
                    fm = FRAME.search(label)
                    if fm:
                        frames[title] = int(fm.group(1))
                        kinds[title] = fm.group(2)
                    edges.setdefault(title, set())
                    continue
                m = EDGE.match(line)
                if m:
                    edges.setdefault(m.group(1), set()).add(m.group(2))
    dynamic = [t for t, k in kinds.items() if k != "static"]
    external = sorted({names.get(t, t) for t in edges if t not in frames})

    memo, on_path = {}, set()

    def depth(t):
        """(bytes, path) of the deepest chain starting at t."""
        if t in memo:
            return memo[t]
        if t in on_path:
            raise RuntimeError("recursion through " + names.get(t, t))
        on_path.add(t)
        best = (0, [])
        for callee in edges.get(t, ()):
            if callee in frames:
                best = max(best, depth(callee), key=lambda x: x[0])
        on_path.discard(t)
        memo[t] = (frames.get(t, 0) + best[0], [t] + best[1])
        return memo[t]

    status = 0
    if dynamic:
        print("frames of dynamic size: " + ", ".join(names[t] for t in dynamic))
        status = 1
    print("calls out of the library (not counted): " + ", ".join(external))
    for entry in ENTRY_POINTS:
        roots = [t for t in frames if re.search(r"(^|:)_ZN9stratmesh%d%sE" % (len(entry), entry), t)]
        if not roots:
            print("FAIL: no function in the call graphs is the entry point %s" % entry)
            status = 1
        for root in roots:
            try:
                total, path = depth(root)
            except RuntimeError as e:
                print("FAIL: %s" % e)
                return 1
            print("%-60s worst-case stack %6d bytes" % (names[root][:60], total))
            for t in path:
                print("    %6d  %s" % (frames[t], names[t][:100]))
            if limit is not None and entry not in ("incircle", "orient2d") and total > limit:
                print("FAIL: above the limit of %d bytes" % limit)
                status = 1
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
