"""Ground motions as arrays (issue 21): record= takes a NumPy array with
record_dt= and units=, and gives the run the same motion read from a file
gives, bit for bit; the units are checked for plausibility."""
import numpy as np
import pytest

import pound
from conftest import EXAMPLES

RINALDI = EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2"
CASE = dict(T0=0.8, gap=0.01, eps=0.6, history=False)


def rinaldi_in_g():
    """The AT2 file's samples as the reader parses them (4 header lines)."""
    lines = RINALDI.read_text().splitlines()[4:]
    return np.array([float(x) for line in lines for x in line.split()])


@pytest.mark.parametrize("method", ["event", "moreau"])
def test_array_in_g_is_the_file(method):
    a = pound.simulate(record=str(RINALDI), method=method, **CASE)
    b = pound.simulate(record=rinaldi_in_g(), record_dt=0.01, units="g", method=method, **CASE)
    assert a["umax"] == b["umax"] and a["impacts"] == b["impacts"]


def test_array_in_m_s2_is_the_file():
    acc = pound.record(str(RINALDI))["acc"]  # m/s^2, as read
    a = pound.simulate(record=str(RINALDI), method="event", **CASE)
    b = pound.simulate(record=acc, record_dt=0.01, units="m/s2", method="event", **CASE)
    assert a["umax"] == b["umax"]


def test_array_defaults_to_the_library_units():
    """record.acc (m/s^2) given back without units= is read in m/s^2, the
    library's own units: the file's run, bit for bit (not a 9.8x motion)."""
    acc = pound.record(str(RINALDI))["acc"]
    a = pound.simulate(record=str(RINALDI), method="event", **CASE)
    b = pound.simulate(record=acc, record_dt=0.01, method="event", **CASE)
    assert a["umax"] == b["umax"] and a["impacts"] == b["impacts"]


def test_a_list_of_files_is_named():
    """A list of paths is not read as samples (a record_dt error): named."""
    with pytest.raises(pound.InputError, match="record: 2 files given"):
        pound.simulate(record=[str(RINALDI), str(RINALDI)], record_dt=0.01, **CASE)
    with pytest.raises(pound.InputError, match="record: 2 files given"):
        pound.simulate(record=[RINALDI, RINALDI], **CASE)


def test_array_misuse():
    acc = rinaldi_in_g()
    with pytest.raises(pound.InputError, match="record_dt"):
        pound.simulate(record=acc, **CASE)
    with pytest.raises(pound.InputError, match="1-D"):
        pound.simulate(record=acc.reshape(11, 181), record_dt=0.01, **CASE)
    with pytest.raises(pound.InputError, match="record_format"):
        pound.simulate(record=acc, record_dt=0.01, record_format="at2", **CASE)
    with pytest.raises(pound.InputError, match="record_dt"):
        pound.simulate(record=str(RINALDI), record_dt=0.01, **CASE)
    bad = acc.copy()
    bad[7] = np.nan
    with pytest.raises(pound.InputError, match="sample 7"):
        pound.simulate(record=bad, record_dt=0.01, **CASE)
    with pytest.raises(pound.InputError, match="record_dt"):
        pound.simulate(record=acc, record_dt=0.0, **CASE)


def test_units_on_a_file_that_states_them():
    with pytest.raises(pound.InputError, match="AT2"):
        pound.record(str(RINALDI), units="m/s2")


def test_implausible_units_warn():
    acc = pound.record(str(RINALDI))["acc"]  # m/s^2 values (8.1 at most) ...
    with pytest.warns(UserWarning, match="m/s2") as w:  # ... called g: 8.3 g
        pound.simulate(record=acc, record_dt=0.01, units="g", **CASE)
    assert "units=" in str(w[0].message) and "--units" not in str(w[0].message)
