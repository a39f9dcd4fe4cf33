#!/usr/bin/env python3
"""stress/gen_corpus.py — (re)write the corpora and tables of `make stress`.

    python3 stress/gen_corpus.py

writes, deterministically:
  stress/corpus/lcp/     base LCPs (plain and Siconos), their mutants, the extreme problems
  stress/corpus/scene/   mutants of examples/scenes/two-sdof.json and three-buildings.json
  stress/corpus/record/  a synthetic AT2 and text record and their mutants
  stress/cases/{lcp,scene,record}.tsv   one row per input:
        input <TAB> command <TAB> expect <TAB> regex <TAB> check
  input    a file under stress/corpus, or gen:FAMILY:BASE:MUTANT for a mutant
           over 256 kB, regenerated at run time by stress/run.py (same code)
  command  pound's arguments, {F} standing for the input (run in a scratch folder)
  expect   allowed exit statuses ("2": bad input; "01": a well-formed input,
           solved or not; "012": anything clean)
  regex    what the one stderr line of an exit 2 must match
  check    an extra check: verify-lcp (a "solved" answer is recomputed)

Mutants of ../shared data (the Siconos LCPs, the PEER/COSMOS records) are made
at run time by stress/run.py: those files are external test data, not copied.
The journals of category 5 are made at run time too (their key line is the
current build's)."""
import json
import os
import re
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import mutate  # noqa: E402

BIG = 64 * 1024


def safe(name):
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_")[:80]


def lcp_regex(fname):
    return re.escape(fname) + r": line \d+"


def line_regex(kind, fname, where):
    f = re.escape(fname)
    if kind == "scene":
        return f + (r":\d+:\d+: " if where == "line" else r"(:\d+:\d+)?: ")
    if kind == "record":
        return f + (r":\d+: " if where == "line" else r"(:\d+)?: ")
    return lcp_regex(fname) if where == "line" else f


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode("latin-1"))


def gen_lcp(rows):
    d = os.path.join(HERE, "corpus", "lcp")
    bases = {
        "base2.lcp": "# 2 x 2 SPD, solution z = (4/3, 7/3)\n2\n2 1\n1 2\n-5 -6\n",
        "murty4.lcp": "# Murty (1978), n = 4\n4\n1 0 0 0\n2 1 0 0\n2 2 1 0\n2 2 2 1\n-1 -1 -1 -1\n",
        "tridiag5.lcp": "5\n2 -1 0 0 0\n-1 2 -1 0 0\n0 -1 2 -1 0\n0 0 -1 2 -1\n0 0 0 -1 2\n"
                        "-1 0.5 -2 0 -1\n",
        "tiny3.dat": "3\n0\n3\n3\n3\t3\n4 1 0\n1 4 1\n0 1 4\n-1 -2 3\nfree text after q\n",
    }
    for name, text in bases.items():
        write(os.path.join(d, name), text)
        rows.append((name, "lcp {F} --json", "01", "", "verify-lcp"))
        for m in mutate.lcp_mutants(text, siconos=name.endswith(".dat")):
            stem, ext = os.path.splitext(name)
            fname = "%s--%s%s" % (stem, safe(m.name), ext)
            if len(m.data) > BIG:
                rows.append(("gen:lcp:%s:%s" % (name, m.name), "lcp {F} --json", m.expect,
                             lcp_regex(fname), "verify-lcp"))
                continue
            write(os.path.join(d, "mut", fname), m.data)
            rows.append(("mut/" + fname, "lcp {F} --json", m.expect,
                         line_regex("lcp", fname, m.where), "verify-lcp"))
        # the wrong format forced
        forced = "plain" if name.endswith(".dat") else "siconos"
        rows.append((name, "lcp {F} --json --format " + forced, "2" if forced == "siconos" else "012",
                     re.escape(name), "verify-lcp"))
    for name, M, q in mutate.lcp_extremes():
        for ext, fn in ((".lcp", mutate.lcp_plain), (".dat", mutate.lcp_siconos)):
            if ext == ".dat" and len(q) > 30:
                continue
            fname = "extreme-%s%s" % (safe(name), ext)
            write(os.path.join(d, "extreme", fname), fn(M, q, "stress: " + name))
            for solver in ("auto", "lemke", "structured", "pgs"):
                rows.append(("extreme/" + fname, "lcp {F} --json --solver " + solver, "01", "",
                             "verify-lcp"))


SCENE_FIELDS = {
    "three-buildings.json": {
        "structures[0].masses[1]", "structures[0].stiffnesses[0]", "structures[1].storeys",
        "structures[1].mass", "structures[1].T0", "structures[1].xi", "contacts[1].levels[2]",
        "contacts[2].gap", "contacts[0].eps", "tend", "excitation.pulse", "excitation.dir",
        "structures[2].name", "contacts[1].b"},
}


def gen_scene(rows):
    d = os.path.join(HERE, "corpus", "scene")
    for base in ("two-sdof.json", "three-buildings.json"):
        with open(os.path.join(ROOT, "examples", "scenes", base)) as f:
            text = f.read()
        rows.append(("../../../examples/scenes/" + base, "simulate --scene {F} --json", "0", "", ""))
        for m in mutate.scene_mutants(text, SCENE_FIELDS.get(base)):
            fname = "%s--%s.json" % (base[:-5], safe(m.name))
            data = m.data
            if b"SELF" in data:
                data = data.replace(b'"SELF"', json.dumps(fname).encode())
            regex = line_regex("scene", fname, m.where)
            if m.name.startswith("excitation.record="):  # the record file or the field is named
                regex = re.escape(fname) + r"|record|/dev/|no-such-record"
            if len(data) > BIG:
                rows.append(("gen:scene:%s:%s" % (base, m.name), "simulate --scene {F} --json",
                             m.expect, regex, ""))
                continue
            write(os.path.join(d, "mut", fname), data)
            rows.append(("mut/" + fname, "simulate --scene {F} --json", m.expect, regex, ""))


def gen_record(rows):
    d = os.path.join(HERE, "corpus", "record")
    acc = mutate.synthetic_acc()
    at2 = mutate.at2_text(len(acc), 0.01, acc)
    at2b = mutate.at2_text(len(acc), 0.01, acc, header_style=2)
    txt = "# t [s]  a [m/s2]: a synthetic pulse-like record\n" + "".join(
        "%.4f %.6e\n" % (k * 0.01, a * 9.80665) for k, a in enumerate(acc))
    bases = {"synth.AT2": (at2, "at2"), "synth-npts-dt.AT2": (at2b, "at2"), "synth.txt": (txt, "text")}
    for name, (text, kind) in bases.items():
        write(os.path.join(d, name), text)
        units = " --units m/s2" if kind == "text" else ""
        cmd = "record {F} --json" + units
        rows.append((name, cmd, "0", "", ""))
        for m in mutate.record_mutants(text, kind):
            stem, ext = os.path.splitext(name)
            fname = "%s--%s%s" % (stem, safe(m.name), ext)
            regex = line_regex("record", fname, m.where)
            if len(m.data) > BIG:
                rows.append(("gen:record:%s:%s" % (name, m.name), cmd, m.expect, regex, ""))
                continue
            write(os.path.join(d, "mut", fname), m.data)
            rows.append(("mut/" + fname, cmd, m.expect, regex, ""))
    # the records as excitations: the run must stay clean
    for name in ("synth.AT2", "synth.txt"):
        units = " --units m/s2" if name.endswith(".txt") else ""
        for method in ("moreau", "event", "penalty"):
            rows.append((name, "simulate --record {F}%s --T0 0.8 --gap 0.01 --method %s --json"
                         % (units, method), "0", "", ""))


def main():
    for sub in ("lcp", "scene", "record"):
        shutil.rmtree(os.path.join(HERE, "corpus", sub), ignore_errors=True)
    os.makedirs(os.path.join(HERE, "cases"), exist_ok=True)
    for kind, fn in (("lcp", gen_lcp), ("scene", gen_scene), ("record", gen_record)):
        rows = []
        fn(rows)
        with open(os.path.join(HERE, "cases", kind + ".tsv"), "w") as f:
            f.write("# input\tcommand\texpect\tregex\tcheck   (written by stress/gen_corpus.py)\n")
            for r in rows:
                assert not any("\t" in c or "\n" in c for c in r), r
                f.write("\t".join(r) + "\n")
        print("%s: %d cases" % (kind, len(rows)))


if __name__ == "__main__":
    main()
