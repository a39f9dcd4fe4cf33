"""Hardening 4 of the binding (a review's defects): a spectrum's to_pandas()
is a long frame, one row per point of the sweep (it raised pandas' "All
arrays must be of the same length", or with as many curves as Pi2 points
gave a frame whose rows were the curves), and converge's and compare's are
their rows; plot.impact_times refuses a contact out of range or negative
(an IndexError, or -1 silently the last contact); an array given as record=
is real numbers only, at every entry point (complex, bool, string entries
and masked arrays with an entry masked were taken: an imaginary part
dropped, a mask ignored)."""
import warnings

import numpy as np
import pytest

import pound
import pound.plot as pp
from conftest import EXAMPLES

FIG9 = dict(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
THREE_SDOF = EXAMPLES / "scenes" / "three-sdof.json"  # 3 contacts
RINALDI = EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2"
CASE = dict(T0=0.8, gap=0.01, eps=0.6)


# ---- 1. to_pandas of a sweep: one row per point -------------------------------------------

def _rows_are_the_points(r, df):
    """Every row of df is the point (curve, j) of the spectrum r, in order."""
    ncurves, npi2 = r.Pi1.shape
    assert len(df) == ncurves * npi2 == len(r.points)
    assert np.array_equal(df["curve"].values, np.repeat(np.arange(ncurves), npi2))
    assert np.array_equal(df["Pi2"].values, np.tile(r.Pi2, ncurves))
    for key in ("Pi1", "gamma", "chi", "umax", "impacts", "T0", "gap"):
        assert np.array_equal(df[key].values, r[key].reshape(-1)), key
    for key in ("pulse", "dir", "eps", "xi", "ap"):
        assert list(df[key]) == [r.curves[c][key] for c in df["curve"]], key


def test_spectrum_to_pandas_one_curve():
    pytest.importorskip("pandas")
    r = pound.spectrum(Pi2_range=(0.5, 2, 3), Pi3=0.01, eps=0.5)
    df = r.to_pandas()  # raised "All arrays must be of the same length"
    _rows_are_the_points(r, df)
    assert list(df["Pi3"]) == [0.01] * 3 and list(df["eps"]) == [0.5] * 3
    assert df.attrs["runs"] == r.runs and df.attrs["method"] == r.method


def test_spectrum_to_pandas_as_many_curves_as_points():
    pytest.importorskip("pandas")
    # 3 curves of 3 points: the (curves, N) arrays were cut into columns Pi1[j], a row per
    # curve labelled as a Pi2
    r = pound.spectrum(Pi2_range=(0.5, 2, 3), Pi3=(0.01, 0.02, 0.03), eps=0.5)
    df = r.to_pandas()
    _rows_are_the_points(r, df)
    assert list(df["Pi3"]) == [0.01] * 3 + [0.02] * 3 + [0.03] * 3


def test_spectrum_to_pandas_every_list_swept():
    pytest.importorskip("pandas")
    r = pound.spectrum(Pi2_range=(0.5, 2, 4), dir=["normal", "reverse"], gap=(0.001, 0.002),
                       eps=(0.5, 0.8))
    df = r.to_pandas()
    _rows_are_the_points(r, df)
    assert len(df) == 2 * 2 * 2 * 4
    assert set(df["dir"]) == {"normal", "reverse"} and set(df["gap"]) == {0.001, 0.002}
    assert set(df["eps"]) == {0.5, 0.8}
    # the tidy frame pivots back to the curves
    one = df[(df["dir"] == "reverse") & (df["gap"] == 0.002) & (df["eps"] == 0.8)]
    c = next(i for i, cv in enumerate(r.curves)
             if (cv["dir"], cv["gap"], cv["eps"]) == ("reverse", 0.002, 0.8))
    assert np.array_equal(one["Pi1"].values, r.Pi1[c])


def test_spectrum_to_xarray_along_curve_and_pi2():
    pytest.importorskip("xarray")
    r = pound.spectrum(Pi2_range=(0.5, 2, 3), Pi3=(0.01, 0.02), eps=0.5)
    ds = r.to_xarray()  # raised "no history (run with history=True)": a spectrum has none
    assert ds["Pi1"].dims == ("curve", "Pi2") and np.array_equal(ds["Pi1"].values, r.Pi1)
    assert np.array_equal(ds["Pi2"].values, r.Pi2)
    assert list(ds["Pi3"].values) == [0.01, 0.02]


def test_converge_and_compare_to_pandas_are_their_rows():
    pytest.importorskip("pandas")
    c = pound.converge((1e-3, 2.5e-4, 3), theta=(0.5, 1.0), methods="moreau", **FIG9)
    df = c.to_pandas()  # was a Series of cpu_s_ref alone
    assert len(df) == len(c.rows) == 6
    assert list(df["theta"]) == [r.theta for r in c.rows]
    assert np.array_equal(df["err_hist_linf"].values, [r.err_hist_linf for r in c.rows])
    assert df.attrs["cpu_s_ref"] == c.cpu_s_ref
    m = pound.compare(methods=("moreau", "penalty"), **FIG9)
    dm = m.to_pandas()
    assert list(dm["method"]) == ["moreau", "penalty"]
    assert list(dm["err_umax_rel"]) == [x.err_umax_rel for x in m.methods]


def test_to_pandas_of_arrays_of_other_lengths_names_them():
    pytest.importorskip("pandas")
    r = pound.Result(a=np.zeros(3), b=np.zeros(2))
    with pytest.raises(ValueError, match="a: 3, b: 2"):
        r.to_pandas()


def test_history_frames_as_before():
    pytest.importorskip("pandas")
    r = pound.simulate_scene(THREE_SDOF)
    df = r.to_pandas()
    assert df.index.name == "t" and len(df) == len(r.t)
    assert np.array_equal(df["x[2]"].values, r.x[:, 2])
    s = pound.simulate(history=False, **FIG9).to_pandas()
    assert s["impacts"] == 5


# ---- 2. plot.impact_times: the contact index in range -------------------------------------

@pytest.fixture(scope="module")
def three():
    return pound.simulate_scene(THREE_SDOF)


@pytest.mark.parametrize("contact", [3, 5, -1, -3, -4])
def test_impact_times_contact_out_of_range(three, contact):
    with pytest.raises(ValueError) as e:  # 5: IndexError; -1: the last contact's marks
        pp.impact_times(three, contact=contact)
    msg = str(e.value)
    assert "contact = %d" % contact in msg and "0 to 2" in msg and "3 contacts" in msg


def test_impact_times_contact_in_range(three):
    for a in range(3):
        k, when = pp.impact_times(three, contact=np.int64(a))
        assert len(k) == three.contacts[a].impacts


def test_impact_times_oscillator_has_contact_0_only():
    r = pound.simulate(method="moreau", **FIG9)
    assert len(pp.impact_times(r, contact=0)[0]) == 5
    for bad in (1, -1):  # were the oscillator's impacts: contact ignored
        with pytest.raises(ValueError, match="contact = %d .*only 0" % bad):
            pp.impact_times(r, contact=bad)


@pytest.mark.parametrize("bad", [1.0, True, "0", None])
def test_impact_times_contact_not_an_index(three, bad):
    with pytest.raises(TypeError, match="contact must be an integer index"):
        pp.impact_times(three, contact=bad)


# ---- 3. record= as an array: real numbers only, at every entry point ----------------------

def rinaldi_in_g():
    lines = RINALDI.read_text().splitlines()[4:]
    return np.array([float(x) for line in lines for x in line.split()])


ACC = rinaldi_in_g()


def _masked():
    m = np.ma.masked_array(ACC.copy(), mask=np.zeros(ACC.size, bool))
    m[17] = np.ma.masked
    return m


BAD = [
    ("complex", lambda: ACC + 0j, "complex"),
    ("complex-imag", lambda: ACC + 1e-3j, "complex"),
    ("masked", _masked, "entry 17 is masked"),
    ("bool", lambda: ACC > 0, "bools"),
    ("strings", lambda: ACC.astype(str), "strings"),
    ("list-of-strings", lambda: [str(x) for x in ACC], "entry 0 is a string"),
    ("list-with-bool", lambda: [0.01, True] + list(ACC), "entry 1 is a bool"),
    ("list-with-none", lambda: list(ACC) + [None], "entry %d is None" % ACC.size),
    ("list-with-complex", lambda: [0.01, 2j] + list(ACC), "entry 1 is complex"),
    ("datetimes", lambda: np.zeros(ACC.size, "M8[s]"), "datetime64"),
]

ENTRY_POINTS = [
    ("simulate", lambda a: pound.simulate(record=a, record_dt=0.01, history=False, **CASE)),
    ("spectrum", lambda a: pound.spectrum(Pi2_range=(0.5, 1, 2), record=a, record_dt=0.01,
                                          Pi3=0.05)),
    ("compare", lambda a: pound.compare(record=a, record_dt=0.01, **CASE)),
    ("converge", lambda a: pound.converge((1e-3, 5e-4, 2), record=a, record_dt=0.01,
                                          methods="moreau", **CASE)),
    ("from_array", lambda a: pound.Record.from_array(a, 0.01)),
]


@pytest.mark.parametrize("entry,call", ENTRY_POINTS, ids=[e for e, _ in ENTRY_POINTS])
@pytest.mark.parametrize("kind,make,message", BAD, ids=[b[0] for b in BAD])
def test_record_array_not_real_refused(entry, call, kind, make, message):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning, no units warning: refused first
        with pytest.raises(pound.InputError) as e:
            call(make())
    assert str(e.value).startswith("record: ") and message in str(e.value), str(e.value)


def test_masked_record_says_what_it_takes():
    with pytest.raises(pound.InputError, match="taken only with no entry masked"):
        pound.simulate(record=_masked(), record_dt=0.01, history=False, **CASE)


def test_record_arrays_of_real_numbers_taken():
    """Floats, ints, a list of numbers and a masked array with nothing masked
    give the record of the same doubles."""
    ref = pound.simulate(record=ACC, record_dt=0.01, history=False, method="event", **CASE)
    for same in (list(ACC), tuple(ACC), np.ma.masked_array(ACC), np.ma.masked_array(ACC, False),
                 ACC.astype(object), ACC.astype(np.longdouble)):
        r = pound.simulate(record=same, record_dt=0.01, history=False, method="event", **CASE)
        assert r.umax == ref.umax and r.impacts == ref.impacts, type(same)
    ints = np.round(ACC * 980.665).astype(np.int32)  # in cm/s2, as ints and as their floats
    a = pound.Record.from_array(ints, 0.01, units="cm/s2")
    b = pound.Record.from_array(ints.astype(float), 0.01, units="cm/s2")
    c = pound.Record.from_array([int(x) for x in ints], 0.01, units="cm/s2")
    assert np.array_equal(a.acc, b.acc) and np.array_equal(a.acc, c.acc)


def test_lcp_arrays_refused_alike():
    """The lcp's M, q, cover go through the same check (pound/_args.real_array)."""
    with pytest.raises(pound.InputError, match="q: entry 1 is masked"):
        pound.lcp([[1, 0], [0, 1]], np.ma.masked_array([-1.0, -1.0], mask=[0, 1]))
    with pytest.raises(pound.InputError, match="M: .*entry \\(0, 1\\) is a bool"):
        pound.lcp([[1.0, False], [0, 1]], [-1, -1])
    with pytest.raises(pound.InputError, match="q: the entries are strings"):
        pound.lcp([[1, 0], [0, 1]], np.array(["-1", "-1"]))
    assert pound.lcp([[1, 0], [0, 1]], np.ma.masked_array([-1.0, -1.0])).solved


# ---- converge: one comparison grid, a degenerate range refused ------------------------------

def test_converge_equal_max_min_with_several_steps_refused():
    with pytest.raises(pound.InputError, match="MAX equals MIN"):
        pound.converge("1e-3:1e-3:3", **CASE)
    assert len(pound.converge("1e-3:1e-3:1", methods=("moreau",), **CASE).rows) == 1


def test_scene_converge_log_spaced_rows_on_one_grid():
    """Rows off the comparison grid (4.64e-4 against 1e-3) are compared at
    their steps interpolated onto it: the errors fall with dt as on their
    own grids, and each row's cpu_s is the run's alone (positive)."""
    r = pound.converge("1e-3:1e-4:4", scene=THREE_SDOF, methods=("moreau",))
    errs = [row.err_umax_rel for row in r.rows]
    assert all(b < a for a, b in zip(errs, errs[1:])), errs
    assert all(row.cpu_s > 0.0 for row in r.rows)
