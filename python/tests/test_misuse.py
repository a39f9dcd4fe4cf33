"""Misuse of the binding is refused with the right exception and a message
naming what is wrong (issue 19, defect 10): non-finite LCP data and
negative budgets, NUL characters in paths and names, bytes and os.PathLike
paths, floats where integers go and booleans where numbers go."""
import os

import numpy as np
import pytest

import pound
from conftest import EXAMPLES, RECORDS

NAN, INF = float("nan"), float("inf")
TWO_SDOF = EXAMPLES / "scenes" / "two-sdof.json"
MURTY = EXAMPLES / "murty1978.lcp"


def refused(call, *message, cls=pound.InputError):
    """call() raises cls whose message contains every part of message."""
    with pytest.raises(cls) as e:
        call()
    for part in message:
        assert part in str(e.value), str(e.value)
    return e.value


# ---- lcp: the library refuses bad input with PD_EINVAL and no message ------------------

@pytest.mark.parametrize("solver", ["auto", "lemke", "structured", "pgs"])
def test_lcp_nonfinite_matrix(solver):
    e = refused(lambda: pound.lcp([[NAN, 0], [0, 1]], [-1, -1], solver=solver),
                "M: entry (0, 0) is not finite")
    assert e.status == -2 and "more than" not in str(e)
    refused(lambda: pound.lcp([[1, 0], [-INF, 1]], [-1, -1], solver=solver),
            "M: entry (1, 0) is not finite")


@pytest.mark.parametrize("solver", ["auto", "lemke", "structured", "pgs"])
def test_lcp_nonfinite_q(solver):
    refused(lambda: pound.lcp([[1, 0], [0, 1]], [-1, INF], solver=solver),
            "q: entry 1 is not finite")
    refused(lambda: pound.lcp([[1, 0], [0, 1]], [NAN, -1], solver=solver),
            "q: entry 0 is not finite")


def test_lcp_nonfinite_sparse_matrix():
    sparse = pytest.importorskip("scipy.sparse")
    M = sparse.csc_matrix(np.array([[2.0, 0.0], [0.0, 1.0]]))
    M.data[1] = NAN  # the entry (1, 1)
    refused(lambda: pound.lcp(M, [-1, -1]), "M: entry (1, 1) is not finite")


def test_lcp_budgets():
    M, q = [[1, 0], [0, 1]], [-1, -1]
    refused(lambda: pound.lcp(M, q, max_pivots=-5), "max_pivots: must be >= 0 (got -5)")
    refused(lambda: pound.lcp(M, q, solver="pgs", max_iterations=-5),
            "max_iterations: must be >= 0 (got -5)")
    refused(lambda: pound.lcp(M, q, max_pivots=3.7), "max_pivots: '3.7' is not an integer")
    refused(lambda: pound.lcp(M, q, max_pivots=True), "max_pivots: 'True' is a bool")
    refused(lambda: pound.lcp(M, q, max_iterations=2 ** 32 - 5), "max_iterations:",
            "out of range")
    refused(lambda: pound.lcp(M, q, tol="x"), "tol: 'x' is not a number")
    refused(lambda: pound.lcp(M, q, tol=True), "tol: 'True' is a bool")
    refused(lambda: pound.lcp(M, q, tol=NAN), "tol: 'nan' is not a finite number")
    refused(lambda: pound.lcp(M, q, cover=NAN), "cover: 'nan' is not a finite number")
    refused(lambda: pound.lcp(M, q, cover=[1, INF]), "cover: entry 1 is not finite")
    refused(lambda: pound.lcp(M, q, cover=[1, -1]), "cover: expected 1 or n = 2 positive")
    # valid budgets still solve: 0 is the library's default, numpy integers are integers
    assert pound.lcp(M, q, max_pivots=np.int32(0), max_iterations=4.0).status == "solved"


def test_lcp_entries_are_numbers():
    refused(lambda: pound.lcp([[True, False], [False, True]], [-1, -1]), "M:", "bool")
    refused(lambda: pound.lcp([[1, 0], [0, 1]], [True, False]), "q:", "bool")
    refused(lambda: pound.lcp([["a"]], [-1]), "M:", "not an array of real numbers")
    refused(lambda: pound.lcp([[1j]], [-1]), "M:", "complex")
    refused(lambda: pound.lcp([[1, 2], [3]], [-1, -1]), "M:")


def test_lcp_too_large_for_lemke_keeps_its_message():
    n = 2049
    refused(lambda: pound.lcp(np.eye(n), -np.ones(n), solver="lemke"),
            "n = 2049 is more than the lemke solver takes (Lemke: at most 2048 unknowns)")


# ---- paths --------------------------------------------------------------------------------

def _nul_calls(path):
    s = str(path) + "\0junk"
    return [("scene", lambda: pound.scene(s)),
            ("scene", lambda: pound.Scene(s)),
            ("scene", lambda: pound.simulate_scene(s, history=False)),
            ("scene", lambda: pound.compare(scene=s)),
            ("scene", lambda: pound.converge("1e-3:5e-4:2", scene=s)),
            ("record", lambda: pound.record(s)),
            ("record", lambda: pound.simulate(record=s, history=False)),
            ("record", lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), record=s)),
            ("read_lcp", lambda: pound.read_lcp(s))]


@pytest.mark.parametrize("i", range(9))
def test_nul_in_a_path_is_refused(i):
    """"two-sdof.json\\0junk" must not load two-sdof.json."""
    what, call = _nul_calls(TWO_SDOF)[i]
    refused(call, what + ": the path ", "\\x00junk", "contains a NUL character")
    refused(lambda: pound.scene(os.fsencode(str(TWO_SDOF)) + b"\0"), "NUL")


def test_bytes_and_pathlike_paths(tmp_path):
    sc = pound.scene(os.fsencode(str(TWO_SDOF)))
    assert sc.path == str(TWO_SDOF) and len(sc.structures) == 2
    r1 = pound.simulate_scene(os.fsencode(str(TWO_SDOF)), history=False, method="moreau")
    r2 = pound.simulate_scene(str(TWO_SDOF), history=False, method="moreau")
    assert r1["structures"][0]["umax"].tolist() == r2["structures"][0]["umax"].tolist()

    class Where:  # an os.PathLike that is not a str
        def __init__(self, p):
            self.p = p

        def __fspath__(self):
            return self.p
    assert pound.scene(Where(str(TWO_SDOF))).path == str(TWO_SDOF)
    M, q = pound.read_lcp(os.fsencode(str(MURTY)))
    M2, q2 = pound.read_lcp(Where(os.fsencode(str(MURTY))))
    assert M.tolist() == M2.tolist() and q.tolist() == q2.tolist()
    # messages name the file as the user wrote it, not its repr
    missing = str(tmp_path / "missing.json")
    for p in (os.fsencode(missing), Where(missing), Where(os.fsencode(missing))):
        e = refused(lambda: pound.scene(p), missing + ": ", cls=pound.FileError)
        assert "b'" not in str(e) and "Where" not in str(e)
        refused(lambda: pound.read_lcp(p), missing, cls=pound.FileError)
        refused(lambda: pound.record(p), missing, cls=pound.FileError)
        refused(lambda: pound.simulate(record=p), missing, cls=pound.FileError)


def test_paths_of_other_types_are_refused():
    refused(lambda: pound.scene(None), "scene: expected a path (str, bytes or os.PathLike)",
            "NoneType")
    refused(lambda: pound.read_lcp(3), "read_lcp: expected a path", "int")
    refused(lambda: pound.record(1.5), "record: expected a path", "float")
    refused(lambda: pound.scene(""), "scene: the path is empty")


@pytest.mark.skipif(not (RECORDS / "H-E12140.at2").exists(), reason="no records")
def test_record_bytes_path():
    src = RECORDS / "H-E12140.at2"
    a = pound.record(os.fsencode(str(src)))
    b = pound.record(src)
    assert a["pga"] == b["pga"] and a["name"] == b["name"]


# ---- integers --------------------------------------------------------------------------------

def test_chain_takes_an_integer():
    refused(lambda: pound.Scene.chain(3.7), "chain: '3.7' is not an integer")
    refused(lambda: pound.Scene.chain(True), "chain: 'True' is a bool, not an integer")
    refused(lambda: pound.Scene.chain("three"), "chain: 'three' is not an integer")
    refused(lambda: pound.Scene.chain(NAN), "chain: 'nan' is not an integer")
    refused(lambda: pound.Scene.chain(0), "chain: N must be in [1, 1e7] (got 0)")
    refused(lambda: pound.Scene.chain(2 ** 40), "chain:", "out of range")
    assert len(pound.Scene.chain(np.int64(3)).structures) == 3
    assert len(pound.Scene.chain(3.0).structures) == 3
    refused(lambda: pound.Scene.chain(3, ratio=True), "chain_ratio: 'True' is a bool")


def test_every_and_threads_take_integers():
    refused(lambda: pound.simulate(every=2.5, method="moreau"), "every: '2.5' is not an integer")
    refused(lambda: pound.simulate(every=True, method="moreau"), "every: 'True' is a bool")
    refused(lambda: pound.simulate_scene(TWO_SDOF, every=1.5), "every: '1.5' is not an integer")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), threads=1.5),
            "threads: '1.5' is not an integer")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), threads=True),
            "threads: 'True' is a bool")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2.5)),
            "Pi2_range: N = '2.5' is not an integer")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, True)), "Pi2_range: N = 'True' is a bool")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, INF, 2)),
            "Pi2_range: MAX = 'inf' is not a finite")
    refused(lambda: pound.spectrum(Pi2="0.5:1:2.5"), "Pi2: N = '2.5' is not an integer")
    refused(lambda: pound.dt_range(1e-2, 1e-3, 2.5), "dt: N = '2.5' is not an integer")
    refused(lambda: pound.dt_range(INF, 1e-3, 3), "dt: MAX = 'inf' is not a finite number")
    assert pound.dt_range(1e-2, 1e-3, np.int64(2)) == [1e-2, 1e-3]


# ---- booleans are not numbers ------------------------------------------------------------------

@pytest.mark.parametrize("key", ["ap", "Tp", "T0", "Pi2", "gap", "Pi3", "eps", "xi", "dt", "tend",
                                 "theta", "gamma", "kc", "kc_abs", "rtol", "atol", "close_tol"])
@pytest.mark.parametrize("value", [True, np.bool_(False)])
def test_bool_is_not_a_number(key, value):
    kw = {key: value}
    if key in ("kc", "kc_abs", "rtol", "atol", "close_tol", "dt", "theta", "gamma"):
        kw["method"] = "moreau" if key in ("dt", "theta", "gamma") else \
            "event" if key == "close_tol" else "penalty"
    refused(lambda: pound.simulate(history=False, **kw),
            "%s: '%s' is a bool, not a number" % (key, value))


def test_bool_in_lists_is_not_a_number():
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), eps=True), "eps: 'True' is a bool")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), Pi3=[0.1, True]), "Pi3: 'True' is a bool")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), dt_per_Tp=True), "dt_per_Tp: 'True'")
    refused(lambda: pound.converge("1e-3:5e-4:2", theta=True), "theta: 'True' is a bool")
    refused(lambda: pound.converge("1e-3:5e-4:2", theta=[0.5, True]), "theta: 'True'")
    refused(lambda: pound.converge([1e-3, True]), "dt: 'True' is a bool")
    refused(lambda: pound.converge("1e-3:5e-4:2", methods="penalty", kcs=[True]),
            "kcs: 'True' is a bool")
    refused(lambda: pound.Scene.chain(2, ap=True), "ap: 'True' is a bool")


def test_flags_are_booleans():
    refused(lambda: pound.simulate(no_wall="false", history=False),
            "no_wall: expected True or False (got 'false')")
    refused(lambda: pound.simulate(allow_unstable=2, theta=0.3, history=False),
            "allow_unstable: expected True or False (got '2')")
    refused(lambda: pound.spectrum(Pi2_range=(0.5, 1, 2), linear="yes"), "linear: expected True")
    refused(lambda: pound.simulate(history="no"), "history: expected True or False")
    a = pound.simulate(no_wall=1, history=False, method="moreau")
    b = pound.simulate(no_wall=np.bool_(True), history=False, method="moreau")
    assert a["umax"] == b["umax"]


# ---- names: no NUL, strings only ------------------------------------------------------------

@pytest.mark.parametrize("kw,message", [
    (dict(pulse="sine\0x"), "pulse: 'sine\\x00x' is not one of sine, cosine, harmonic"),
    (dict(method="moreau\0"), "method: 'moreau\\x00' is not one of"),
    (dict(dir="normal\0"), "dir: 'normal\\x00' is not one of"),
    (dict(kernel=["auto"]), "kernel: '['auto']' is not one of auto, general"),
    (dict(stepper=["rk8pd"]), "stepper: '['rk8pd']' is not one of"),
    (dict(contact="kelvin\0"), "contact: 'kelvin\\x00' is not one of kelvin, hertz"),
    (dict(factor="auto\0"), "factor: 'auto\\x00' is not one of"),
    (dict(lcp_solver="lemke\0"), "lcp_solver: 'lemke\\x00' is not one of"),
    (dict(record=str(TWO_SDOF), units="g\0"), "units: 'g\\x00' is not one of"),
    (dict(record=str(TWO_SDOF), record_format="at2\0"), "record_format: 'at2\\x00' is not"),
    (dict(dir=2), "dir: '2' is not one of normal, reverse"),
])
def test_names(kw, message):
    refused(lambda: pound.simulate(history=False, **kw), message)


def test_other_names():
    refused(lambda: pound.lcp([[1.0]], [1], solver="lemke\0"), "solver: 'lemke\\x00' is not")
    refused(lambda: pound.read_lcp(MURTY, format=["auto"]), "format: '['auto']' is not")
    refused(lambda: pound.converge("1e-3:5e-4:2", error=["hist"]), "error: '['hist']' is not")
    refused(lambda: pound.compare(methods=[1]), "methods: '1' is not one of")
    refused(lambda: pound.compare(methods=["moreau\0"]), "methods: 'moreau\\x00' is not")


def test_dir_as_a_number():
    a = pound.simulate(dir=-1, history=False, method="moreau")
    assert pound.simulate(dir=np.int64(-1), history=False, method="moreau")["umax"] == a["umax"]
    assert pound.simulate(dir=-1.0, history=False, method="moreau")["dir"] == "reverse"
    refused(lambda: pound.simulate(dir=True), "dir: 'True' is not one of")
