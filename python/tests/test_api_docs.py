"""The public API is documented and typed: every name in pound.__all__ (and
pound.plot's), and every public method and property of the classes among
them, has a docstring and full annotations (PEP 484: each parameter and the
return).  python/check.sh also runs mypy on the installed package and on
tests/typing_usage.py (a user's code, --strict) when mypy is installed."""
import inspect

import pytest

import pound
import pound.plot


def public_api():
    """(qualified name, object) of every public function, class, method and
    property of the package."""
    out = []
    for mod, names in ((pound, pound.__all__), (pound.plot, pound.plot.__all__)):
        for name in names:
            obj = getattr(mod, name)
            qual = "%s.%s" % (mod.__name__, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            out.append((qual, obj))
            if not inspect.isclass(obj):
                continue
            for klass in obj.__mro__:  # its own and the package's bases' members
                if not klass.__module__.startswith("pound"):
                    continue
                for mname, member in vars(klass).items():
                    if mname.startswith("_") and mname != "__init__":
                        continue
                    if isinstance(member, (classmethod, staticmethod)):
                        member = member.__func__
                    if isinstance(member, property) or inspect.isfunction(member):
                        out.append(("%s.%s" % (qual, mname), member))
    return out


API = public_api()


def test_the_api_is_all_there():
    names = {q for q, _ in API}
    for q in ("pound.simulate", "pound.Scene.simulate", "pound.Scene.chain", "pound.Scene.Le",
              "pound.Result.to_pandas", "pound.Record.from_array", "pound.PoundError.code",
              "pound.plot.history", "pound.plot.spectrum", "pound.version"):
        assert q in names
    assert len(API) > 40


@pytest.mark.parametrize("qual,obj", API, ids=[q for q, _ in API])
def test_documented(qual, obj):
    doc = inspect.getdoc(obj.fget if isinstance(obj, property) else obj)
    if qual.endswith(".__init__") and doc is None:
        return  # the class's docstring says how to make one
    assert doc and len(doc.split()) >= 3, "%s has no docstring" % qual


@pytest.mark.parametrize("qual,obj", [(q, o) for q, o in API if not inspect.isclass(o)],
                         ids=[q for q, o in API if not inspect.isclass(o)])
def test_annotated(qual, obj):
    f = obj.fget if isinstance(obj, property) else obj
    sig = inspect.signature(f)
    missing = [p.name for i, p in enumerate(sig.parameters.values())
               if p.annotation is inspect.Parameter.empty
               and not (i == 0 and p.name in ("self", "cls"))]
    assert not missing, "%s: parameters without a type: %s" % (qual, ", ".join(missing))
    assert sig.return_annotation is not inspect.Signature.empty, \
        "%s: no return type" % qual


def test_exceptions_documented():
    for name in pound.__all__:
        obj = getattr(pound, name)
        if inspect.isclass(obj) and issubclass(obj, Exception):
            assert obj.__doc__ and obj.__doc__ is not Exception.__doc__, name


def test_library_path_is_a_str():
    assert isinstance(pound.library_path, str)
    assert pound._lib.__annotations__["library_path"] is str
