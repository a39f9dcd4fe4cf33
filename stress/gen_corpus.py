#!/usr/bin/env python3
"""stress/gen_corpus.py — (re)write the corpora and tables of `make stress`.

    python3 stress/gen_corpus.py

writes, deterministically:
  stress/corpus/lcp/     base LCPs (plain and Siconos), their mutants, the extreme problems,
                         and synthetic problems in the Siconos test set's style (sic-*.dat)
  stress/corpus/scene/   mutants of examples/scenes/two-sdof.json and three-buildings.json
  stress/corpus/record/  synthetic records (AT2 in both header styles and an older
                         processing's, COSMOS V2, text) and their mutants
  stress/cases/{lcp,scene,record}.tsv   one row per input:
        input <TAB> command <TAB> expect <TAB> regex <TAB> check
  input    a file under stress/corpus, or gen:FAMILY:BASE:MUTANT for a mutant
           over 64 kB, regenerated at run time by stress/run.py (same code)
  command  pound's arguments, {F} standing for the input (run in a scratch folder)
  expect   allowed exit statuses ("2": bad input; "0": a good one; "01": a
           well-formed LCP, solved or not; "012": anything clean); every scene
           row states one status
  regex    what the one stderr line of an exit 2 must match (scene rows: the
           FILE:LINE:COL and the field, "f.json:12:10: structures[0].T0: ")
  check    an extra check: verify-lcp (a "solved" answer is recomputed);
           output (scene rows, run with -o out.csv or -o out.h5: after exit 0
           the output is whole, after a refusal nothing is left)

stress/run.py rebuilds all of this in memory at every run (build() below) and
fails, loudly, when a file is missing or differs: the in-repo corpus is always
expected.  Mutants of ../shared data (the Siconos LCPs, the PEER/COSMOS
records) are made at run time by stress/run.py: those files are external test
data, not copied; the synthetic sic-*.dat and synth*.{AT2,V2} stand in for
them here.  The journals of category 5 are made at run time too (their key
line is the current build's)."""
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
KINDS = ("lcp", "scene", "record")


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


def scene_regex(fname, m):
    """FILE:LINE:COL, then the field the mutant breaks (or jansson's message)."""
    if m.name.startswith("excitation.record="):  # the record file or the field is named
        return re.escape(fname) + r"|record|/dev/|no-such-record"
    head = line_regex("scene", fname, m.where)
    if not m.field:
        return head
    if m.field.startswith("missing:"):
        return head + r"missing field '(%s)'" % m.field[len("missing:"):]
    return head + re.escape(m.field) + r"(: |\.|\[)"


class Sink:
    """The files of the corpus (relative to stress/) as bytes, in memory."""

    def __init__(self):
        self.files = {}

    def write(self, rel, data):
        self.files[rel] = data if isinstance(data, bytes) else data.encode("latin-1")


def gen_lcp(rows, out):
    d = "corpus/lcp"
    bases = {
        "base2.lcp": "# 2 x 2 SPD, solution z = (4/3, 7/3)\n2\n2 1\n1 2\n-5 -6\n",
        "murty4.lcp": "# Murty (1978), n = 4\n4\n1 0 0 0\n2 1 0 0\n2 2 1 0\n2 2 2 1\n-1 -1 -1 -1\n",
        "tridiag5.lcp": "5\n2 -1 0 0 0\n-1 2 -1 0 0\n0 -1 2 -1 0\n0 0 -1 2 -1\n0 0 0 -1 2\n"
                        "-1 0.5 -2 0 -1\n",
        "tiny3.dat": "3\n0\n3\n3\n3\t3\n4 1 0\n1 4 1\n0 1 4\n-1 -2 3\nfree text after q\n",
    }
    # the Siconos test set's classes, in its style (../shared is not needed);
    # the mutants of three of them, as run.py makes for CPS_1, mmc and trivial
    sic = {name: mutate.lcp_siconos_styled(M, q, t) for name, M, q, t in mutate.siconos_set()}
    sic_mutated = ("sic-degenerate.dat", "sic-spd-26.dat", "sic-diagonal-9.dat")
    for name, text in list(bases.items()) + list(sic.items()):
        sub = "sic/" if name in sic else ""
        out.write("%s/%s%s" % (d, sub, name), text)
        for solver in (("auto", "lemke", "structured", "pgs") if name in sic else (None,)):
            rows.append((sub + name, "lcp {F} --json" + (" --solver " + solver if solver else ""),
                         "01", "", "verify-lcp"))
        if name in sic and name not in sic_mutated:
            continue
        for m in mutate.lcp_mutants(text, siconos=name.endswith(".dat")):
            stem, ext = os.path.splitext(name)
            fname = "%s--%s%s" % (stem, safe(m.name), ext)
            if len(m.data) > BIG:
                rows.append(("gen:lcp:%s:%s" % (sub + name, m.name), "lcp {F} --json", m.expect,
                             lcp_regex(fname), "verify-lcp"))
                continue
            out.write(d + "/mut/" + fname, m.data)
            rows.append(("mut/" + fname, "lcp {F} --json", m.expect,
                         line_regex("lcp", fname, m.where), "verify-lcp"))
        # the wrong format forced
        forced = "plain" if name.endswith(".dat") else "siconos"
        rows.append((sub + name, "lcp {F} --json --format " + forced,
                     "2" if forced == "siconos" else "012", re.escape(name), "verify-lcp"))
    for name, M, q in mutate.lcp_extremes():
        for ext, fn in ((".lcp", mutate.lcp_plain), (".dat", mutate.lcp_siconos)):
            if ext == ".dat" and len(q) > 30:
                continue
            fname = "extreme-%s%s" % (safe(name), ext)
            out.write(d + "/extreme/" + fname, fn(M, q, "stress: " + name))
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


def scene_command(k):
    """Every scene row writes an output, CSV and HDF5 in turn: a refused
    scene must leave neither the file nor its temporary."""
    return "simulate --scene {F} --json -o " + ("out.csv" if k % 2 == 0 else "out.h5")


def gen_scene(rows, out):
    d = "corpus/scene"
    k = 0
    for base in ("two-sdof.json", "three-buildings.json"):
        with open(os.path.join(ROOT, "examples", "scenes", base)) as f:
            text = f.read()
        for ext in ("csv", "h5"):
            rows.append(("../../../examples/scenes/" + base,
                         "simulate --scene {F} --json -o out." + ext, "0", "", "output"))
        for m in mutate.scene_mutants(text, SCENE_FIELDS.get(base)):
            assert m.expect in ("0", "2"), (base, m.name, m.expect)
            fname = "%s--%s.json" % (base[:-5], safe(m.name))
            data = m.data
            if b"SELF" in data:
                data = data.replace(b'"SELF"', json.dumps(fname).encode())
            regex = scene_regex(fname, m) if m.expect == "2" else ""
            cmd = scene_command(k)
            k += 1
            if m.name == "structures-100001":
                # CSV takes any count; HDF5 is refused up front beyond 5000
                # groups (docs/formats.md), naming -o
                gen = "gen:scene:%s:%s" % (base, m.name)
                rows.append((gen, "simulate --scene {F} --json -o out.csv", "0", "", "output"))
                rows.append((gen, "simulate --scene {F} --json -o out.h5", "2",
                             r"^pound: simulate: \-o out\.h5: 100001 structures", "output"))
                continue
            if len(data) > BIG:
                rows.append(("gen:scene:%s:%s" % (base, m.name), cmd, m.expect, regex, "output"))
                continue
            out.write(d + "/mut/" + fname, data)
            rows.append(("mut/" + fname, cmd, m.expect, regex, "output"))


def gen_record(rows, out):
    d = "corpus/record"
    acc = mutate.synthetic_acc()
    at2 = mutate.at2_text(len(acc), 0.01, acc)
    at2b = mutate.at2_text(len(acc), 0.01, acc, header_style=2)
    at2c = mutate.at2_text(len(acc), 0.01, acc, header_style=3)
    v2 = mutate.v2_text(len(acc), 0.01, [a * 980.665 for a in acc])
    txt = "# t [s]  a [m/s2]: a synthetic pulse-like record\n" + "".join(
        "%.4f %.6e\n" % (k * 0.01, a * 9.80665) for k, a in enumerate(acc))
    bases = {"synth.AT2": (at2, "at2"), "synth-npts-dt.AT2": (at2b, "at2"),
             "synth-touching-crcrlf.AT2": (at2c, None), "synth.V2": (v2, "v2"),
             "synth.txt": (txt, "text")}
    for name, (text, kind) in bases.items():
        out.write(d + "/" + name, text)
        units = " --units m/s2" if kind == "text" else ""
        cmd = "record {F} --json" + units
        rows.append((name, cmd, "0", "", ""))
        if kind is None:
            continue
        for m in mutate.record_mutants(text, kind):
            stem, ext = os.path.splitext(name)
            fname = "%s--%s%s" % (stem, safe(m.name), ext)
            regex = line_regex("record", fname, m.where)
            if len(m.data) > BIG:
                rows.append(("gen:record:%s:%s" % (name, m.name), cmd, m.expect, regex, ""))
                continue
            out.write(d + "/mut/" + fname, m.data)
            rows.append(("mut/" + fname, cmd, m.expect, regex, ""))
    # the records as excitations: the run must stay clean
    for name in ("synth.AT2", "synth.V2", "synth.txt"):
        units = " --units m/s2" if name.endswith(".txt") else ""
        for method in ("moreau", "event", "penalty"):
            rows.append((name, "simulate --record {F}%s --T0 0.8 --gap 0.01 --method %s --json"
                         % (units, method), "0", "", ""))


def build():
    """Every file of the corpus and the tables, {path relative to stress/:
    bytes}, and the number of rows of each table."""
    out = Sink()
    counts = {}
    for kind, fn in (("lcp", gen_lcp), ("scene", gen_scene), ("record", gen_record)):
        rows = []
        fn(rows, out)
        text = "# input\tcommand\texpect\tregex\tcheck   (written by stress/gen_corpus.py)\n"
        for r in rows:
            assert not any("\t" in c or "\n" in c for c in r), r
            text += "\t".join(r) + "\n"
        out.write("cases/%s.tsv" % kind, text.encode("utf-8"))
        counts[kind] = len(rows)
    return out.files, counts


def main():
    files, counts = build()
    for sub in KINDS:
        shutil.rmtree(os.path.join(HERE, "corpus", sub), ignore_errors=True)
    for rel, data in files.items():
        p = os.path.join(HERE, rel)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "wb") as f:
            f.write(data)
    for kind in KINDS:
        print("%s: %d cases" % (kind, counts[kind]))


if __name__ == "__main__":
    main()
