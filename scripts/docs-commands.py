#!/usr/bin/python3
"""docs-commands.py: every `pound` command the README and the docs show in
their code blocks, run as written, from a fresh folder that sees only the
repository (its build/ and examples/; no ../shared).

    python3 scripts/docs-commands.py [build/pound]

A command is a line of a fenced or indented code block that starts with
`build/pound`, `$ build/pound` or `$ pound` (continuation lines joined;
`pound` is build/pound).  It runs under sh in a temporary folder holding
links to the repository's build/ and examples/, so that the files it writes
stay there.  It must exit as the block shows: 0, or the status an `exit N`
line after it prints, or 2 where the block shows `pound:` error lines (a
reader's or a scene's error on a file the block shows or names; such
inputs are illustrations, and their commands must still fail as bad input
and not crash).  `make` and `sh scripts/...` lines are CI's own.

It prints one line per command (status, seconds) and exits 1 on any
failure.  Standard library only.
"""
import glob
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = ["README.md", "python/README.md", "examples/records/README.md"] + sorted(
    glob.glob(os.path.join(ROOT, "docs", "*.md")))
START = re.compile(r"^\s*(\$ )?(build/)?pound (simulate|compare|converge|spectrum|record|lcp|bench)\b")


def commands(path):
    """(line, command, expected status) of the file's code blocks."""
    lines = open(os.path.join(ROOT, path), encoding="utf-8").read().splitlines()
    out, fenced, k = [], False, 0
    while k < len(lines):
        line = lines[k]
        if line.startswith("```"):
            fenced = not fenced
            k += 1
            continue
        in_block = fenced or line.startswith("    ")
        m = START.match(line) if in_block else None
        if not m:
            k += 1
            continue
        first = k + 1
        cmd = line.strip()
        while cmd.endswith("\\") and k + 1 < len(lines):
            k += 1
            cmd = cmd[:-1] + " " + lines[k].strip()
        cmd = re.sub(r"^\$ ", "", cmd)
        cmd = re.sub(r"\s+#.*$", "", cmd)  # a trailing comment
        cmd = re.sub(r"^pound ", "build/pound ", cmd)
        if re.search(r" \[-|\bFILE\b|\|", cmd) and ">" not in cmd:  # a synopsis, not a command
            k += 1
            continue
        # what the block shows after it: an exit line or error lines
        status, j = 0, k + 1
        while j < len(lines) and not START.match(lines[j]) and not lines[j].startswith("```"):
            shown = lines[j].strip()
            if re.match(r"^exit \d+$", shown):
                status = int(shown.split()[1])
            elif shown.startswith("pound: ") and "warning" not in shown:
                status = 2
            if not shown and not fenced:
                break
            j += 1
        out.append((first, cmd, status))
        k += 1
    return out


def main():
    pound = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build",
                                                                               "pound"))
    if not os.access(pound, os.X_OK):
        print("docs-commands: no pound binary at %s" % pound)
        return 1
    failed, total, t_all = 0, 0, time.time()
    with tempfile.TemporaryDirectory(prefix="pound-docs.") as tmp:
        os.mkdir(os.path.join(tmp, "build"))
        os.symlink(pound, os.path.join(tmp, "build", "pound"))
        os.symlink(os.path.join(ROOT, "examples"), os.path.join(tmp, "examples"))
        for doc in DOCS:
            rel = os.path.relpath(doc, ROOT) if os.path.isabs(doc) else doc
            for line, cmd, want in commands(rel):
                total += 1
                t0 = time.time()
                p = subprocess.run(["sh", "-c", cmd], cwd=tmp, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, timeout=600, check=False)
                got = p.returncode
                # a command with `; echo "exit $?"` prints its own status last
                said = re.findall(r"^exit (\d+)$", p.stdout.decode(errors="replace"), re.M)
                if "exit $?" in cmd and got == 0 and said:
                    got = int(said[-1])
                ok = got == want
                if not ok:
                    failed += 1
                print("%s %s:%d (exit %d, wanted %d, %.1f s) %s" %
                      ("ok  " if ok else "FAIL", rel, line, got, want, time.time() - t0, cmd))
                if not ok:
                    sys.stdout.write("     " + p.stderr.decode(errors="replace")[:400])
    print("docs-commands: %s: %d of %d commands as the docs show them (%.0f s, no ../shared)" %
          ("FAILED" if failed else "ok", total - failed, total, time.time() - t_all))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
