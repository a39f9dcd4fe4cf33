#!/usr/bin/env python3
"""scripts/mutate.py -- `make mutate`: mutation testing of pound's numerical
core.  Does the C suite fail when the code is wrong?

For each file, the code is masked (comments, string and character literals
blanked, #include lines left out) and every mutation site inside a function
body is listed; a seeded sample of N sites is taken, so that a run is
reproducible.  Operators, one textual change each:

  relop    <  <=  >  >=  ==  !=   turned into their neighbour (< to <=, == to !=)
  arith    binary + - * /         + to -, - to +, * to /, / to *
  logic    && ||                  swapped
  const    a numeric literal      nudged: an integer n to n + 1, a real x to 2 x
  delete   an assignment statement (x = ...; x += ...;) replaced by ;
  negate   !x                     to x

Each mutant is built in a copy of the tree (incremental make: the file and
the links), then run: the file's own cases first (a filter of the test
runner's names), then the whole C suite, both stopping at the first failure
(POUND_TEST_FAILFAST) and under a per-case time limit (POUND_TEST_TIMEOUT)
and a per-mutant limit.  A mutant is

  stillborn  it does not compile (not counted),
  (the build checks array indices against fixed sizes: -fsanitize=bounds, a trap)
  killed     a case failed, the run crashed, or it ran out of time,
  survived   every case passed.

Survivors listed in scripts/mutate_equivalent.txt (FILE:LINE:COLUMN: ORIGINAL
-> MUTANT  # why it cannot change a result) count as equivalent and leave the
denominator: killed / (mutants - stillborn - equivalent) is the file's score.
The other survivors are the suite's gaps, printed with their line.

usage: python3 scripts/mutate.py [--files F,...] [--n 30] [--seed 1]
                                 [--timeout S] [--report FILE] [--keep]
                                 [--only FILE:LINE:COL,...]
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The numerical core (issue 33) and each file's own cases: substrings of
# the runner's case names, run first.
DEFAULT_FILES = {
    "lcp/lemke.c": ["lcp", "lemke", "solver"],
    "engine/pd_mj1.h": ["engine", "moreau", "mj", "osc", "yield"],
    "engine/event_row.c": ["rows", "edr", "row_"],
    "engine/event_row_cluster.c": ["rows", "edr", "row_"],
    "engine/event_row_scan.c": ["rows", "edr", "row_"],
    "core/root.c": ["root", "edr_scan", "event", "rows"],
    "problems/demand.c": ["demand", "aabs"],
    "problems/scene_measure.c": ["measure", "general_history", "other_grid", "compare",
                                 "converge"],
    "engine/event_sdof.c": ["yield_rk", "yield_exact", "event", "reference"],
    "engine/penalty_newmark.c": ["yield_newmark", "newmark", "yield_mj", "penalty"],
    "engine/mj_yield.c": ["yield_mj", "yield_scene", "yield"],
    "problems/scene_energy.c": ["yield_scene"],
    "problems/separation.c": ["separation"],
    "problems/suite.c": ["suite"],
    "engine/mj_adapt.c": ["adapt"],
    "engine/mj_flight.c": ["adapt"],
}

# Array indices checked against the arrays' sizes (a trap, no runtime
# library; its instrumentation misleads -Wmaybe-uninitialized, left out):
# a mutant that writes one past a fixed array crashes, killed,
# instead of surviving by luck of the stack's layout.
BOUNDS = "-fsanitize=bounds -fsanitize-undefined-trap-on-error -Wno-maybe-uninitialized"

SKIP_DIRS = {".git", "build", "build-asan", "build-mpi", "build-tsan"}


# ---- masking and sites ----------------------------------------------------------


def mask(text):
    """text with comments, string and character literals and #include lines
    blanked (newlines kept): positions match the original."""
    out = list(text)
    i, n = 0, len(text)

    def blank(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            blank(i, min(j + 1, n))
            i = j + 1
        elif c == "#" and (i == 0 or text[i - 1] == "\n"):
            j = text.find("\n", i)
            j = n if j < 0 else j
            line = text[i:j]
            if re.match(r"#\s*(include|pragma|if|ifdef|ifndef|endif|else|elif|undef)", line):
                blank(i, j)
            i = j
        else:
            i += 1
    return "".join(out)


def depth_map(masked):
    """Brace depth at each position (function bodies: depth >= 1)."""
    d, depth = 0, [0] * (len(masked) + 1)
    for i, c in enumerate(masked):
        if c == "{":
            d += 1
        depth[i] = d
        if c == "}":
            d -= 1
    return depth


BEFORE_BINARY = r"(?<=[\w\)\]])\s"  # an operand, then a space
RELOPS = {"<=": "<", ">=": ">", "==": "!=", "!=": "==", "<": "<=", ">": ">="}


def sites(text):
    """Every mutation site: (start, end, replacement, operator)."""
    m = mask(text)
    depth = depth_map(m)
    out = []

    def add(a, b, new, op):
        if depth[a] >= 1:
            out.append((a, b, new, op))

    for mo in re.finditer(r"(?<![<>=!\-])(<=|>=|==|!=|<|>)(?![<>=])", m):
        a = mo.start()
        if m[a] in "<>" and (m[a - 1:a + 1] == "->" or m[a:a + 2] in ("<<", ">>")):
            continue
        if m[a] == ">" and m[a - 1] == "-":
            continue
        add(a, mo.end(), RELOPS[mo.group(1)], "relop")
    for mo in re.finditer(r"(?<=[\w\)\]]) ([+\-*/]) (?=[\w\(\-.])", m):
        op = mo.group(1)
        new = {"+": "-", "-": "+", "*": "/", "/": "*"}[op]
        add(mo.start(1), mo.end(1), new, "arith")
    for mo in re.finditer(r"&&|\|\|", m):
        add(mo.start(), mo.end(), "||" if mo.group() == "&&" else "&&", "logic")
    for mo in re.finditer(r"(?<![\w.])(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+|\.\d+(?:[eE][-+]?\d+)?|\d+)(?![\w.])", m):
        lit = mo.group(1)
        if re.fullmatch(r"\d+", lit):
            new = str(int(lit) + 1)
        elif float(lit) == 0.0:
            new = "1.0"
        else:
            new = "(2.0 * %s)" % lit
        add(mo.start(1), mo.end(1), new, "const")
    for mo in re.finditer(r"(?m)^([ \t]+)([A-Za-z_][\w\[\]\.>\-\*\s]*?\s*(?:[+\-*/]?=)\s*[^=;][^;]*;)[ \t]*$", m):
        stmt = mo.group(2)
        if re.match(r"(double|int|long|unsigned|size_t|const|static|char|float|"
                     r"return|for|if|while|else|pd_\w+\s|struct|uint64_t)\b", stmt):
            continue
        if "{" in stmt or "}" in stmt:
            continue
        add(mo.start(2), mo.end(2), ";", "delete")
    for mo in re.finditer(r"!(?=[\w\(])", m):
        add(mo.start(), mo.end(), "", "negate")
    out.sort()
    return out


def line_of(text, pos):
    return text.count("\n", 0, pos) + 1


# ---- the copy of the tree, builds and runs ----------------------------------------


def copy_tree(dst):
    def ignore(d, names):
        return [n for n in names if n in SKIP_DIRS and os.path.abspath(d) == ROOT]
    shutil.copytree(ROOT, dst, ignore=ignore, symlinks=True)


def build(work, log):
    p = subprocess.run(["make", "-j2", "all", "XCFLAGS=" + BOUNDS], cwd=work, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, timeout=900)
    if p.returncode != 0:
        log.write(p.stdout.decode("utf-8", "replace")[-2000:])
    return p.returncode == 0


def run_suite(work, filt, limit):
    """(status, last lines): 'pass', 'fail' or 'time'."""
    env = dict(os.environ, POUND_TEST_FAILFAST="1", POUND_TEST_TIMEOUT=str(int(limit)),
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    argv = ["./build/pound_tests"] + ([filt] if filt else [])
    try:
        p = subprocess.run(argv, cwd=work, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, timeout=limit * 4, start_new_session=True)
    except subprocess.TimeoutExpired:
        return "time", "over %g s" % (limit * 4)
    out = p.stdout.decode("utf-8", "replace")
    tail = [l for l in out.splitlines() if l.startswith("FAIL") or "test_" in l and ":" in l][:3]
    if p.returncode == 0 and re.search(r" 0 failed", out):
        return "pass", ""
    return "fail", "; ".join(tail) or "exit %d" % p.returncode


def load_equivalent(path):
    eq = {}
    if not os.path.exists(path):
        return eq
    for raw in open(path, encoding="utf-8"):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        m = re.match(r"(\S+?):(\d+):(\d+): (.*?) -> (.*?)\s+#\s*(.*)$", line)
        if m:
            eq[(m.group(1), int(m.group(2)), int(m.group(3)), " ".join(m.group(4).split()),
                m.group(5))] = m.group(6)
    return eq


# ---- the run -----------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--files", default=",".join(DEFAULT_FILES))
    ap.add_argument("--n", type=int, default=30, help="mutants per file")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=0.0,
                    help="per-case limit in s (default: 3 x the slowest baseline, >= 60)")
    ap.add_argument("--report", default=None, help="write the table into this file")
    ap.add_argument("--keep", action="store_true", help="keep the work tree")
    ap.add_argument("--remap", default="", metavar="REV",
                    help="rewrite scripts/mutate_equivalent.txt's FILE:LINE:COLUMN keys for "
                         "the files changed since REV by comments or layout only (the same "
                         "mutation sites in the same order), then exit")
    ap.add_argument("--only", default="",
                    help="FILE:LINE:COL,... : of the sample, run only these mutants (to "
                         "check that a new test kills a survivor)")
    args = ap.parse_args()
    if args.remap:
        return remap(args.remap)
    files = [f for f in args.files.split(",") if f]
    only = set(x.strip() for x in args.only.split(",") if x.strip())
    eq = load_equivalent(os.path.join(ROOT, "scripts", "mutate_equivalent.txt"))
    work = tempfile.mkdtemp(prefix="pound-mutate-")
    log = open(os.path.join(work, "mutate.log"), "w")
    print("mutate: a copy of the tree in %s" % work, flush=True)
    try:
        src = os.path.join(work, "src")
        copy_tree(src)
        if not build(src, log):
            print("mutate: the unmutated tree does not build (%s)" % log.name)
            return 2
        t0 = time.monotonic()
        st, why = run_suite(src, None, 600)
        base = time.monotonic() - t0
        if st != "pass":
            print("mutate: the unmutated suite fails: %s" % why)
            return 2
        limit = args.timeout or max(60.0, 3.0 * base)
        print("mutate: baseline suite %.0f s; limit %.0f s a case" % (base, limit), flush=True)
        rows, gaps = [], []
        for f in files:
            path = os.path.join(src, f)
            text = open(path, encoding="utf-8").read()
            all_sites = sites(text)
            rnd = random.Random("%d:%s" % (args.seed, f))
            pick = sorted(rnd.sample(all_sites, min(args.n, len(all_sites))))
            counts = {"stillborn": 0, "killed": 0, "survived": 0, "equivalent": 0}
            for (a, b, new, op) in pick:
                mutated = text[:a] + new + text[b:]
                line = line_of(text, a)
                col = a - text.rfind("\n", 0, a)
                orig = " ".join(text[a:b].split())  # a statement's layout left out
                key = (f, line, col, orig, new if new else "(removed)")
                if only and "%s:%d:%d" % (f, line, col) not in only:
                    continue
                with open(path, "w", encoding="utf-8") as fh:
                    fh.write(mutated)
                try:
                    if not build(src, log):
                        counts["stillborn"] += 1
                        verdict = "stillborn"
                    else:
                        verdict = "survived"
                        for filt in DEFAULT_FILES.get(f, []) + [None]:
                            st, why = run_suite(src, filt, limit)
                            if st != "pass":
                                verdict = "killed"
                                break
                        if verdict == "survived" and key in eq:
                            verdict = "equivalent"
                        counts[verdict] += 1
                        if verdict == "survived":
                            gaps.append("%s:%d:%d: %s -> %s  (%s)" % (f, line, col, orig, key[4],
                                                                       op))
                finally:
                    with open(path, "w", encoding="utf-8") as fh:
                        fh.write(text)
                print("  %-28s %5d:%-3d %-7s %-12s -> %-12s %s" % (f, line, col, op, orig[:12],
                                                                     key[4][:12], verdict),
                      flush=True)
            tried = sum(counts.values())
            live = tried - counts["stillborn"] - counts["equivalent"]
            score = counts["killed"] / live if live else 1.0
            rows.append((f, tried, counts, score))
        build(src, log)  # the tree as it was
        table = ["| file | mutants | stillborn | equivalent | killed | survived | killed of the "
                 "non-equivalent |", "| --- | --- | --- | --- | --- | --- | --- |"]
        for f, n, c, score in rows:
            table.append("| %s | %d | %d | %d | %d | %d | %.0f %% |" % (
                f, n, c["stillborn"], c["equivalent"], c["killed"], c["survived"],
                100.0 * score))
        text = "\n".join(table)
        print("\nmutate: seed %d, %d mutants a file\n%s" % (args.seed, args.n, text))
        if gaps:
            print("survivors (the suite's gaps):\n  " + "\n  ".join(gaps))
        if args.report:
            write_report(args.report, args, text, gaps)
        return 0 if all(score >= 0.9 for _, _, _, score in rows) else 1
    finally:
        log.close()
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)


def site_keys(text):
    """Each site's (line, column, original, replacement, operator), in order."""
    return [(line_of(text, a), a - text.rfind("\n", 0, a), " ".join(text[a:b].split()),
             new or "(removed)", op) for (a, b, new, op) in sites(text)]


def shape(key):
    """A site as a change of names or layout keeps it: its operator and
    text (a deleted statement's text may name a field otherwise)."""
    return (key[4], key[3]) if key[4] == "delete" else key[2:]


def remap(rev):
    """The equivalents' keys moved with their sites: a file changed since rev
    only by comments, names or layout has the same sites in the same order,
    so the k-th site of the old text is the k-th of the new."""
    path = os.path.join(ROOT, "scripts", "mutate_equivalent.txt")
    out, moved, bad, cache = [], 0, 0, {}
    for raw in open(path, encoding="utf-8"):
        m = re.match(r"(\S+?):(\d+):(\d+): (.*?) -> (.*?)(\s+#.*)$", raw.rstrip("\n"))
        if not m:
            out.append(raw)
            continue
        f, line, col = m.group(1), int(m.group(2)), int(m.group(3))
        if f not in cache:
            old = subprocess.run(["git", "show", "%s:%s" % (rev, f)], cwd=ROOT,
                                 capture_output=True, text=True)
            new = open(os.path.join(ROOT, f), encoding="utf-8").read()
            cache[f] = (site_keys(old.stdout) if old.returncode == 0 else None, site_keys(new))
        old_keys, new_keys = cache[f]
        idx = [i for i, k in enumerate(old_keys or []) if k[0] == line and k[1] == col
               and k[2] == " ".join(m.group(4).split())]
        same = old_keys is not None and [shape(k) for k in old_keys] == [shape(k) for k in new_keys]
        if not idx or not same:
            print("remap: %s:%d:%d left as it is (%s)" % (f, line, col, "not a site at " + rev
                  if not idx else "its sites changed since " + rev))
            bad += 1
            out.append(raw)
            continue
        k = new_keys[idx[0]]
        moved += (k[0], k[1]) != (line, col)
        out.append("%s:%d:%d: %s -> %s%s\n" % (f, k[0], k[1], k[2], m.group(5), m.group(6)))
    open(path, "w", encoding="utf-8").writelines(out)
    print("remap: %d keys moved, %d left" % (moved, bad))
    return 1 if bad else 0


def write_report(path, args, table, gaps):
    """The table between the <!-- mutate --> markers of path."""
    body = ("<!-- mutate -->\n`make mutate` (seed %d, %d mutants a file; %s):\n\n%s\n\n%s\n"
            "<!-- /mutate -->" % (args.seed, args.n, time.strftime("%Y-%m-%d"), table,
                                  "Survivors: " + ("; ".join(gaps) if gaps else "none beyond "
                                                   "scripts/mutate_equivalent.txt.")))
    old = open(path, encoding="utf-8").read()
    if "<!-- mutate -->" in old:
        old = re.sub(r"<!-- mutate -->.*?<!-- /mutate -->", lambda _: body, old, flags=re.S)
    else:
        old = old.rstrip("\n") + "\n\n" + body + "\n"
    open(path, "w", encoding="utf-8").write(old)


if __name__ == "__main__":
    sys.exit(main())
