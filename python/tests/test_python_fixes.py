"""The review of issue 31: explicit Pi2 values (a tuple is never silently a
range), pound.record()'s Result as a record, spectra over a suite of records
(`pound spectrum --records F --json` to the bit), and the oscillator's
history units as the CLI's files state them."""
import shutil
import subprocess
import warnings

import numpy as np
import pytest

import pound
from conftest import EXAMPLES, pound_bin, read_csv

SUITE = EXAMPLES / "records" / "suite" / "suite.txt"
RECS = [SUITE.parent / line.split()[0] for line in SUITE.read_text().splitlines()
        if line.strip() and not line.startswith("#")]
GRID = ["--Pi3", "0.05,0.3", "--eps", "0.6", "--method", "event"]
GRID_KW = dict(Pi3=[0.05, 0.3], eps=0.6, method="event")


# ---- 1. Pi2: values, and the range named -------------------------------------------------

def test_pi2_values_are_the_grids_points(cli, same):
    """Explicit values, as a list, a tuple or an array, give the points a grid
    through the same values gives (the CLI's --Pi2 MIN:MAX:N)."""
    js = cli("spectrum", "--Pi2", "0.2:3:4", *GRID)
    values = [p["Pi2"] for p in js["points"][:4]]
    for given in (values, np.array(values), tuple(values)):
        r = pound.spectrum(Pi2=given, **GRID_KW)
        same(r.points, js["points"])
        assert list(r.Pi2) == values and r.Pi1.shape == (2, 4)
        assert r.runs == js["runs"] and r.twins == js["twins"]


def test_pi2_values_are_the_clis_single_points(cli, same):
    """Any values, in the order given: each the CLI's --Pi2 X:X:1."""
    values = [1.7, 0.3, 0.9]
    r = pound.spectrum(Pi2=values, **GRID_KW)
    one = [cli("spectrum", "--Pi2", "%r:%r:1" % (v, v), *GRID)["points"] for v in values]
    # the points curve by curve, each curve's in the order of the values
    same(r.points, [one[j][cv] for cv in range(2) for j in range(3)])
    assert list(r.Pi2) == values
    same(pound.spectrum(Pi2=0.9, **GRID_KW).points, one[2])


def test_a_tuple_of_three_is_three_values():
    """(0.1, 1, 10) is no longer read as MIN, MAX, N; a warning names the range."""
    with pytest.warns(UserWarning, match=r"Pi2_range=\(MIN, MAX, N\)"):
        r = pound.spectrum(Pi2=(0.1, 1, 10), method="event")
    assert list(r.Pi2) == [0.1, 1.0, 10.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a list, or floats only: no warning
        assert list(pound.spectrum(Pi2=[0.1, 1, 10], method="event").Pi2) == [0.1, 1.0, 10.0]
        pound.spectrum(Pi2=(0.1, 1.0, 10.0), method="event")


def test_pi2_range_is_the_clis(cli, same):
    js = cli("spectrum", "--Pi2", "0.2:3:5", *GRID)
    for kw in (dict(Pi2_range=(0.2, 3, 5)), dict(Pi2_range="0.2:3:5"), dict(Pi2="0.2:3:5")):
        same(pound.spectrum(**kw, **GRID_KW).points, js["points"])


@pytest.mark.parametrize("kw,err,says", [
    (dict(Pi2=[0.5, 1], Pi2_range=(0.5, 1, 2)), pound.InputError, "alternatives"),
    (dict(Pi2=[0.5, 1], linear=True), pound.InputError, "linear: the spacing of Pi2_range"),
    (dict(), TypeError, "Pi2_range"),
    (dict(Pi2=[0.5, -1]), pound.InputError, "Pi2: the values must be > 0"),
    (dict(Pi2=[]), pound.InputError, "Pi2: empty list"),
    (dict(Pi2_range=[0.5, 1]), pound.InputError, r"Pi2_range: give the range \(MIN, MAX, N\)"),
    (dict(T0_range=(0.2, 2, 4)), pound.InputError, "the axis of a suite's spectrum"),
    (dict(Pi2=[0.5], T0=1), pound.InputError, "T0_range"),
])
def test_pi2_refusals(kw, err, says):
    with pytest.raises(err, match=says):
        pound.spectrum(**kw)


# ---- 2. pound.record()'s Result as a record ----------------------------------------------

def _equal(a, b):
    return {k for k in a if k != "cpu_s" and not (np.array_equal(a[k], b[k]) or (
        isinstance(a[k], float) and np.isnan(a[k]) and np.isnan(b[k])))}


def test_record_result_is_its_file():
    m = pound.record(RECS[0])
    kw = dict(T0=0.8, gap=0.01, eps=0.6, history=False)
    by_file, by_result = pound.simulate(record=RECS[0], **kw), pound.simulate(record=m, **kw)
    assert not _equal(by_file, by_result) and by_result.record == RECS[0].name
    suite = pound.simulate(records=[m, RECS[1]], **kw)
    files = pound.simulate(records=RECS[:2], **kw)
    assert not _equal(suite.records[0], files.records[0])
    a = pound.spectrum(Pi2=[0.5, 2], record=m, method="event").points
    b = pound.spectrum(Pi2=[0.5, 2], record=RECS[0], method="event").points
    assert len(a) == len(b) == 2 and not [k for p, q in zip(a, b) for k in _equal(p, q)]


def test_record_result_refusals():
    m = pound.record(RECS[0])
    measures = {k: v for k, v in m.items() if k not in ("acc", "t", "vel", "disp")}
    for kw in (dict(record=measures), dict(records=[measures])):
        with pytest.raises(pound.InputError, match=r"without the samples \(acc\).*pound.record"):
            pound.simulate(T0=0.8, history=False, **kw)
    with pytest.raises(pound.InputError, match="units: pound.record"):
        pound.simulate(record=m, units="g", T0=0.8, history=False)
    with pytest.raises(pound.InputError, match="record_dt: pound.record"):
        pound.simulate(record=m, record_dt=0.02, T0=0.8, history=False)


# ---- 3. spectra over a suite --------------------------------------------------------------

def test_suite_spectrum_is_the_clis(cli, same):
    """records= a suite file: the CLI's --records JSON, records and stats."""
    args = ["--Pi2", "0.5:2:3", "--Pi3", "0.05,0.3", "--eps", "0.6"]
    js = cli("spectrum", "--records", SUITE, *args)
    r = pound.spectrum(records=str(SUITE), Pi2_range=(0.5, 2, 3), Pi3=[0.05, 0.3], eps=0.6,
                       threads=2)
    same(r, js)
    assert r.n == 7 and r.axis == "Pi2" and len(r.stats) == 6
    assert r.stats[4].Pi1.mean == pound.stats_of([e.Pi1[1, 1] for e in r.records]).mean
    # a list of records: --record given for each
    js = cli("spectrum", *sum([["--record", p] for p in RECS[:3]], []), *args,
             "--target-pga", "4")
    same(pound.spectrum(records=RECS[:3], Pi2="0.5:2:3", Pi3=[0.05, 0.3], eps=0.6,
                        target_pga=4), js)


def test_suite_spectrum_against_periods(cli, same):
    js = cli("spectrum", "--records", SUITE, "--T0", "0.2:2:4", "--gap", "0.01", "--eps", "0.6",
             "--method", "event")
    r = pound.spectrum(records=SUITE, T0_range=(0.2, 2, 4), gap=0.01, eps=0.6, method="event")
    same(r, js)
    assert r.axis == "T0" and list(r.T0) == [s["T0"] for s in js["stats"]]


def test_suite_spectrum_refusals():
    with pytest.raises(pound.InputError, match="log-spaced"):
        pound.spectrum(records=SUITE, T0_range=(0.2, 2, 4), linear=True)
    with pytest.raises(pound.InputError, match="give the suite one way"):
        pound.spectrum(records=SUITE, record=RECS[0], Pi2=[1])
    with pytest.raises(pound.InputError, match="scales a suite's records"):
        pound.spectrum(Pi2=[1], target_pga=3)


# ---- 4. the oscillator's units --------------------------------------------------------------

def _h5_units(path, name):
    out = subprocess.run(["h5dump", "-a", "/%s/units" % name, str(path)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, check=True).stdout.decode()
    return out.split("(0): \"")[1].split("\"")[0]


@pytest.mark.parametrize("extra", [{}, {"uy": 0.01}])
def test_oscillator_units_are_the_clis(tmp_path, extra):
    pytest.importorskip("xarray")
    kw = dict(T0=0.8, gap=0.01, eps=0.6, pulse="sine", **extra)
    args = sum([["--" + k, str(v)] for k, v in kw.items()], [])
    csv = tmp_path / "x.csv"
    subprocess.run([str(pound_bin()), "simulate", *args, "-o", str(csv)], check=True,
                   stdout=subprocess.PIPE)
    header, _ = read_csv(csv)
    line = [ln for ln in csv.read_text().splitlines() if ln.startswith("# units = ")][0]
    cli_units = dict(zip(header, line[len("# units = "):].split(",")))
    ds = pound.simulate(**kw).to_xarray()
    names = [k for k in ds.data_vars if k in cli_units] + ["t"]
    assert set(names) >= {"t", "u", "v", "impulse", "gap"} | ({"up"} if extra else set())
    for k in names:
        assert ds[k].attrs["units"] == cli_units[k], k
    assert ds["impulse"].attrs["units"] == "m/s"  # per unit mass
    if shutil.which("h5dump"):
        h5 = tmp_path / "x.h5"
        subprocess.run([str(pound_bin()), "simulate", *args, "-o", str(h5)], check=True,
                       stdout=subprocess.PIPE)
        for k in names:
            assert ds[k].attrs["units"] == _h5_units(h5, k), k
