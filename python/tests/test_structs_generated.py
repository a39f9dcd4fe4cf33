"""The generated ctypes mirrors (pound/_structs.py, scripts/gen_py_structs.py)
against the headers they come from and the C compiler's layout of them.

The installed _structs.py must be what the generator writes from this
tree's headers.  Then a small C program, compiled against the headers
(cc -Icore -Ilcp -Iengine -Iproblems), prints each mirrored struct's sizeof
and alignment and every mirrored field's offsetof, size and type class
(GCC's and Clang's __builtin_classify_type: integer, real, pointer, struct;
of the element for an array, of the pointee for a typed pointer); each must
equal the mirror's.  A positional initializer with one value per mirror
field, compiled with -Werror=missing-field-initializers, refuses a mirror
that leaves a C field out (a field the mirror has and C lacks does not
compile).  So a bug of the generator cannot pass with both files agreeing.
Skipped without a C compiler."""
import ctypes
import importlib.util
import shutil
import subprocess

import pytest

from conftest import REPO

from pound import _lib, _structs

GENERATOR = REPO / "scripts" / "gen_py_structs.py"
MIRRORS = sorted(_structs.MIRRORS.items())

# __builtin_classify_type's classes: integer (char, enum) 1-3, real 8, pointer 5, record 12
INTEGER, REAL, POINTER, RECORD = {1, 2, 3}, {8}, {5}, {12}
POINTERS = (ctypes.c_char_p, ctypes.c_void_p)


def test_the_generated_file_is_current():
    if not GENERATOR.exists():
        pytest.skip("no generator at %s" % GENERATOR)
    spec = importlib.util.spec_from_file_location("gen_py_structs", str(GENERATOR))
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    with open(_structs.__file__, encoding="utf-8") as f:
        installed = f.read()
    assert installed == gen.generate(str(REPO)), \
        "pound/_structs.py is stale: python3 scripts/gen_py_structs.py"


def test_the_binding_uses_the_generated_mirrors():
    for name, mirror in MIRRORS:
        assert getattr(_lib, mirror.__name__) is mirror, name
    assert (_lib.PD_WALL, _lib.PD_SPEC_MAX_LIST) == (_structs.PD_WALL, _structs.PD_SPEC_MAX_LIST)


def _zero(t):
    """A positional initializer of zeros for ctypes type t: a struct's one
    value per mirror field (nested structs the same way)."""
    if issubclass(t, ctypes.Structure):
        return "{%s}" % ", ".join(_zero(ft) for _, ft in t._fields_)
    return "{0}" if issubclass(t, ctypes.Array) else "0"


def _program():
    """C printing, per struct, `S size align` and per field `S.F offset size
    class pointee-class` (-1: not a typed pointer)."""
    out = ["#include <stddef.h>", "#include <stdio.h>", '#include "pd_core.h"',
           '#include "pd_lcp.h"', '#include "pd_engine.h"', '#include "pd_problems.h"',
           "#define K(e) __builtin_classify_type(e)"]
    body = []
    for name, mirror in MIRRORS:
        out.append("static const %s zero_%s = %s;" % (name, name, _zero(mirror)))
        body.append('    printf("%s %%zu %%zu\\n", sizeof(%s), _Alignof(%s));' % (name, name, name))
        for f, t in mirror._fields_:
            x = "zero_%s.%s" % (name, f)
            cls = "K(%s[0])" % x if issubclass(t, ctypes.Array) else "K(%s)" % x
            typed = issubclass(t, (ctypes._Pointer, ctypes.c_char_p))
            body.append('    printf("%s.%s %%zu %%zu %%d %%d\\n", offsetof(%s, %s), sizeof %s, %s, %s);'
                        % (name, f, name, f, x, cls, "K(*%s)" % x if typed else "-1"))
    return "\n".join(out + ["int main(void)", "{"] + body + ["    return 0;", "}", ""])


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    """{"S": (size, align), "S.F": (offset, size, class, pointee class)} from the compiler."""
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None or not (REPO / "problems" / "pd_problems.h").exists():
        pytest.skip("no C compiler or no headers under %s" % REPO)
    tmp = tmp_path_factory.mktemp("layout")
    (tmp / "layout.c").write_text(_program())
    cmd = [cc, "-std=c11", "-Wall", "-Wextra", "-Werror", "-Werror=missing-field-initializers",
           "-D_POSIX_C_SOURCE=200809L"]
    for d in ("core", "lcp", "engine", "problems"):
        cmd += ["-I", str(REPO / d)]
    build = subprocess.run(cmd + [str(tmp / "layout.c"), "-o", str(tmp / "layout")],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           universal_newlines=True)
    assert build.returncode == 0, "the mirrors do not compile against the headers:\n" + \
        build.stdout
    out = subprocess.run([str(tmp / "layout")], check=True, stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    return {w[0]: tuple(int(v) for v in w[1:]) for w in (ln.split() for ln in out.splitlines())}


def _classes(t):
    """The type classes C may give a field of ctypes type t."""
    if issubclass(t, ctypes.Array):
        return _classes(t._type_)
    if issubclass(t, ctypes.Structure):
        return RECORD
    if issubclass(t, (ctypes._Pointer,) + POINTERS):
        return POINTER
    return REAL if t in (ctypes.c_double, ctypes.c_float) else INTEGER


def _pointee(t):
    """The type classes of what a typed pointer points to (None: not one)."""
    if issubclass(t, ctypes._Pointer):
        return _classes(t._type_)
    return INTEGER if t is ctypes.c_char_p else None


def test_every_struct_is_mirrored():
    assert len(MIRRORS) >= 28


@pytest.mark.parametrize("name,mirror", MIRRORS, ids=[n for n, _ in MIRRORS])
def test_layout_is_the_compilers(c_layout, name, mirror):
    assert (ctypes.sizeof(mirror), ctypes.alignment(mirror)) == c_layout[name], name
    for f, t in mirror._fields_:
        offset, size, cls, pointee = c_layout["%s.%s" % (name, f)]
        where = "%s.%s" % (name, f)
        assert getattr(mirror, f).offset == offset, where + ": offset"
        assert getattr(mirror, f).size == size == ctypes.sizeof(t), where + ": size"
        assert cls in _classes(t), "%s: C type class %d, the mirror's %r" % (where, cls, t)
        want = _pointee(t)
        if want is not None:
            assert pointee in want, "%s: C points to class %d, the mirror to %r" % (
                where, pointee, t)
