"""stress/mutate.py — the mutations of pound's input files, shared by
stress/gen_corpus.py (which writes stress/corpus/ and stress/cases/) and
stress/run.py (which mutates ../shared data at run time: those files are
external test data, not copied into the project).

Each generator returns a list of Mutant(name, data, expect, where, field):
  expect  the exit statuses allowed, as a string: "2" bad input, "0" a good
          one, "01" a well-formed problem (solved or not), "012" anything
          clean (scene mutants always state one status)
  where   what an exit-2 message must name: "line" FILE:LINE (the readers'
          FILE: line N / FILE:N / FILE:N:C forms), "file" the file's name
  field   scene mutants: the field path the message names right after
          FILE:LINE:COL ("structures[0].T0"; "missing:A|B" for "missing
          field 'A'"), or None for a syntax error
"""
import json
import random
import re
from collections import namedtuple

Mutant = namedtuple("Mutant", "name data expect where field", defaults=(None,))


def _tokens(text):
    """(start, end) spans of the whitespace-separated tokens outside '#' comments."""
    spans = []
    for m in re.finditer(r"#[^\n]*|[^\s]+", text):
        if not m.group().startswith("#"):
            spans.append((m.start(), m.end()))
    return spans


def _replace_token(text, k, new):
    s, e = _tokens(text)[k]
    return text[:s] + new + text[e:]


def _adder(out, encoding):
    """add(name, data, expect, where, field): one Mutant onto out (text encoded)."""
    def add(name, data, expect="2", where="line", field=None):
        if isinstance(data, str):
            data = data.encode(encoding)
        out.append(Mutant(name, data, expect, where, field))
    return add


def junk(seed, n):
    r = random.Random(seed)
    return bytes(r.randrange(256) for _ in range(n))


# ---- LCP files (docs/lcp.md §8) ---------------------------------------------


def lcp_mutants(text, siconos=False):
    """Mutants of an LCP file's text (plain, or Siconos with siconos=True)."""
    toks = _tokens(text)
    ntext = text[toks[0][0]:toks[0][1]]
    first = 6 if siconos else 1          # the first entry of M
    last = len(toks) - 1                  # the last entry of q (plain)
    if siconos:
        # Siconos files may carry free text after q: q ends at 6 + n*n + n - 1
        n = int(ntext)
        last = 5 + n * n + n
    mid = (first + last) // 2
    out = []

    add = _adder(out, "latin-1")

    b = text
    add("empty", "")
    add("blank", "  \n\t\n\n")
    add("comment-only", "# nothing but a comment\n")
    add("n-only", ntext + "\n")
    # A cut that leaves M and q whole (a Siconos trailer) or leaves the last
    # entry a shorter number ("6.01" cut to "6") is a well-formed file: no
    # reader can tell it was cut, so it must be read (or solved), not refused.
    half = len(b) // 2
    add("trunc-half", b[:half], "01" if half >= toks[last][1] else "2")
    add("trunc-last-token", b[: toks[last][0]])
    cut = toks[last][0] + 1 if toks[last][1] - toks[last][0] > 1 else toks[last][0]
    add("trunc-in-number", b[:cut], "01" if re.fullmatch(r"[0-9]", b[toks[last][0]:cut]) else "2")
    add("trunc-1byte", b[:1])
    for name, val, exp in [("nan", "nan", "2"), ("NaN", "NaN", "2"), ("inf", "inf", "2"),
                           ("-inf", "-inf", "2"), ("infinity", "Infinity", "2"),
                           ("1e999", "1e999", "2"), ("-1e999", "-1e999", "2"),
                           ("1e-999", "1e-999", "012"), ("letters", "abc", "2"),
                           ("comma-decimal", "1,5", "2"), ("two-dots", "1.5.2", "2"),
                           ("hex", "0x10", "012"), ("trailing-e", "1e", "2"),
                           ("sign-only", "-", "2"), ("plus-sign", "+2", "012"),
                           ("d-exponent", "1d3", "2"),
                           ("long-number", "1" * 400, "2"),
                           ("long-fraction", "0." + "0" * 400 + "1", "012"),
                           ("long-digits", "1." + "1" * 5000, "012")]:
        add("entry-" + name, _replace_token(b, mid, val), exp)
    add("q-nan", _replace_token(b, last, "nan"))
    # the size n
    for name, val, exp in [("n-zero", "0", "2"), ("n-negative", "-2", "2"),
                           ("n-fraction", "2.5", "2"), ("n-exp", "2e0", "2"),
                           ("n-hex", "0x2", "2"), ("n-letters", "x", "2"),
                           ("n-46341", "46341", "2"), ("n-int-max", "2147483647", "2"),
                           ("n-2^31", "2147483648", "2"), ("n-2^32+2", "4294967298", "2"),
                           ("n-huge", "9" * 30, "2"), ("n-nan", "nan", "2"),
                           ("n-46340-short", "46340", "2")]:
        add(name, _replace_token(b, 0, val), exp)
    n0 = int(ntext)
    add("n-plus-one", _replace_token(b, 0, str(n0 + 1)))
    add("n-minus-one", _replace_token(b, 0, str(n0 - 1)) if n0 > 1 else _replace_token(b, 0, "0"))
    if siconos:
        add("extra-text", b + "\n7 8 9 free text\n", "01")
        add("storage-1", _replace_token(b, 1, "1"))
        add("storage-neg", _replace_token(b, 1, "-1"))
        add("rows-differ", _replace_token(b, 2, str(n0 + 1)), "012")
        add("cols-differ", _replace_token(b, 3, str(n0 + 1)), "012")
        add("dims-line-differ", _replace_token(b, 5, str(n0 + 1)), "012")
        add("rows-zero", _replace_token(b, 2, "0"), "012")
        add("rows-negative", _replace_token(b, 4, "-1"), "012")
    else:
        add("extra-token", b.rstrip("\n") + " 7\n")
        add("extra-text", b + "junk\n")
    add("binary-junk", junk(1, 512), "2")
    add("binary-after-n", ntext.encode() + b"\n" + junk(2, 256), "2")
    add("nul-inside", b[: toks[mid][0]] + "\0" + b[toks[mid][0]:], "2")
    add("bom", "\ufeff".encode("utf-8").decode("latin-1") + b, "012")
    add("crlf", b.replace("\n", "\r\n"), "01")
    add("cr-only", b.replace("\n", "\r"), "012")
    add("no-final-newline", b.rstrip("\n"), "01")
    add("tabs", b.replace(" ", "\t"), "01")
    add("comment-eof-no-newline", b.rstrip("\n") + "\n# end", "01")
    add("long-comment", "#" + "x" * (1 << 17) + "\n" + b, "01")
    add("long-blank-line", " " * (1 << 17) + "\n" + b, "01")
    add("minus-zero", re.sub(r"(?m)^(\s*)0(\s)", r"\1-0\2", b), "01")
    return out


def lcp_plain(M, q, comment=None):
    n = len(q)
    lines = []
    if comment:
        lines.append("# " + comment)
    lines.append(str(n))
    for i in range(n):
        lines.append(" ".join(repr(float(M[i][j])) for j in range(n)))
    lines.append(" ".join(repr(float(x)) for x in q))
    return "\n".join(lines) + "\n"


def lcp_siconos(M, q, comment=None):
    n = len(q)
    lines = [str(n), "0", str(n), str(n), "%d\t%d" % (n, n)]
    for j in range(n):  # each printed line is a column
        lines.append(" ".join(repr(float(M[i][j])) for i in range(n)))
    lines.append(" ".join(repr(float(x)) for x in q))
    if comment:
        lines.append(comment)
    return "\n".join(lines) + "\n"


def lcp_extremes():
    """Numerically extreme but well-formed problems: (name, M, q)."""
    r = random.Random(7)
    out = []
    base_M = [[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]]
    base_q = [-1.0, -2.0, 3.0]
    # (scaled by 1e307, not 1e308: 4e308 would overflow to inf, which is not
    # a well-formed problem and is refused)
    for s in ["1e300", "1e-300", "1e307", "1e-308", "4.9e-324"]:
        f = float(s)
        out.append(("scale-M-" + s, [[x * f for x in row] for row in base_M], base_q))
        out.append(("scale-q-" + s, base_M, [x * f for x in base_q]))
    out.append(("q-huge-M-tiny", [[x * 1e-300 for x in row] for row in base_M],
                [x * 1e300 for x in base_q]))
    out.append(("q-tiny-M-huge", [[x * 1e300 for x in row] for row in base_M],
                [x * 1e-300 for x in base_q]))
    out.append(("rows-1e300-1e-300", [[x * (1e300 if i % 2 else 1e-300) for x in row]
                                      for i, row in enumerate(base_M)],
                [x * (1e300 if i % 2 else 1e-300) for i, x in enumerate(base_q)]))
    out.append(("zero-M-neg-q", [[0.0] * 3 for _ in range(3)], [-1.0, 0.0, 1.0]))
    out.append(("zero-M-pos-q", [[0.0] * 3 for _ in range(3)], [1.0, 0.0, 2.0]))
    out.append(("singular-rank1", [[1.0, 1.0, 1.0]] * 3, [-1.0, -1.0, -1.0]))
    out.append(("denormal-M", [[4.9e-324 if i == j else 0.0 for j in range(3)]
                               for i in range(3)], [-1.0, 1.0, -1.0]))
    out.append(("cond-1e15", [[1.0, 1.0], [1.0, 1.0 + 1e-15]], [-1.0, -1.0 - 1e-15]))
    # found by fuzz_lcp: q of subnormals, whose solution z_0 = 6e-327 underflows;
    # z = (0, 5 ulp, 0) leaves w_0 = -2.5e-324 < 0 (a third of the row's scale)
    out.append(("subnormal-q-underflow", [[400.0, 0.1, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]],
                [-5e-324, -1e-322, 1.5e-323]))
    out.append(("cond-1e300-2x2", [[1e300, 1.0], [1.0, 1e-300]], [-1.0, -1.0]))
    for n in (8, 12):
        out.append(("hilbert-%d" % n, [[1.0 / (i + j + 1) for j in range(n)] for i in range(n)],
                    [-1.0] * n))
    n = 20
    out.append(("random-wide-exponents-20",
                [[r.choice([-1, 1]) * 10.0 ** r.uniform(-300, 300) for _ in range(n)]
                 for _ in range(n)],
                [r.choice([-1, 1]) * 10.0 ** r.uniform(-300, 300) for _ in range(n)]))
    out.append(("random-wide-exponents-pd-20",
                [[10.0 ** r.uniform(-300, 300) if i == j else r.uniform(-1e-300, 1e-300)
                  for j in range(n)] for i in range(n)],
                [-(10.0 ** r.uniform(-300, 300)) for _ in range(n)]))
    n = 30
    A = [[r.uniform(-1, 1) for _ in range(n)] for _ in range(n)]
    out.append(("random-nonsym-30", A, [r.uniform(-1, 1) for _ in range(n)]))
    # Murty's exponential example for Lemke: 2^n pivots (n = 16 exceeds the default cap)
    for n in (12, 16):
        out.append(("murty-%d" % n, [[1.0 if i == j else (2.0 if j < i else 0.0) for j in range(n)]
                                     for i in range(n)], [-1.0] * n))
    # a long tridiagonal Delassus-like row (structured solver's home ground)
    n = 200
    out.append(("tridiag-200", [[2.0 if i == j else (-1.0 if abs(i - j) == 1 else 0.0)
                                 for j in range(n)] for i in range(n)],
                [r.uniform(-1, 1) for _ in range(n)]))
    out.append(("tridiag-200-scaled-1e300", [[x * 1e300 for x in row] for row in out[-1][1]],
                out[-1][2]))
    return out



def _sic_num(x):
    return ("  %.24e " if x >= 0 else " %.24e ") % float(x)


def lcp_siconos_styled(M, q, trailer=None):
    """A Siconos-format file in the style of the Siconos test set: each
    printed line a column of M, numbers as "  %.24e" with a trailing blank,
    and free text after q (a remark or reference, to be ignored)."""
    n = len(q)
    lines = [str(n), "0", str(n), str(n), "%d\t%d" % (n, n)]
    for j in range(n):
        lines.append("".join(_sic_num(M[i][j]) for i in range(n)))
    lines.append("".join(_sic_num(x) for x in q))
    text = "\n".join(lines) + "\n"
    if trailer:
        text += "\n" + trailer + "\n"
    return text


def siconos_set():
    """Synthetic problems in the Siconos test set's file style, made here so
    that the suite does not depend on ../shared (whose files are external
    data, not copied): (name, M, q, trailer).  The classes of that set: a
    degenerate problem with a continuum of solutions, one with no solution
    (Lemke ends on a ray), a diagonal one, a dense SPD one of 26 unknowns, a
    nonsymmetric one with zero diagonal entries, Murty's exponential one."""
    r = random.Random(19)
    out = [("sic-degenerate.dat", [[1.0, 1.0], [1.0, 1.0]], [-1.0, -1.0],
            "stress: a continuum of solutions z_1 + z_2 = 1"),
           ("sic-no-solution.dat", [[0.0, -1.0, -1.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            [-1e-4, 1.0, 1.0], "stress: w_1 = -z_2 - z_3 - 1e-4 < 0: no solution"),
           ("sic-diagonal-9.dat", [[float(i + 1) if i == j else 0.0 for j in range(9)] for i in range(9)],
            [-1.0] * 9, "stress: diag(1..9), z_i = 1/i\n" + "".join(
                _sic_num(1.0 / (i + 1)) for i in range(9)))]
    n = 26
    A = [[r.uniform(-1, 1) * 1e5 for _ in range(n)] for _ in range(n)]
    spd = [[sum(A[k][i] * A[k][j] for k in range(n)) / n + (1e5 if i == j else 0.0)
            for j in range(n)] for i in range(n)]
    out.append(("sic-spd-26.dat", spd, [r.uniform(-1e3, 1e3) for _ in range(n)],
                "stress: a dense SPD matrix of 26 unknowns with entries near 1e5"))
    n = 40
    ns = [[0.0 if i == j else r.uniform(-1, 1) for j in range(n)] for i in range(n)]
    for i in range(n):
        for j in range(n):
            if (i + j) % 3 == 0 and i != j:
                ns[i][j] = abs(ns[i][j]) + abs(ns[j][i])
    out.append(("sic-nonsym-zero-diag-40.dat", ns, [r.uniform(-1, 1) for _ in range(n)],
                "stress: nonsymmetric, zero diagonal"))
    n = 6
    out.append(("sic-murty-6.dat", [[1.0 if i == j else (2.0 if j < i else 0.0) for j in range(n)]
                                    for i in range(n)], [-1.0] * n,
                "stress: Murty's exponential example, 2^6 pivots"))
    out.append(("sic-p-matrix-4.dat", [[3.0, 1.0, 0.0, -1.0], [-1.0, 2.0, 1.0, 1.0],
                                       [0.0, 1.0, 3.0, -1.0], [0.0, 0.0, 1.0, 2.0]],
                [-2.0, 1.0, -1.0, 1.0], "stress: a nonsymmetric P-matrix"))
    return out


def v2_text(npts, dt, acc_cms2):
    """A COSMOS/CDMG V2 file: a text header, the acceleration block (in
    cm/s^2, 8 values of 10 characters to a line), then the velocity and
    displacement blocks, which the reader does not read, and "/&"."""
    head = ["CORRECTED ACCELEROGRAM   00000-STRESS-00000.01       CHAN  1:  90 DEG",
            "SYNTHETIC STRONG-MOTION DATA               PROCESSED:  1/01/00, POUND STRESS SUITE",
            "STRESS SYNTHETIC EARTHQUAKE",
            "JAN 1, 2000 00:00 UTC",
            "STATION NO. 00000   0.000N, 0.000W",
            "INSTR PERIOD =  .0400 SEC,  DAMPING =  .600,  SENSITIVITY = 1.80 CM/G.",
            "                        RECORD LENGTH = %7.3f SEC." % (npts * dt),
            "  %d POINTS OF INSTRUMENT- AND BASELINE-CORRECTED ACCEL, VELOC AND DISPL DATA" % npts,
            "AT EQUALLY-SPACED INTERVALS OF   %.3f  SEC." % dt,
            "PEAK ACCELERATION =  %9.3f    CM/SEC/SEC" % max(acc_cms2, key=abs),
            ""]
    head += ["".join("%5d" % ((i * 7 + k) % 10) for k in range(16)) for i in range(4)]
    head += ["".join("%10.3f" % (0.001 * (i + k)) for k in range(8)) for i in range(6)]

    def block(what, units, vals):
        lines = [" %d POINTS OF %s DATA EQUALLY SPACED AT %5.3f SEC.  (UNITS: %s)"
                 % (len(vals), what, dt, units)]
        for k in range(0, len(vals), 8):
            lines.append("".join(("%10.3f" % v).replace("0.", ".", 1) if abs(v) < 1 else "%10.3f" % v
                                 for v in vals[k:k + 8]))
        return lines
    vel, disp, v, x = [], [], 0.0, 0.0
    for a in acc_cms2:
        v += a * dt
        x += v * dt
        vel.append(v)
        disp.append(x)
    body = block("ACCEL", "CM/SEC/SEC", acc_cms2) + block("VELOC", "CM/SEC", vel) + \
        block("DISPL", "CM", disp) + ["/&"]
    return "\n".join(head + body) + "\n"

# ---- scene files (docs/scenes.md) -------------------------------------------

# field -> (kind, domain, usable range) for the fields the example scenes use
# (docs/scenes.md §3: "Values are also held to usable ranges"); a value in the
# domain and in the usable range is accepted (exit 0), any other is refused
# (exit 2) with the field named
def _scene_domain(path):
    key = path[-1] if isinstance(path[-1], str) else path[-2]
    return {
        "ap": ("num", lambda x: x > 0, (1e-6, 1e4)), "Tp": ("num", lambda x: x > 0, (0.01, 1000)),
        "T0": ("num", lambda x: x > 0, (0.01, 1000)), "mass": ("num", lambda x: x > 0, (1e-6, 1e12)),
        "masses": ("num", lambda x: x > 0, (1e-6, 1e12)),
        "stiffnesses": ("num", lambda x: x > 0, (1e-11, 1e18)),
        "xi": ("num", lambda x: 0 <= x < 1, None), "eps": ("num", lambda x: 0 <= x <= 1, None),
        "gap": ("num", lambda x: x >= 0, (0, 1000)),
        # tend 0: derived from the excitation (docs/scenes.md: "(0, 100000] s (0: derived)")
        "tend": ("num", lambda x: x >= 0, (0, 1e5)),
        "scale": ("num", lambda x: x > 0, (1e-6, 1e6)),
        "storeys": ("int", lambda x: 1 <= x <= 100000, None), "levels": ("int", lambda x: x >= 1, None),
    }.get(key, ("other", None, None))


def _leaves(v, path=()):
    if isinstance(v, dict):
        for k, x in v.items():
            yield from _leaves(x, path + (k,))
    elif isinstance(v, list):
        for i, x in enumerate(v):
            yield from _leaves(x, path + (i,))
    else:
        yield path, v


def _set(doc, path, val):
    d = doc
    for p in path[:-1]:
        d = d[p]
    d[path[-1]] = val


MARK = "@@MUTANT@@"


def _with_raw(doc, path, raw, also=()):
    """doc serialised with the value at path (and at the paths of also)
    replaced by raw JSON text."""
    d = json.loads(json.dumps(doc))
    for p in (path,) + tuple(also):
        _set(d, p, MARK)
    return json.dumps(d, indent=1).replace('"%s"' % MARK, raw)


def _pathname(path):
    s = ""
    for p in path:
        s += "[%d]" % p if isinstance(p, int) else ("." if s else "") + p
    return s


def _name_refs(doc, name):
    """The paths of the contacts' sides that name structure `name`."""
    return [("contacts", i, side) for i, c in enumerate(doc.get("contacts") or [])
            for side in ("a", "b") if c.get(side) == name]


def scene_mutants(text, limit_fields=None):
    """Mutants of a scene file's text (a JSON object), each with one expected
    exit status and, for a refused one, the field its message names."""
    doc = json.loads(text)
    out = []

    add = _adder(out, "utf-8")

    b = text
    for frac in (0.1, 0.5, 0.9):
        add("trunc-%d%%" % int(frac * 100), b[: int(len(b) * frac)])
    add("trunc-last-byte", b.rstrip()[:-1])
    add("empty", "")
    add("whitespace", " \n\t\n")
    add("null", "null")
    add("array", "[]")
    add("empty-object", "{}", "2", field="missing:structures|excitation")
    add("number", "42")
    add("trailing-text", b.rstrip() + " trailing\n")
    add("two-objects", b.rstrip() + "\n" + b)
    add("binary-junk", junk(3, 600), "2", "file")
    add("nul-byte", b[:20] + "\0" + b[20:], "2", "file")
    add("latin1-byte", b.replace('"', '"\xe9', 1).encode("latin-1"), "2")
    # a UTF-8 byte-order mark: jansson refuses it at 1:1 (RFC 8259 lets a
    # parser refuse it); refused, with the position
    add("bom", "\ufeff" + b, "2")
    add("crlf", b.replace("\n", "\r\n"), "0")
    add("deep-nesting", '{"description": ' + "[" * 100000 + "]" * 100000 + "}", "2")
    add("unknown-top-key", json.dumps(dict(doc, bogus=1), indent=1), field="bogus")
    add("dup-top-key", b.rstrip().rstrip("}") + ', "tend": 1}' if "tend" in doc
        else b.rstrip().rstrip("}") + ', "tend": 1, "tend": 2}')
    add("dup-excitation-key", json.dumps(doc, indent=1).replace(
        '"excitation": {', '"excitation": {"ap": 1.0, ', 1))
    add("dup-structure-key", json.dumps(doc, indent=1).replace(
        '"name":', '"xi": 0.01, "xi": 0.02, "name":', 1))
    for k in ("excitation", "structures"):
        d = dict(doc)
        d.pop(k, None)
        add("missing-" + k, json.dumps(d, indent=1), field="missing:" + k)
    d = json.loads(b)
    d["structures"] = []
    add("no-structures", json.dumps(d, indent=1), field="structures")
    # values at every numeric leaf
    for path, v in _leaves(doc):
        if limit_fields and _pathname(path) not in limit_fields:
            continue
        kind, ok, usable = _scene_domain(path)
        if kind == "other" or isinstance(v, (str, bool)) or v is None:
            continue
        pn = _pathname(path)
        for raw, x in [("-1", -1.0), ("0", 0.0), ("1e308", 1e308), ("4.9e-324", 5e-324),
                       ("1e999", None), ("-1e999", None), ("NaN", None), ("Infinity", None),
                       ('"1"', None), ("true", None), ("null", None), ("[]", None),
                       ("{}", None), ("2.5", 2.5)]:
            if x is None:
                exp = "2"
            elif kind == "int":
                exp = "2" if x != int(x) or raw in ("1e308", "4.9e-324") or not ok(x) else "0"
            else:
                exp = "0" if ok(x) and (usable is None or usable[0] <= x <= usable[1]) else "2"
            if raw == "2.5" and kind != "int":
                continue
            # jansson's syntax errors (1e999, NaN, ...) name no field; an
            # array's entry is named by the array ("structures[0].masses:
            # storey 2 has mass -1") or by itself (".masses[1]")
            syntax = raw in ("1e999", "-1e999", "NaN", "Infinity")
            field = _pathname(path[:-1]) if isinstance(path[-1], int) else pn
            add("%s=%s" % (pn, raw), _with_raw(doc, path, raw), exp,
                field=None if syntax else field)
    # strings: names and enumerations; a structure's new name is used by its
    # contacts too, so that the name itself is what is judged
    for path, v in _leaves(doc):
        if not isinstance(v, str) or path[-1] == "description":
            continue
        pn = _pathname(path)
        if limit_fields and pn not in limit_fields:
            continue
        is_name = path[-1] == "name"
        refs = _name_refs(doc, v) if is_name else []
        for label, raw, exp in [("empty", '""', "2"), ("ctrl-u0001", '"A\\u0001"', "2"),
                                ("ctrl-raw", '"A\x01"', "2"), ("nul-u0000", '"A\\u0000"', "2"),
                                ("newline", '"A\\nB"', "2"), ("del", '"A\\u007f"', "2"),
                                ("long", '"' + "x" * 10000 + '"', "2"),
                                ("number", "1", "2"), ("null", "null", "2")]:
            # a raw control byte and \u0000 in a string are jansson's syntax errors
            add("%s=%s" % (pn, label), _with_raw(doc, path, raw, refs), exp,
                field=None if label in ("ctrl-raw", "nul-u0000") else pn)
        if is_name:
            add(pn + "=wall", _with_raw(doc, path, '"wall"', refs), field=pn)
            add(pn + "=slash", _with_raw(doc, path, '"a/b"', refs), field=pn)
            add(pn + "=utf8", _with_raw(doc, path, '"\u00e9t\u00e9"', refs), "0")
            add(pn + "=63-bytes", _with_raw(doc, path, '"' + "y" * 63 + '"', refs), "0")
            add(pn + "=64-bytes", _with_raw(doc, path, '"' + "y" * 64 + '"', refs), field=pn)
    # contacts that name what is not there
    if doc.get("contacts"):
        for label, val, exp in [("unknown-a", "Z", "2"), ("wall-wall", "wall", "2")]:
            d = json.loads(b)
            d["contacts"][0]["a"] = val
            if label == "wall-wall":
                d["contacts"][0]["b"] = "wall"
            add("contacts[0]." + label, json.dumps(d, indent=1), exp,
                field="contacts[0].a" if label == "unknown-a" else "contacts[0]")
        # a repeated level would join one pair of floors twice: refused
        # ("contacts[0]: ... are joined twice")
        for label, lv, field in [("levels-empty", [], ".levels"), ("levels-zero", [0], ".levels"),
                                 ("levels-neg", [-1], ".levels"), ("levels-big", [1000000000], ".levels"),
                                 ("levels-float", [1.5], ".levels"),
                                 ("levels-200000", [1] * 200000, ".levels"),
                                 ("levels-dup", [1, 1], "")]:
            d = json.loads(b)
            d["contacts"][0]["levels"] = lv
            add("contacts[0]." + label, json.dumps(d), "2", field="contacts[0]" + field)
    # huge arrays
    d = json.loads(b)
    d["structures"] = [{"name": "s%d" % i, "T0": 0.5 + (i % 3) * 0.1} for i in range(100001)]
    d["contacts"] = []
    d["tend"] = 1e-3
    add("structures-100001", json.dumps(d), "0")
    d = json.loads(b)
    d["structures"] = [{"name": "tall", "masses": [1.0] * 200000, "stiffnesses": [1e6] * 200000}]
    d["contacts"] = []
    d["tend"] = 1e-4
    add("masses-200000", json.dumps(d), "2", field="structures[0]")
    d = json.loads(b)
    d["structures"][0]["masses"] = [1.0] * 3
    add("mixed-forms", json.dumps(d, indent=1), field="structures[0]")
    # records named by the excitation (docs/records.md)
    for label, rec in [("dev-null", "/dev/null"), ("missing", "no-such-record.AT2"),
                       ("directory", "."), ("itself", "SELF"), ("dev-zero", "/dev/zero")]:
        d = json.loads(b)
        d["excitation"] = {"record": rec, "dir": "+x"}
        add("excitation.record=" + label, json.dumps(d, indent=1), "2", "file")
    return out


# ---- records (docs/records.md) -----------------------------------------------


def at2_text(npts, dt, acc, header_style=1):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD",
             "STRESS SYNTHETIC, 1/1/2000, POUND STRESS SUITE, 0",
             "ACCELERATION TIME SERIES IN UNITS OF G"]
    if header_style == 1:
        lines.append("NPTS=%7d, DT=%9.4f SEC" % (npts, dt))
    else:
        lines.append("%d    %.4f    NPTS, DT" % (npts, dt))
    # header_style 3: an older processing's file, numbers that touch
    # ("1.234567E-02-5.678901E-03") and CR CR LF line ends
    width = "%13.6E" if header_style == 3 else "%15.6E"
    for k in range(0, len(acc), 5):
        lines.append("".join(width % a for a in acc[k:k + 5]))
    return ("\r\r\n" if header_style == 3 else "\n").join(lines) + ("\r\r\n" if header_style == 3 else "\n")


def synthetic_acc(npts=400, dt=0.01, seed=11):
    """A pulse-like accelerogram in g: one cosine velocity pulse plus noise."""
    import math
    r = random.Random(seed)
    Tp, t0 = 1.2, 1.8
    acc = []
    for k in range(npts):
        t = k * dt
        a = 0.0
        if abs(t - t0) <= Tp:
            a = 0.4 * math.sin(2 * math.pi * (t - t0) / Tp) * 0.5 * (1 + math.cos(math.pi * (t - t0) / Tp))
        acc.append(a + 0.01 * r.uniform(-1, 1))
    return acc


def record_mutants(text, kind):
    """Mutants of a record's text: kind 'at2', 'v2' or 'text'."""
    out = []

    add = _adder(out, "latin-1")

    b = text
    lines = b.split("\n")
    add("empty", "")
    add("blank-lines", "\n\n\n")
    add("binary-junk", junk(4, 2000))
    add("nul-bytes", b[:300] + "\0\0\0" + b[300:])
    # Cut inside the last value, a record still holds its NPTS values (the
    # last one shorter); a text record or a COSMOS file cut after its
    # acceleration block is a shorter record: read or refused, both clean.
    add("trunc-half", b[: len(b) // 2], "2" if kind == "at2" else "02")
    add("trunc-in-number", b[: len(b) - 7], "02")
    add("crlf", b.replace("\n", "\r\n"), "0")
    add("cr-cr-lf", b.replace("\n", "\r\r\n"), "0")
    if kind == "at2":
        hdr = lines[3]
        m = re.search(r"(\d+)", hdr)
        npts = int(m.group(1))
        add("header-only", "\n".join(lines[:4]) + "\n")
        add("no-header", "\n".join(lines[4:]), "2")
        add("trunc-header", "\n".join(lines[:2]) + "\n")

        def hdr_sub(pat, rep):
            ls = list(lines)
            ls[3] = re.sub(pat, rep, ls[3], count=1)
            return "\n".join(ls)
        for label, val, exp in [("npts-more", str(npts + 100), "2"), ("npts-less", str(npts - 7), "2"),
                                ("npts-zero", "0", "2"), ("npts-one", "1", "2"),
                                ("npts-neg", "-5", "2"), ("npts-1e8", "100000000", "2"),
                                ("npts-1e9", "1000000000", "2"), ("npts-2^31", "2147483648", "2"),
                                ("npts-huge", "9" * 25, "2"), ("npts-letters", "abc", "2")]:
            add("NPTS=" + label, hdr_sub(r"\d+", val), exp)
        dtm = re.search(r"(DT=\s*)([-\d.Ee+]+)", hdr)
        if dtm:
            for label, val, exp in [("zero", "0", "2"), ("neg", "-.01", "2"), ("nan", "nan", "2"),
                                    ("inf", "inf", "2"), ("1e308", "1e308", "012"),
                                    ("4.9e-324", "4.9e-324", "012"), ("1e-300", "1e-300", "012"),
                                    ("letters", "x", "2"), ("1e999", "1e999", "2")]:
                add("DT=" + label, hdr_sub(r"DT=\s*[-\d.Ee+]+", "DT= " + val), exp)
        first_data = 4
    elif kind == "v2":
        first_data = next(i for i, ln in enumerate(lines) if re.search(r"POINTS OF ACCEL", ln)) + 1
        m = re.search(r"(\d+)\s+POINTS OF ACCEL", b)
        npts = int(m.group(1))
        for label, val in [("more", str(npts + 50)), ("zero", "0"), ("neg", "-3"),
                           ("huge", "999999999")]:
            add("points-" + label, b.replace(m.group(0), m.group(0).replace(str(npts), val, 1), 1))
        add("header-only", "\n".join(lines[: first_data + 2]) + "\n")
        add("spacing-zero", re.sub(r"(SPACED AT\s+)[\d.]+", r"\g<1>0.000", b, count=1))
        add("spacing-nan", re.sub(r"(SPACED AT\s+)[\d.]+", r"\g<1>nan", b, count=1))
    else:  # text: "t a" per line
        first_data = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
        data = [ln for ln in lines[first_data:] if ln.strip()]

        def with_line(k, new):
            d = list(data)
            d[k] = new
            return "\n".join(lines[:first_data] + d) + "\n"
        t1, a1 = data[1].split()
        add("one-line", "\n".join(lines[:first_data] + data[:1]) + "\n")
        add("one-column", "\n".join(lines[:first_data] + [ln.split()[1] for ln in data]) + "\n")
        add("three-columns", "\n".join(lines[:first_data] + [ln + " 0" for ln in data]) + "\n",
            "012")
        add("non-uniform-time", with_line(5, "%.6f %s" % (float(data[5].split()[0]) + 0.003,
                                                          data[5].split()[1])))
        add("time-backwards", with_line(5, "0.0 0.0"))
        add("time-repeated", with_line(5, data[4].split()[0] + " 0.0"))
        add("time-nan", with_line(3, "nan 0.0"))
        add("time-1e308", with_line(len(data) - 1, "1e308 0.0"))
        add("comma-separated", "\n".join(lines[:first_data] + [ln.replace(" ", ",") for ln in data]) + "\n",
            "012")
        add("all-zero", "\n".join(lines[:first_data] + ["%s 0" % ln.split()[0] for ln in data]) + "\n",
            "2", "file")
        add("huge-acc", "\n".join(lines[:first_data] + ["%s %s" % (ln.split()[0], "1e308" if i % 2 else "-1e308")
                                                        for i, ln in enumerate(data)]) + "\n", "012", "file")
        add("tiny-acc", "\n".join(lines[:first_data] + ["%s %s" % (ln.split()[0], "4.9e-324" if i % 2 else "0")
                                                        for i, ln in enumerate(data)]) + "\n", "012", "file")
        add("tiny-dt", "\n".join(lines[:first_data] + ["%.3e %s" % (i * 1e-300, ln.split()[1])
                                                       for i, ln in enumerate(data)]) + "\n", "012", "file")
        add("2-samples", "\n".join(lines[:first_data] + data[:2]) + "\n", "012", "file")
    # value mutations inside the data block
    k = min(first_data + 3, len(lines) - 2)
    for label, val, exp in [("nan", "NaN", "2"), ("inf", "Infinity", "2"), ("1e999", "1e999", "2"),
                            ("-1e999", "-1e999", "2"), ("letters", "abc", "2"),
                            ("1e308", "1e308", "012"), ("1e-308", "1e-308", "012"),
                            ("4.9e-324", "4.9e-324", "012"), ("long-number", "1" * 400, "2")]:
        ls = list(lines)
        toks = ls[k].split()
        if not toks:
            continue
        toks[-1] = val
        ls[k] = " ".join(toks) if kind == "text" else "".join("%15s" % t for t in toks)
        add("value-" + label, "\n".join(ls), exp, "line" if exp == "2" else "file")
    add("long-line", b.replace("\n", "\n" + " " * (1 << 17) + "\n", 1) if kind == "text"
        else b + (" " * (1 << 17)) + "\n", "012")
    return out


# ---- spectrum journals (docs/spectrum.md, cli/spectrum_journal.c) -----------------


def fnv1a(data):
    h = 2166136261
    for c in data:
        h ^= c
        h = (h * 16777619) & 0xFFFFFFFF
    return h


def journal_record(task, fields):
    """A record line with a valid checksum: fields is the text after the task."""
    body = ("T %d %s" % (task, fields)).encode()
    return body + b" #%08x\n" % fnv1a(body)


def journal_mutants(data, other_key_line):
    """Mutants of a journal (bytes) made by a real interrupted sweep.
    expect: "0=" resumes and the output must equal the uninterrupted one; "0"
    resumes (output not compared); "02" either a clean restart or refused;
    "2" refused; "012" anything clean."""
    lines = data.split(b"\n")
    magic, key = lines[0] + b"\n", lines[1] + b"\n"
    recs = [ln + b"\n" for ln in lines[2:] if ln]
    out = []

    def add(name, d, expect, where="file"):
        out.append(Mutant(name, d, expect, where))

    add("intact", data, "0=")
    add("empty", b"", "02")
    add("magic-only", magic, "02")
    add("torn-key", magic + key[: len(key) // 2], "02")
    add("header-only", magic + key, "0=")
    add("wrong-magic", b"pound-spectrum-journal 9\n" + key + b"".join(recs), "2")
    add("other-file", b"hello\n", "2")
    add("other-sweep", magic + other_key_line + b"".join(recs), "2")
    add("key-trailing-space", magic + key[:-1] + b" \n" + b"".join(recs), "2")
    add("torn-last-line", magic + key + b"".join(recs)[:-9], "0=")
    add("torn-in-checksum", magic + key + b"".join(recs)[:-3], "0=")
    bad = recs[0].replace(b"T ", b"T  ", 1)
    add("bad-checksum-first", magic + key + bad + b"".join(recs[1:]), "0=")
    flip = bytearray(recs[-1])
    flip[6] ^= 1
    add("bit-flip-last", magic + key + b"".join(recs[:-1]) + bytes(flip), "0=")
    add("duplicate-records", magic + key + b"".join(recs) + b"".join(recs), "0=")
    add("task-out-of-range", magic + key + b"".join(recs) +
        journal_record(10 ** 9, "0x1p+0 0x0p+0 0x1p+0 0x0p+0 nan 0 10 0x0p+0"), "0=")
    add("task-negative", magic + key + b"".join(recs) +
        journal_record(-1, "0x1p+0 0x0p+0 0x1p+0 0x0p+0 nan 0 10 0x0p+0"), "0=")
    add("task-huge-digits", magic + key + b"".join(recs) +
        journal_record(0, "").replace(b"T 0", b"T " + b"9" * 40), "0=")
    add("fields-missing", magic + key + b"".join(recs) + journal_record(1, "0x1p+0"), "0=")
    add("forged-nan", magic + key + journal_record(0, "nan nan nan nan nan -1 -1 nan") +
        b"".join(recs), "012")
    add("forged-huge", magic + key + journal_record(0, "0x1p+1023 0x1p+1023 0x1p+1023 1e308 1e308 "
                                                       "9223372036854775807 9223372036854775807 1e308") +
        b"".join(recs), "012")
    add("junk-appended", magic + key + b"".join(recs) + junk(5, 300) + b"\n", "0=")
    add("junk-instead-of-records", magic + key + junk(6, 2000) + b"\n", "0=")
    add("nul-in-record", magic + key + recs[0][:5] + b"\0" + recs[0][5:] + b"".join(recs[1:]), "0=")
    add("crlf", data.replace(b"\n", b"\r\n"), "02")
    add("long-line", magic + key + b"T " + b"1" * (1 << 17) + b"\n" + b"".join(recs), "0=")
    add("many-garbage-lines", magic + key + b"x\n" * 200000 + b"".join(recs), "0=")
    add("no-newline-anywhere", (magic + key).replace(b"\n", b" ") + b"".join(recs).replace(b"\n", b" "),
        "02")
    return out
