"""Results in the tools of notebooks: a short repr, to_pandas() and
to_xarray() of a history (pandas and xarray: python3-pandas, python3-xarray,
installed by scripts/deps.sh --python)."""
import numpy as np
import pytest

import pound
from conftest import EXAMPLES

FIG9 = dict(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)


def test_short_repr():
    r = pound.simulate(**FIG9)
    text = repr(r)
    assert len(text) < 400 and "umax=0.175108" in text and "more)" in text
    assert repr(r.history).count("array(") == 7  # step, t, u, v, impulse, gap, impacts


def test_to_pandas_oscillator():
    pd = pytest.importorskip("pandas")
    r = pound.simulate(**FIG9)
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t"
    assert np.array_equal(df.index.values, r.t) and np.array_equal(df["u"].values, r.u)
    assert df.attrs["umax"] == r.umax
    # without a history: the scalars
    s = pound.simulate(history=False, **FIG9).to_pandas()
    assert s["umax"] == r.umax


def test_to_xarray_scene():
    xr = pytest.importorskip("xarray")
    r = pound.simulate_scene(EXAMPLES / "scenes" / "two-sdof.json")
    ds = r.to_xarray()
    assert isinstance(ds, xr.Dataset) and "t" in ds.coords
    assert ds["x"].dims == ("t", "dof") and np.array_equal(ds["x"].values, r.x)
    assert float(ds["x"].sel(t=r.t[10]).values[0]) == r.x[10, 0]


def test_to_xarray_scene_names_and_units():
    """The dofs and contacts named (NAME.k; sides and level), CF units."""
    pytest.importorskip("xarray")
    r = pound.simulate_scene(EXAMPLES / "scenes" / "three-buildings.json", every=50)
    ds = r.to_xarray()
    assert ds["x"].dims == ("t", "dof") and ds["gap"].dims == ("t", "contact")
    assert list(ds["dof"].values)[:2] == ["low.1", "low.2"]
    assert list(ds["contact"].values)[:2] == ["wall-low@1", "low-tower@1"]
    units = {k: ds[k].attrs.get("units") for k in ("x", "v", "a", "gap", "impulse")}
    assert units == {"x": "m", "v": "m/s", "a": "m/s^2", "gap": "m", "impulse": "N s"}
    assert ds["t"].attrs["units"] == "s"
    # every 50th step's a_abs is among the states the demands measured
    acc = np.concatenate([st.acc_max for st in r.structures])
    assert np.all(np.abs(ds["a"].values).max(axis=0) <= acc)
    assert float(np.abs(ds["a"].sel(dof="tower.1")).max()) == np.abs(r.history.a[:, 3]).max()
