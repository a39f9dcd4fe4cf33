"""Errors carry the library's message and status; the layout check refuses
mirrors that do not match the library."""
import ctypes
import os

import numpy as np
import pytest

import pound
from pound import _lib
from conftest import EXAMPLES


def test_negative_gap_is_an_input_error():
    with pytest.raises(pound.InputError) as e:
        pound.simulate(gap=-0.01, ap=4, Tp=0.3)
    assert e.value.status == -2 and e.value.code == "PD_EINVAL"
    assert str(e.value).startswith("gap must be >= 0 (Pi3 = -")
    assert isinstance(e.value, pound.PoundError) and isinstance(e.value, ValueError)


@pytest.mark.parametrize("kw,message", [
    (dict(eps=1.5), "eps (restitution) must be in [0, 1] (got 1.5)"),
    (dict(xi=1.0), "xi (damping ratio) must be in [0, 1) (got 1)"),
    (dict(ap=0), "ap (pulse amplitude) must be > 0 (got 0)"),
    (dict(T0=-1), "T0 / Pi2 must be finite and > 0"),
    (dict(T0=1, Pi2=2), "T0 and Pi2 are alternatives: give one"),
    (dict(gap=0.1, Pi3=2), "gap and Pi3 are alternatives: give one"),
    (dict(pulse="square"), "pulse: 'square' is not one of sine, cosine, harmonic"),
    (dict(method="rk4"), "method: 'rk4' is not one of moreau, event, penalty"),
    (dict(theta=0.3), "theta: 0.3 is outside [1/2, 1]"),
    (dict(dt=0), "dt: the step must be > 0 (got 0)"),
    (dict(dt=5), "dt: the step 5 s is not shorter than the run"),
    (dict(scale=2), "scale: goes with record"),
])
def test_input_errors(kw, message):
    with pytest.raises(pound.InputError) as e:
        pound.simulate(**kw)
    assert str(e.value).startswith(message), str(e.value)


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError):
        pound.simulate(gapp=0.1)


def test_file_errors(tmp_path):
    with pytest.raises(pound.FileError) as e:
        pound.scene(tmp_path / "missing.json")
    assert e.value.status == -7 and "missing.json" in str(e.value)
    assert isinstance(e.value, OSError)
    bad = tmp_path / "bad.json"
    bad.write_text('{"structures": [}\n')
    with pytest.raises(pound.ParseError) as e:
        pound.scene(bad)
    assert e.value.status == -8 and str(e.value).startswith(str(bad) + ":1:")
    lcp = tmp_path / "bad.lcp"
    lcp.write_text("2\n1 0\n0 x\n1 1\n")
    with pytest.raises(pound.ParseError) as e:
        pound.read_lcp(lcp)
    assert "line" in str(e.value)
    with pytest.raises(pound.FileError):
        pound.record(tmp_path / "none.AT2")


def test_scene_option_errors():
    with pytest.raises(pound.InputError) as e:
        pound.simulate_scene(EXAMPLES / "scenes" / "two-sdof.json", gamma=2)
    assert str(e.value) == "gamma: must be in [0, 1] (got 2)"
    with pytest.raises(pound.InputError):
        pound.Scene.chain(0)
    # the GSL-based reference is measured on scenes only, as the CLI says
    with pytest.raises(pound.InputError) as e:
        pound.compare(methods="moreau,event-general", pulse="sine")
    assert "event-general is a reference for scenes" in str(e.value)
    with pytest.raises(pound.InputError):
        pound.converge("1e-3:5e-4:2", methods=["event-general"], pulse="sine")
    with pytest.raises(pound.InputError):
        pound.compare(methods="event", pulse="sine")


def test_lcp_input_errors():
    with pytest.raises(pound.InputError):
        pound.lcp([[1, 2, 3]], [1])
    with pytest.raises(pound.InputError):
        pound.lcp([[1.0]], [1, 2])
    with pytest.raises(pound.InputError):
        pound.lcp([[1.0]], [1], solver="simplex")


def test_spectrum_errors():
    with pytest.raises(pound.InputError) as e:
        pound.spectrum(Pi2_range=(2, 1, 5))
    assert str(e.value).startswith("Pi2_range: need 0 < MIN < MAX")
    for values in ([0.1, 1, -10], np.array([0.1, 0, 10])):  # values, each > 0
        with pytest.raises(pound.InputError) as e:
            pound.spectrum(Pi2=values)
        assert str(e.value).startswith("Pi2: the values must be > 0")
    with pytest.raises(pound.InputError):
        pound.spectrum(Pi2_range=(0.1, 1, 5), eps=[0.5, 1.5])
    with pytest.raises(pound.InputError):
        pound.spectrum(Pi2_range=(0.1, 1, 5), Pi3=[0.1], gap=[0.01])


def test_library_not_found(tmp_path):
    import subprocess
    import sys
    env = dict(os.environ, POUND_LIBRARY=str(tmp_path / "libpound.so"))
    out = subprocess.run([sys.executable, "-c", "import pound"], env=env, cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert out.returncode != 0
    msg = out.stderr.decode()
    assert "ImportError: pound: libpound not found; tried %s" % (tmp_path / "libpound.so") in msg
    assert "POUND_LIBRARY" in msg


def test_library_and_version():
    assert pound.library_path
    v = pound.version()
    assert v is None or v.count(".") == 2


# ---- the layout check -------------------------------------------------------------------

def test_layout_probe_measures_the_c_size():
    """pd_spec_init clears sizeof(pd_spectrum) bytes: the probe finds that
    size, and refuses a mirror one field short or one field long."""
    _lib._probe(_lib.PdSpectrum, _lib.lib.pd_spec_init, "pd_spectrum")  # matches

    class Short(ctypes.Structure):
        _fields_ = _lib.PdSpectrum._fields_[:-1]

    class Long(ctypes.Structure):
        _fields_ = _lib.PdSpectrum._fields_ + [("extra", ctypes.c_double)]

    for bad in (Short, Long):
        with pytest.raises(pound.LayoutError) as e:
            _lib._probe(bad, lambda p: _lib.lib.pd_spec_init(ctypes.cast(p, ctypes.POINTER(_lib.PdSpectrum))),
                        "pd_spectrum")
        assert "does not match" in str(e.value)


def test_layout_values_round_trip():
    o, c = _lib.default_opts(), _lib.default_osc()
    assert (o.theta, o.gamma, o.pen.rtol, o.pen.atol, _lib.s(o.pen.stepper)) == \
        (0.5, 0.5, 1e-10, 1e-12, "rk8pd")
    assert (c.ap, c.Tp, c.Pi2, c.Pi3, c.eps, c.xi, c.dir) == (1, 1, 1, 0.05, 0.5, 0.05, 1)
    with pytest.raises(pound.LayoutError):
        _lib._expect("pd_osc.Tp", c.Tp, 2.0)
