"""pound.plot on the Agg backend: the artists drawn, where the marks are
(at the impacts the library counts, on the wall, on the right curve), and
that nothing calls show(); no image is compared."""
import sys

import numpy as np
import pytest

import pound

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import pound.plot as pp  # noqa: E402

from conftest import EXAMPLES  # noqa: E402

FIG9 = dict(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)  # 5 impacts, no accumulation


@pytest.fixture(autouse=True)
def no_show(monkeypatch):
    """Every figure is closed after the test, and show() fails it."""
    def show(*a, **k):
        raise AssertionError("pound.plot called show()")
    monkeypatch.setattr(plt, "show", show)
    yield
    plt.close("all")


def onsets(p):
    """Samples with an impulse after one without (the library's impacts)."""
    p = np.asarray(p) > 0
    return np.flatnonzero(p & ~np.r_[False, p[:-1]])


def test_oscillator_history_moreau_marks_every_impact_on_the_curve():
    r = pound.simulate(method="moreau", **FIG9)
    fig, ax = pp.history(r)
    assert fig is ax.figure and len(ax.lines) == 3  # u, the wall, the impacts
    u, wall, marks = ax.lines
    assert np.array_equal(u.get_xdata(), r.t) and np.array_equal(u.get_ydata(), r.u)
    assert list(wall.get_ydata()) == [r.gap, r.gap]  # axhline at u = gap [m]
    k = onsets(r.impulse)
    assert len(k) == r.impacts == 5 and marks.get_marker() == "o"
    assert np.array_equal(marks.get_xdata(), r.t[k])
    assert np.array_equal(marks.get_ydata(), r.u[k])
    # the first mark is the step that ends after the closing instant the library interpolates
    assert 0.0 <= marks.get_xdata()[0] - r.first_impact <= r.dt


def test_oscillator_history_event_reference_marks_on_the_wall():
    r = pound.simulate(**FIG9)  # the exact reference: impulses at the samples after its impacts
    assert r.method == "event" and np.count_nonzero(r.impulse) == r.impacts
    assert r.accumulations == 0 and r.impulse.max() == pytest.approx(r.max_impulse, rel=1e-14)
    fig, ax = pp.history(r)
    marks = ax.lines[2]
    t = marks.get_xdata()
    assert len(t) == r.impacts == 5
    assert np.all(marks.get_ydata() == r.gap)  # the oscillator strikes at u = gap
    # the linear closing time between samples against the reference's own first impact:
    # the curvature over one sample (dt = 1.5e-4 s) leaves far less than 1e-6 s
    assert abs(t[0] - r.first_impact) < 1e-6
    assert np.all(np.diff(t) > 0) and t[-1] < r.tend


def test_oscillator_history_scaled_and_without_marks():
    r = pound.simulate(method="moreau", **FIG9)
    Le = r.ap * (r.Tp / (2 * np.pi)) ** 2
    fig, ax = pp.history(r, scaled=True, impacts=False)
    assert len(ax.lines) == 2
    assert np.allclose(ax.lines[0].get_xdata(), r.t / r.Tp, rtol=0, atol=0)
    assert np.array_equal(ax.lines[0].get_ydata(), r.u / Le)
    assert ax.lines[1].get_ydata()[0] == pytest.approx(r.gap / Le, rel=1e-15)  # Pi3


@pytest.mark.parametrize("method", ["moreau", "event"])
def test_no_wall_draws_no_wall(method):
    r = pound.simulate(method=method, no_wall=True, **FIG9)
    assert r.umax > r.gap and r.impacts == 0  # it went through where the wall would be
    fig, ax = pp.history(r)
    assert len(ax.lines) == 1


def test_scene_history_three_sdof():
    r = pound.simulate_scene(EXAMPLES / "scenes" / "three-sdof.json")
    assert r.method == "moreau"
    fig, ax = pp.history(r)
    # S1, S2, S3; the wall at -0.01 m (left of S1: gap = 0.01 + x_S1); marks of contact
    # wall-S1 on S1, S1-S2 on both, S2-S3 on both
    assert len(ax.lines) == 3 + 1 + 5
    for j in range(3):
        assert np.array_equal(ax.lines[j].get_ydata(), r.x[:, j])
    assert list(ax.lines[3].get_ydata()) == [-0.01, -0.01]
    marks = ax.lines[4:]
    sides = [(0, 0), (1, 0), (1, 1), (2, 1), (2, 2)]  # (contact, dof) of each mark line
    for line, (a, dof) in zip(marks, sides):
        k = onsets(r.history.impulse[:, a])
        assert len(k) == r.contacts[a].impacts
        assert np.array_equal(line.get_xdata(), r.t[k])
        assert np.array_equal(line.get_ydata(), r.x[k, dof])
        assert 0.0 <= line.get_xdata()[0] - r.contacts[a].first_impact <= r.dt


def test_scene_history_chain_two_walls_into_given_axes():
    fig, ax0 = plt.subplots()
    with pound.Scene.chain(3, pulse="sine", ap=4, Tp=0.5, T0=1, gap=0.01, eps=0.5) as sc:
        r = sc.simulate(tend=1.0, dt=1e-3)
    fig2, ax = pp.history(r, ax=ax0, impacts=False)
    assert ax is ax0 and fig2 is fig
    walls = sorted(ln.get_ydata()[0] for ln in ax.lines if ln.get_linestyle() == "--")
    assert walls == [-0.01, 0.01] and len(ax.lines) == 3 + 2


def test_multistorey_curves_are_the_storeys_in_contact():
    r = pound.simulate_scene(EXAMPLES / "scenes" / "three-buildings.json", tend=0.2)
    fig, ax = pp.history(r, impacts=False, wall=False)
    # low: storeys 1-3 (wall at 1, tower at 1-3); tower: 1-5; mid: 1-5; dofs 0-2, 3-7, 11-15
    dofs = [0, 1, 2, 3, 4, 5, 6, 7, 11, 12, 13, 14, 15]
    assert len(ax.lines) == len(dofs)
    for line, d in zip(ax.lines, dofs):
        assert np.array_equal(line.get_ydata(), r.x[:, d])


def test_history_needs_a_history():
    r = pound.simulate(history=False, **FIG9)
    with pytest.raises(ValueError, match="history=True"):
        pp.history(r)


def test_spectrum_in_pi_terms_and_the_traditional_view():
    s = pound.spectrum(Pi2_range=(0.1, 5, 12), pulse="sine", dir=["normal", "reverse"],
                       Pi3=[0.01, 0.1, 1], eps=0.5, threads=1)
    fig, axes = pp.spectrum(s)
    assert axes.shape == (1, 2)
    for j, d in enumerate(("normal", "reverse")):
        ax = axes[0, j]
        assert ax.get_xscale() == ax.get_yscale() == "log" and d in ax.get_title()
        assert len(ax.lines) == 3
        for i, line in enumerate(ax.lines):
            k = 3 * j + i  # curves: dir slowest, Pi3 fastest
            assert s.curves[k].dir == d
            assert np.array_equal(line.get_xdata(), s.Pi2)
            assert np.array_equal(line.get_ydata(), s.Pi1[k])
            assert ("%g" % s.curves[k].Pi3) in line.get_label()
    fig, axes = pp.spectrum(s, traditional=True)
    assert axes.shape == (2, 2)
    for j in range(2):
        assert len(axes[1, j].lines) == 3 and axes[1, j].get_xscale() == "log"
        for i, line in enumerate(axes[1, j].lines):
            assert np.array_equal(line.get_xdata(), s.chi[3 * j + i])
            assert np.array_equal(line.get_ydata(), s.gamma[3 * j + i])


def test_record_plot():
    path = EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2"
    rec = pound.record(path)
    fig, ax = pp.record(rec, in_g=False)
    acc, pulse, peak = ax.lines
    assert np.array_equal(acc.get_ydata(), rec.acc)
    assert np.array_equal(pulse.get_ydata(), rec.pulse_acc)
    assert peak.get_xdata()[0] == pytest.approx(rec.t_pga, abs=rec.dt / 2)
    assert abs(peak.get_ydata()[0]) == pytest.approx(rec.pga, rel=1e-12)
    # in g: the curves and every label's figure in g (they mixed in m/s^2)
    fig, ax = pp.record(rec)
    acc, pulse, peak = ax.lines
    g = 9.80665
    assert np.allclose(acc.get_ydata(), rec.acc / g, rtol=1e-15)
    assert "pga = %.3g g" % (rec.pga / g) in peak.get_label()
    assert "ap = %.3g g" % (rec.pulse["ap"] / g) in pulse.get_label()
    assert "m/s" not in peak.get_label() + pulse.get_label()


def test_without_matplotlib_the_message_says_what_to_install(monkeypatch):
    r = pound.simulate(method="moreau", **FIG9)
    for name in list(sys.modules):
        if name == "matplotlib" or name.startswith("matplotlib."):
            monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(ImportError, match="needs Matplotlib.*python3-matplotlib"):
        pp.history(r)
