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

Every ```python block of the same files runs too, each as its own script,
after its file's commands and in the same folder (so it finds what they
write and `examples/...` as written), with the Python tests' interpreter and
environment: $PYTHON (default /usr/bin/python3), PYTHONPATH=<repo>/python,
POUND_LIBRARY=libpound.so next to the pound binary, POUND_BIN=that binary,
MPLBACKEND=Agg (no display), PYTHONDONTWRITEBYTECODE=1.  It must exit 0; a
failure prints file:line, the block and its stderr (tracebacks give the
file's own line numbers).  A block is a fragment, skipped and listed, when
its first line is `# fragment`, or when it uses a name it neither imports
nor defines (it continues an earlier block).  Without libpound.so next to
the binary (make shared), or NumPy and Matplotlib in $PYTHON (sh
scripts/deps.sh --python), the blocks are skipped and the last line says so.

It prints one line per command and block (status, seconds) and exits 1 on
any failure.  Standard library only.
"""
import builtins
import glob
import os
import re
import shutil
import subprocess
import symtable
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


def python_blocks(path):
    """(line of the block's first line, source) of the file's ```python blocks."""
    lines = open(os.path.join(ROOT, path), encoding="utf-8").read().splitlines()
    out, k = [], 0
    while k < len(lines):
        if re.match(r"^```\s*python\s*$", lines[k]):
            j = k + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            out.append((k + 2, "\n".join(lines[k + 1:j]) + "\n"))
            k = j
        k += 1
    return out


def fragment(src):
    """Why the block is a fragment (not run), or None."""
    if src.lstrip().startswith("# fragment"):
        return "marked '# fragment'"
    try:
        top = symtable.symtable(src, "block", "exec")
    except SyntaxError:
        return None  # not a fragment: it runs, and fails with its SyntaxError
    bound = {s.get_name() for s in top.get_symbols()
             if s.is_assigned() or s.is_imported() or s.is_namespace()}
    known = bound | set(dir(builtins)) | {"__file__", "__builtins__"}
    free, todo = set(), [top]
    while todo:
        t = todo.pop()
        todo.extend(t.get_children())
        for sym in t.get_symbols():
            if sym.is_referenced() and (t is top or sym.is_global()) and sym.get_name() not in known:
                free.add(sym.get_name())
    return "uses %s, which it neither imports nor defines" % ", ".join(sorted(free)) if free else None


def python_env(pound, python):
    """The Python tests' environment, or why the blocks cannot run."""
    lib = os.path.join(os.path.dirname(pound), "libpound.so")
    if not os.path.exists(lib):
        return None, "no %s (make shared)" % (os.path.relpath(lib, ROOT)
                                               if lib.startswith(ROOT + os.sep) else lib)
    exe = shutil.which(python)
    probe = subprocess.run([exe, "-c", "import numpy, matplotlib"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, check=False) if exe else None
    if probe is None or probe.returncode != 0:
        return None, "%s lacks NumPy or Matplotlib (sh scripts/deps.sh --python)" % python
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"), POUND_LIBRARY=lib,
               POUND_BIN=pound, MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1")
    return env, None


def run_block(tmp, rel, line, src, python, env):
    """Runs one block as a script padded to the file's line numbers: whether it exits 0."""
    script = os.path.join(tmp, ".docs-py", rel)
    os.makedirs(os.path.dirname(script), exist_ok=True)
    with open(script, "w", encoding="utf-8") as f:
        f.write("\n" * (line - 1) + src)
    t0 = time.time()
    try:
        p = subprocess.run([python, script], cwd=tmp, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, timeout=600, check=False)
        got, err = p.returncode, p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        got, err = -1, "timed out after 600 s\n"
    ok = got == 0
    print("%s %s:%d (python, exit %d, %.1f s)" % ("ok  " if ok else "FAIL", rel, line, got,
                                                   time.time() - t0))
    if not ok:
        for k, text in enumerate(src.splitlines()):
            print("     %5d | %s" % (line + k, text))
        sys.stdout.write("     stderr:\n" + "".join("     " + l for l in
                                                      err[-4000:].splitlines(True)))
        if not err.endswith("\n"):
            print()
    return ok


def main():
    pound = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build",
                                                                               "pound"))
    if not os.access(pound, os.X_OK):
        print("docs-commands: no pound binary at %s" % pound)
        return 1
    python = os.environ.get("PYTHON", "/usr/bin/python3")
    env, no_python = python_env(pound, python)
    failed, total, t_all = 0, 0, time.time()
    py_failed, py_total, skipped = 0, 0, []
    with tempfile.TemporaryDirectory(prefix="pound-docs.") as tmp:
        os.mkdir(os.path.join(tmp, "build"))
        os.symlink(pound, os.path.join(tmp, "build", "pound"))
        if env:
            os.symlink(env["POUND_LIBRARY"], os.path.join(tmp, "build", "libpound.so"))
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
            for line, src in python_blocks(rel):
                why = fragment(src) or no_python
                if why:
                    skipped.append("%s:%d" % (rel, line))
                    print("SKIP %s:%d (python: %s)" % (rel, line, why))
                    continue
                py_total += 1
                if not run_block(tmp, rel, line, src, python, env):
                    py_failed += 1
    if no_python:
        what = "commands as the docs show them (python blocks skipped: %s)" % no_python
    else:
        what = "commands and %d of %d python blocks as the docs show them" % (
            py_total - py_failed, py_total)
        by_file = {}
        for where in skipped:
            rel, line = where.rsplit(":", 1)
            by_file.setdefault(rel, []).append(line)
        if skipped:
            what += ", %d fragments skipped (%s)" % (len(skipped), "; ".join(
                "%s:%s" % (rel, ",".join(lines)) for rel, lines in by_file.items()))
    bad = failed + py_failed
    print("docs-commands: %s: %d of %d %s (%.0f s, no ../shared)" %
          ("FAILED" if bad else "ok", total - failed, total, what, time.time() - t_all))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
