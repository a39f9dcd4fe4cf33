"""The ctypes mirrors (generated: pound/_structs.py) and the binding's
prototypes against the C headers, read by cffi.

The import-time layout check (pound/_lib.py) measures each struct's size
from a call and reads some fields back; it cannot see a function's
prototype, nor the offset of a field whose value it does not read.  Here
the public headers (include/pound/pound.h and the four module headers) go
through the C preprocessor and cffi's C parser (python3-cffi), and every
mirrored struct must have the header's fields, in its order, at its
offsets, and every prototype the binding declares must have the header's
argument and result types (kind and size; a struct by value returned into
its padded mirror).  cffi is the checker only: the binding stays ctypes.
Skipped without cffi or a C compiler."""
import ctypes
import re
import shutil
import subprocess

import pytest

from conftest import REPO

cffi = pytest.importorskip("cffi")

from pound import _lib, _structs  # noqa: E402

MODULE_DIRS = ("core", "lcp", "engine", "problems")


def _strip_attributes(s):
    """Remove __attribute__((...)) (balanced parentheses)."""
    out, i = [], 0
    while True:
        j = s.find("__attribute__", i)
        if j < 0:
            return "".join(out) + s[i:]
        out.append(s[i:j])
        k, depth = s.index("(", j), 0
        for m in range(k, len(s)):
            depth += {"(": 1, ")": -1}.get(s[m], 0)
            if depth == 0:
                break
        i = m + 1


def _strip_bodies(s):
    """static inline function definitions -> declarations (cdef takes no
    code): a top-level '{' right after ')' opens a body."""
    out, depth, i = [], 0, 0
    while i < len(s):
        ch = s[i]
        if ch == "{" and depth == 0 and "".join(out).rstrip().endswith(")"):
            d = 0
            for m in range(i, len(s)):
                d += {"{": 1, "}": -1}.get(s[m], 0)
                if d == 0:
                    break
            out.append(";")
            i = m + 1
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        out.append(ch)
        i += 1
    return re.sub(r"\b(static|inline)\b", "", "".join(out))


@pytest.fixture(scope="module")
def ffi(tmp_path_factory):
    header = REPO / "include" / "pound" / "pound.h"
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None or not header.exists():
        pytest.skip("no C compiler or no headers at %s" % header)
    # the system headers replaced by empty files: size_t, int64_t and FILE are
    # cffi's own types, declared below
    fake = tmp_path_factory.mktemp("sys")
    for h in ("stddef.h", "stdint.h", "stdio.h", "stdbool.h"):
        (fake / h).write_text("")
    cmd = [cc, "-E", "-P", "-nostdinc", "-I", str(fake)]
    for d in MODULE_DIRS:
        cmd += ["-I", str(REPO / d)]
    text = subprocess.run(cmd + [str(header)], check=True, stdout=subprocess.PIPE,
                          universal_newlines=True).stdout
    f = cffi.FFI()
    f.cdef("typedef struct _IO_FILE FILE;\n" + _strip_bodies(_strip_attributes(text)))
    return f


@pytest.fixture(scope="module")
def clib(ffi):
    """The library the binding loaded, opened by cffi with the header's types."""
    return ffi.dlopen(_lib.library_path)


def c_name(mirror):
    """PdSceneSample -> pd_scene_sample."""
    return "pd_" + re.sub(r"(?<!^)([A-Z])", r"_\1", mirror.__name__[2:]).lower()


MIRRORS = sorted(_structs.MIRRORS.values(), key=lambda c: c.__name__)


def test_every_mirror_is_checked():
    assert len(MIRRORS) >= 25


@pytest.mark.parametrize("mirror", MIRRORS, ids=[c.__name__ for c in MIRRORS])
def test_struct_mirror_matches_the_header(ffi, mirror):
    name = c_name(mirror)
    ct = ffi.typeof(name)
    c_fields = [f for f, _ in ct.fields]
    py_fields = [f[0] for f in mirror._fields_]
    assert py_fields == c_fields, "%s: fields differ from the header" % name
    assert ctypes.sizeof(mirror) == ffi.sizeof(name)
    for f in py_fields:
        assert getattr(mirror, f).offset == ffi.offsetof(name, f), "%s.%s" % (name, f)
        assert getattr(mirror, f).size == ffi.sizeof(dict(ct.fields)[f].type), \
            "%s.%s: size" % (name, f)


def _same(t, c, ffi):
    """Does the ctypes type t (None: void) declare the cffi type c?"""
    if t is None:
        return c.kind == "void"
    if t is ctypes.c_void_p:
        return c.kind in ("pointer", "function")
    if t is ctypes.c_char_p:
        return c.kind == "pointer" and c.item.cname == "char"
    if isinstance(t, type) and issubclass(t, ctypes._CFuncPtr):
        return c.kind == "function" and len(c.args) == len(t._argtypes_) and \
            all(_same(a, b, ffi) for a, b in zip(t._argtypes_, c.args)) and \
            _same(t._restype_, c.result, ffi)
    if isinstance(t, type) and issubclass(t, ctypes._Pointer):
        return c.kind == "pointer" and _same(t._type_, c.item, ffi)
    if isinstance(t, type) and issubclass(t, ctypes.Structure):
        if t.__name__.startswith("Padded"):  # a struct returned by value
            t = t._fields_[0][1]
        return c.kind == "struct" and ffi.typeof(c_name(t)) is c
    if t is ctypes.c_double:
        return c.cname == "double"
    if t in (ctypes.c_int, ctypes.c_long, ctypes.c_ubyte, ctypes.c_size_t):
        return c.kind in ("primitive", "enum") and c.cname not in ("double", "float") and \
            ffi.sizeof(c) == ctypes.sizeof(t)
    raise AssertionError("no rule for %r" % (t,))


PROTOTYPES = sorted({**_lib._PROTOTYPES, **_lib._OPTIONAL}.items())


@pytest.mark.parametrize("name,proto", PROTOTYPES, ids=[n for n, _ in PROTOTYPES])
def test_prototype_matches_the_header(ffi, clib, name, proto):
    res, args = proto
    fn = ffi.typeof(getattr(clib, name))
    assert not fn.ellipsis
    assert len(fn.args) == len(args), "%s: %d arguments, the header %d" % (
        name, len(args), len(fn.args))
    for i, (t, a) in enumerate(zip(args, fn.args)):
        assert _same(t, a, ffi), "%s: argument %d is %r, the header %s" % (name, i, t, a.cname)
    assert _same(res, fn.result, ffi), "%s: result %r, the header %s" % (
        name, res, fn.result.cname)
