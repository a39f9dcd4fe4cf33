#!/usr/bin/env python3
"""scripts/house.py -- the house's measures (issue 32): every function's
length in core/, lcp/, engine/, problems/ (ctags' line of the definition to
its closing brace at column 0), and the share of comment lines inside
function bodies of engine/ and lcp/.

usage: python3 scripts/house.py [--max 150] [--density 0.10]   (exit 1 when a
function is longer or the density lower)"""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def functions(path):
    """(name, first line, last line) of each function defined in path."""
    out = subprocess.run(["ctags", "-x", "--c-kinds=f", "--language-force=C", path],
                         capture_output=True, text=True, check=True).stdout
    lines = open(path, encoding="utf-8").read().split("\n")
    res = []
    for row in out.splitlines():
        parts = row.split()
        name, line = parts[0], int(parts[2])
        end = line
        first = lines[line - 1].rstrip()
        if not ("{" in first and first.endswith("}")):  # not a one-line function
            while end < len(lines) and not lines[end - 1].startswith("}"):
                end += 1
        res.append((name, line, end))
    return res


def comment_lines(path, spans):
    """(comment lines, lines) inside the bodies of spans."""
    text = open(path, encoding="utf-8").read().split("\n")
    com = tot = 0
    for _, a, b in spans:
        in_block = False
        for ln in text[a:b - 1]:  # the body, without the signature's first line and "}"
            s = ln.strip()
            if not s:
                continue
            tot += 1
            has = in_block or "//" in s or "/*" in s
            if "/*" in s and "*/" not in s.split("/*", 1)[1]:
                in_block = True
            elif in_block and "*/" in s:
                in_block = False
            com += 1 if has else 0
    return com, tot


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max", type=int, default=150)
    ap.add_argument("--density", type=float, default=0.10)
    ap.add_argument("--top", type=int, default=8)
    args = ap.parse_args()
    allf, dens = [], {}
    for d in ("core", "lcp", "engine", "problems"):
        com = tot = 0
        for f in sorted(os.listdir(os.path.join(ROOT, d))):
            if not f.endswith((".c", ".h")):
                continue
            p = os.path.join(ROOT, d, f)
            spans = functions(p)
            allf += [(b - a + 1, "%s/%s:%d %s" % (d, f, a, n)) for n, a, b in spans]
            c, t = comment_lines(p, spans)
            com, tot = com + c, tot + t
        dens[d] = (com, tot)
    allf.sort(reverse=True)
    print("largest functions:")
    for n, where in allf[:args.top]:
        print("  %4d  %s" % (n, where))
    for d, (c, t) in dens.items():
        print("comment lines inside function bodies, %-8s %5d of %6d  %4.1f %%" % (d + "/:", c, t,
                                                                              100.0 * c / t))
    long_ = [w for n, w in allf if n > args.max]
    low = [d for d in ("engine", "lcp") if dens[d][0] < args.density * dens[d][1]]
    if long_:
        print("over %d lines: %s" % (args.max, ", ".join(long_)))
    if low:
        print("comment density below %.0f %%: %s" % (100 * args.density, ", ".join(low)))
    return 1 if long_ or low else 0


if __name__ == "__main__":
    sys.exit(main())
