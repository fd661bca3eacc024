#!/usr/bin/env python3
"""Writes stratmesh.h, the one header users vendor, from the sources under src/.

    python3 tools/amalgamate.py            writes stratmesh.h at the repository's root
    python3 tools/amalgamate.py --check    writes nothing; exit 1 if stratmesh.h differs
    python3 tools/amalgamate.py --src DIR --out FILE   other places (the check's control)

src/stratmesh.h.in is the frame of the document: the include guard, the C++ and C parts
and the implementation's guard. A line `//@file PATH` there is replaced by the file
src/PATH; `//@contents` by the table of contents of the implementation, one line per
file whose first line is a section banner (`// >>name ===`), with the summary on the line
under it. Lines `#include "..."` in the sources (for editors) are left out.
Standard library only."""

import argparse
import os
import re
import sys

BANNER = re.compile(r'^// >>([a-z0-9 ]+?) =+$')
FILE = re.compile(r'^//@file (\S+)$')
LOCAL_INCLUDE = re.compile(r'^#include "[^"]*"\s*$')
CONTENTS_WIDTH = 91  # the header's lines are at most this long


def read_source(src, path):
    with open(os.path.join(src, path), encoding='utf-8') as f:
        lines = f.read().split('\n')
    if lines and lines[-1] == '':
        lines.pop()
    return [line for line in lines if not LOCAL_INCLUDE.match(line)]


def summary(lines):
    """The section's name and the line under its banner, its one-line summary."""
    name = BANNER.match(lines[0]).group(1)
    text = lines[1][2:].strip() if len(lines) > 1 and lines[1].startswith('//') else ''
    if len(text) > 1 and text[0].isupper() and (text[1].islower() or text[1] == ' '):
        text = text[0].lower() + text[1:]  # a clause of the table, as "the arena"
    return name, text.rstrip('.')


def contents(entries):
    """One `//   >>name  summary` line per section, wrapped under the summaries' column."""
    column = max(len(name) for name, _ in entries) + 8
    out = []
    for name, text in entries:
        line = ('//   >>' + name).ljust(column)
        for word in text.split():
            if len(line) + 1 + len(word) > CONTENTS_WIDTH and line.strip() != '//':
                out.append(line.rstrip())
                line = '//'.ljust(column)
            line += ('' if line.endswith(' ') else ' ') + word
        out.append(line.rstrip())
    return out


def amalgamate(src):
    with open(os.path.join(src, 'stratmesh.h.in'), encoding='utf-8') as f:
        frame = f.read().split('\n')
    files = [FILE.match(line).group(1) for line in frame if FILE.match(line)]
    sources = {path: read_source(src, path) for path in files}
    sections = [summary(lines) for path, lines in sources.items()
                if lines and BANNER.match(lines[0])]
    out = []
    for line in frame:
        match = FILE.match(line)
        if match:
            out.extend(sources[match.group(1)])
        elif line == '//@contents':
            out.extend(contents(sections))
        else:
            out.append(line)
    while out and out[-1] == '':
        out.pop()
    return '\n'.join(out) + '\n'


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--src', default=os.path.join(root, 'src'))
    parser.add_argument('--out', default=os.path.join(root, 'stratmesh.h'))
    parser.add_argument('--check', action='store_true',
                        help='compare with --out instead of writing it; exit 1 on a difference')
    args = parser.parse_args()
    text = amalgamate(args.src)
    if args.check:
        try:
            with open(args.out, encoding='utf-8') as f:
                current = f.read()
        except OSError:
            current = None
        if current != text:
            print('%s is not what tools/amalgamate.py writes from %s: run it and commit both'
                  % (args.out, args.src), file=sys.stderr)
            return 1
        return 0
    with open(args.out, 'w', encoding='utf-8') as f:
        f.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
