#!/usr/bin/env python3
"""gen_py_structs.py -- python/pound/_structs.py, the Python package's ctypes
mirrors of libpound's public structs, generated from the public headers.

    python3 scripts/gen_py_structs.py            (re)write python/pound/_structs.py
    python3 scripts/gen_py_structs.py --check    exit 1 with a diff when it is stale
    python3 scripts/gen_py_structs.py --stdout   print what it would write

Reads the four public headers (HEADERS, in the project's own regular style:
`typedef struct NAME { fields; } NAME;`, `typedef enum {...} NAME;`,
function-pointer typedefs, `#define NAME value` and `enum { NAME = value }`
constants) with the comments stripped, and writes one ctypes Structure per
struct of STRUCTS (and per struct they hold by value), named in CamelCase
(pd_osc_result -> PdOscResult) with the C field names, in dependency order,
and the constants their array sizes name (plus CONSTANTS).  Types map as
ctypes does them: double c_double, int and enums c_int, long c_long, size_t
c_size_t, unsigned char c_ubyte, char[N] c_char * N, char * c_char_p, a
pointer to a mirrored struct POINTER(Class), to a scalar POINTER(ctype),
every other pointer and function pointer c_void_p, T[N] ctype * N.  A field
it cannot map stops it with the struct and field named: nothing is guessed.
"""
import difflib
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HEADERS = ("core/pd_core.h", "lcp/pd_lcp.h", "engine/pd_engine.h", "problems/pd_problems.h")
OUT = "python/pound/_structs.py"

# The structs the package uses (python/pound/_lib.py binds the functions
# taking them); structs they hold by value are added.
STRUCTS = (
    "pd_err", "pd_matrix", "pd_lcp_opts", "pd_lcp_info", "pd_record", "pd_record_measures",
    "pd_record_pulse", "pd_penalty_setup", "pd_run_opts", "pd_osc", "pd_osc_sample",
    "pd_osc_result", "pd_osc_summary", "pd_trace", "pd_measured", "pd_structure", "pd_contact",
    "pd_scene_excitation", "pd_scene", "pd_scene_sample", "pd_scene_result", "pd_scene_summary",
    "pd_scene_trace", "pd_scene_errors", "pd_spectrum", "pd_spec_coords", "pd_spec_result",
    "pd_spec_row", "pd_stats", "pd_suite_peaks", "pd_suite_contact", "pd_scene_suite",
)
# Integer constants the package uses besides the array sizes: the statuses,
# the wall's index, the automatic method.
STATUSES = ("PD_OK", "PD_ENOMEM", "PD_EINVAL", "PD_ENOSOLUTION", "PD_EMAXPIVOTS", "PD_ENUMERICAL",
            "PD_ENONFINITE", "PD_EIO", "PD_EPARSE", "PD_ESINGULAR", "PD_EBUDGET", "PD_ESTOPPED",
            "PD_EMAXITER")
CONSTANTS = STATUSES + ("PD_WALL", "PD_METHOD_AUTO", "PD_METHOD_NEWMARK")

SCALARS = {"double": "c_double", "int": "c_int", "long": "c_long", "size_t": "c_size_t",
           "unsigned char": "c_ubyte", "char": "c_char"}
# pointers to these are c_void_p: the C library's own types, and void
OPAQUE = {"void", "FILE"}


def fail(msg):
    sys.exit("gen_py_structs: " + msg)


def class_name(c):
    """pd_osc_result -> PdOscResult."""
    return "".join(w.capitalize() for w in c.split("_"))


def braced(text, i):
    """The text between the '{' at i and its matching '}', and the index after it."""
    depth = 0
    for j in range(i, len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return text[i + 1:j], j + 1
    fail("unbalanced braces after: " + text[i:i + 60])


class Headers:
    """What the headers declare: constants, enum and function-pointer type
    names, opaque struct names, and each struct's body (header, text)."""

    def __init__(self, root):
        self.consts, self.bodies = {}, {}
        self.enums, self.fnptrs, self.opaque = set(), set(), set()
        for h in HEADERS:
            with open(os.path.join(root, h), encoding="utf-8") as f:
                text = f.read()
            text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
            text = re.sub(r"//[^\n]*", " ", text)
            for name, value in re.findall(r"^[ \t]*#[ \t]*define[ \t]+(PD_\w+)[ \t]+(.+)$", text,
                                          flags=re.M):
                self.consts[name] = value.strip()
            text = re.sub(r"^[ \t]*#.*$", " ", text, flags=re.M)  # the other directives
            for body, tname in re.findall(r"\benum\s*\w*\s*\{([^}]*)\}\s*(\w*)", text):
                self.enum_constants(body)
                if tname:
                    self.enums.add(tname)
            self.fnptrs |= set(re.findall(r"typedef[^;{}]*?\(\s*\*\s*(\w+)\s*\)\s*\(", text))
            for tag, tname in re.findall(r"typedef\s+struct\s+(\w+)\s+(\w+)\s*;", text):
                self.opaque.add(tname)
            for m in re.finditer(r"typedef\s+struct\s+(\w+)\s*\{", text):
                body, end = braced(text, m.end() - 1)
                tname = re.match(r"\s*(\w+)\s*;", text[end:])
                if not tname or tname.group(1) != m.group(1):
                    fail("%s: typedef struct %s {...} is not named %s"
                         % (h, m.group(1), m.group(1)))
                self.bodies[m.group(1)] = (h, body)

    def enum_constants(self, body):
        """NAME = value entries of an enum (an entry without a value: the last + 1)."""
        value = -1
        for item in body.split(","):
            m = re.match(r"\s*(\w+)\s*(?:=\s*(.+?))?\s*$", item)
            if not m:
                continue
            value = self.int_value(m.group(2)) if m.group(2) else value + 1
            self.consts[m.group(1)] = str(value)

    def int_value(self, text):
        """The integer a constant's text stands for, or None (1e-6, strings, ...)."""
        t = text.strip()
        while t.startswith("(") and t.endswith(")"):
            t = t[1:-1].strip()
        if t in self.consts:
            return self.int_value(self.consts[t])
        m = re.fullmatch(r"([-+]?\s*(?:0[xX][0-9a-fA-F]+|\d+))[uUlL]*", t)
        return int(m.group(1).replace(" ", ""), 0) if m else None


def fields(hd, struct):
    """[(field, base type, pointer depth, array size or None)] of a struct, in order."""
    header, body = hd.bodies[struct]
    out = []
    for decl in filter(None, (d.strip() for d in body.split(";"))):
        decl = " ".join(decl.split())
        fp = re.fullmatch(r"[\w\s*]+\(\s*\*\s*(\w+)\s*\)\s*\(.*\)", decl)
        if fp:  # a function pointer written out
            out.append((fp.group(1), "void", 1, None))
            continue
        m = re.fullmatch(r"((?:(?:const|unsigned|signed|struct)\s+)*\w+)((?:\s*const)?)\s*(.+)",
                         decl)
        if not m:
            fail("%s: struct %s: cannot read the field '%s'" % (header, struct, decl))
        base = re.sub(r"\b(const|struct)\s+", "", m.group(1)).strip()
        for d in m.group(3).split(","):
            dm = re.fullmatch(r"\s*(\**)\s*(?:const\s+)?(\w+)\s*(?:\[\s*(\w+)\s*\])?\s*", d)
            if not dm:
                fail("%s: struct %s: cannot read the declarator '%s' of '%s'"
                     % (header, struct, d.strip(), decl))
            out.append((dm.group(2), base, len(dm.group(1)), dm.group(3)))
    return out


def needed(hd):
    """STRUCTS and the structs they hold by value, in dependency order (a
    struct after those it holds or points to), ties in header order."""
    want, todo = set(), list(STRUCTS)
    while todo:
        s = todo.pop()
        if s not in hd.bodies:
            fail("struct %s is not defined in %s" % (s, ", ".join(HEADERS)))
        if s not in want:
            want.add(s)
            todo += [b for _, b, ptr, _ in fields(hd, s) if not ptr and b in hd.bodies]
    deps = {s: {b for _, b, _, _ in fields(hd, s) if b in want and b != s} for s in want}
    order, placed = [], set()
    while len(order) < len(want):
        ready = [s for s in hd.bodies if s in want and s not in placed and deps[s] <= placed]
        if not ready:
            fail("structs that point to each other: %s" % ", ".join(sorted(want - placed)))
        order.append(ready[0])
        placed.add(ready[0])
    return order


def ctype(hd, struct, field, base, ptr, mirrored):
    """The ctypes expression of a field's type, without its array size."""
    where = "struct %s, field %s: " % (struct, field)
    if ptr == 0:
        if base in SCALARS:
            return SCALARS[base]
        if base in hd.enums:
            return "c_int"
        if base in mirrored:
            return class_name(base)
        if base in hd.fnptrs:
            return "c_void_p"
        fail(where + "no ctypes type for '%s'" % base)
    if ptr == 1 and base == "char":
        return "c_char_p"
    if ptr == 1 and base in SCALARS:
        return "POINTER(%s)" % SCALARS[base]
    if ptr == 1 and base in hd.enums:
        return "POINTER(c_int)"
    if ptr == 1 and base in mirrored:
        return "POINTER(%s)" % class_name(base)
    if base in SCALARS or base in hd.enums or base in hd.bodies or base in hd.opaque \
            or base in hd.fnptrs or base in OPAQUE:
        return "c_void_p"
    fail(where + "no ctypes type for a pointer to '%s'" % base)


def generate(root=ROOT):
    """The text of python/pound/_structs.py."""
    hd = Headers(root)
    order = needed(hd)
    consts, classes, used = set(CONSTANTS), [], {"Structure"}
    for s in order:
        rows = []
        for f, base, ptr, size in fields(hd, s):
            t = ctype(hd, s, f, base, ptr, order)
            used |= set(re.findall(r"\b(POINTER|c_\w+)\b", t))
            if size is not None:
                if hd.int_value(size) is None:
                    fail("struct %s, field %s: the array size %s is not an integer constant"
                         % (s, f, size))
                if not size.isdigit():
                    consts.add(size)
                t = "%s * %s" % (t, size)
            rows.append('        ("%s", %s),' % (f, t))
        classes.append('class %s(Structure):\n    """%s (%s)."""\n    _fields_ = [\n%s\n    ]\n'
                       % (class_name(s), s, hd.bodies[s][0], "\n".join(rows)))
    for c in sorted(consts):
        if c not in hd.consts or hd.int_value(hd.consts[c]) is None:
            fail("%s is not an integer constant of the headers" % c)
    return "".join([
        "# python/pound/_structs.py -- GENERATED by scripts/gen_py_structs.py from\n",
        "# %s: do not edit.\n" % ", ".join(HEADERS),
        "# After a change to a struct, regenerate with\n",
        "#     python3 scripts/gen_py_structs.py\n",
        "# (make python-check and scripts/api-check.sh run it with --check).\n",
        '"""ctypes mirrors of libpound\'s public structs, generated from its headers."""\n',
        "from ctypes import %s\n\n" % ", ".join(sorted(used, key=lambda u: (u.islower(), u))),
        "".join("%s = %d\n" % (c, hd.int_value(hd.consts[c])) for c in sorted(consts)),
        "\n# status -> its name\nSTATUS_NAMES = {\n%s\n}\n" % "\n".join(
            "    %s: \"%s\"," % (c, c) for c in STATUSES),
        "".join("\n\n" + c for c in classes),
        "\n\n# C name -> mirror, for the layout tests\n",
        "MIRRORS = {\n%s\n}\n" % "\n".join('    "%s": %s,' % (s, class_name(s)) for s in order),
    ])


def main(argv):
    args = set(argv[1:])
    if not args <= {"--check", "--stdout"}:
        sys.exit(__doc__.split("\n\n")[1])
    text = generate()
    path = os.path.join(ROOT, OUT)
    if "--stdout" in args:
        sys.stdout.write(text)
        return 0
    if "--check" in args:
        try:
            with open(path, encoding="utf-8") as f:
                old = f.read()
        except OSError:
            old = ""
        if old == text:
            print("gen_py_structs: %s is up to date with the headers" % OUT)
            return 0
        print("gen_py_structs: %s is stale (run python3 scripts/gen_py_structs.py):" % OUT)
        sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), text.splitlines(True),
                                                   OUT + " (committed)", OUT + " (generated)"))
        return 1
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    print("gen_py_structs: wrote %s" % OUT)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
