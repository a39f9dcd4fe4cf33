"""Each function against closed forms and invariants."""
import ctypes
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pound
from pound import _lib
from conftest import EXAMPLES, RECORDS

HERE = Path(__file__).resolve().parent


def free_sine_umax(ap, Tp, T0):
    """umax of the undamped oscillator from rest under ap sin(wp t) on
    [0, Tp], when its peak comes after the pulse: the free vibration's
    amplitude sqrt(u^2 + (v / w0)^2) at Tp."""
    wp, w0 = 2 * math.pi / Tp, 2 * math.pi / T0
    k = ap / (w0 ** 2 - wp ** 2)
    u = k * (math.sin(wp * Tp) - wp / w0 * math.sin(w0 * Tp))
    v = k * (wp * math.cos(wp * Tp) - wp * math.cos(w0 * Tp))
    t = np.linspace(0, Tp, 20001)
    during = np.max(np.abs(k * (np.sin(wp * t) - wp / w0 * np.sin(w0 * t))))
    amp = math.hypot(u, v / w0)
    assert amp > during
    return amp


# ---- simulate -------------------------------------------------------------------------------

def test_free_response_closed_form():
    r = pound.simulate(pulse="sine", ap=2, Tp=0.5, T0=2.5, xi=0, Pi3=1e3, method="event",
                       history=False)
    exact = free_sine_umax(2, 0.5, 2.5)
    assert r.impacts == 0
    assert abs(r.umax_free - exact) <= 1e-12 * exact
    assert r.umax == r.umax_free and r.gamma == 1.0
    m = pound.simulate(pulse="sine", ap=2, Tp=0.5, T0=2.5, xi=0, Pi3=1e3, history=False,
                       method="moreau")
    assert abs(m.umax - exact) < 1e-5 * exact  # Moreau-Jean, dt = Tp / 2000
    d = pound.simulate(pulse="sine", ap=2, Tp=0.5, T0=2.5, xi=0, Pi3=1e3, history=False)
    assert d.method == "event" and d.method_by == "default"  # the default: exact
    assert abs(d.umax - exact) < 1e-13 * exact


def test_summary_figures():
    r = pound.simulate(pulse="cosine", ap=3, Tp=0.6, Pi2=0.7, Pi3=0.2, eps=0.6, theta=0.5)
    assert r.method == "moreau" and r.method_by == "--theta"  # as the CLI's --theta
    Le = r.ap / (2 * math.pi / r.Tp) ** 2
    assert r.gamma == r.umax / r.umax_free and r.chi == r.gap / r.umax_free
    assert abs(r.Pi1 - r.umax / Le) <= 1e-15 * r.Pi1
    assert abs(r.gap - r.Pi3 * Le) <= 1e-15 * r.gap and abs(r.T0 - r.Tp / r.Pi2) < 1e-15
    assert r.impacts >= 1 and r.first_impact > 0 and r.contact_time >= 0
    assert r.umax == max(r.u_toward, r.u_away)
    # the history: every step from 0 to tend, Moreau-Jean's umax its largest |u|
    assert len(r.t) == r.steps + 1 and r.t[0] == 0
    assert abs(r.t[-1] - r.steps * r.dt) < 1e-12 and r.tend <= r.t[-1] < r.tend + r.dt
    assert np.allclose(np.diff(r.t), r.dt, rtol=1e-9, atol=0)
    assert np.max(np.abs(r.u)) == r.umax
    assert np.allclose(r.history.gap, r.gap - r.u, rtol=0, atol=1e-15)
    assert abs(r.u_toward - (r.gap - r.min_gap)) < 1e-15 and -0.01 * r.gap < r.min_gap < 0
    assert np.all(r.impulse >= 0) and np.count_nonzero(r.impulse) >= r.impacts


def test_dimensionless_history_is_scale_free():
    """The paper's Fig. 3: the same Pi terms give the same Pi1 whatever ap, Tp."""
    a = pound.simulate(pulse="cosine", ap=3, Tp=0.3, Pi2=0.6, Pi3=0.2, eps=0.7)
    b = pound.simulate(pulse="cosine", ap=5, Tp=0.9, Pi2=0.6, Pi3=0.2, eps=0.7)
    assert abs(a.Pi1 - b.Pi1) <= 1e-12 * a.Pi1
    La, Lb = a.umax / a.Pi1, b.umax / b.Pi1
    assert np.allclose(a.u / La, b.u / Lb, rtol=0, atol=1e-10 * a.Pi1)


def test_every_keeps_every_kth_step():
    kw = dict(pulse="sine", Pi2=0.5, Pi3=0.1)
    full, some = pound.simulate(**kw), pound.simulate(every=10, **kw)
    assert np.array_equal(some.history.step, full.history.step[::10])
    assert np.array_equal(some.u, full.u[::10])


def test_methods_agree():
    kw = dict(pulse="sine", dir="normal", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6,
              history=False)
    ref = pound.simulate(method="event", **kw)
    for method, tol in (("moreau", 2e-3), ("penalty", 2e-2)):
        r = pound.simulate(method=method, **kw)
        assert abs(r.umax - ref.umax) < tol * ref.umax, method
        assert r.impacts == ref.impacts
    assert abs(ref.umax - 0.175) < 1e-3 and ref.impacts == 5  # docs/paper.md, Fig. 9


def test_compare_and_converge():
    kw = dict(pulse="sine", Pi2=0.5, Pi3=0.1, eps=0.5)
    c = pound.compare(**kw)
    assert c.err_umax_rel < 1e-5 and c.err_hist_linf < 1e-3 and c.impacts >= 1
    assert c.err_umax_rel == abs(c.umax - c.umax_ref) / c.umax_ref
    # without contact the theta = 1/2 scheme is of order 2, theta = 1 of order 1
    # (the default methods also run Moreau-Jean to a tolerance: rows after the fixed steps')
    rows = pound.converge("0.01:0.0025:3", theta=[0.5, 1.0], pulse="sine", Pi2=0.5,
                          Pi3=100).rows
    assert [r.theta for r in rows[:6]] == [0.5, 1.0] * 3 and math.isnan(rows[0].order)
    for r in rows[2:6]:
        want = 2.0 if r.theta == 0.5 else 1.0
        assert abs(r.order - want) < 0.1, r
    assert all(math.isnan(r.rtol) and math.isnan(r.err_est) for r in rows[:6])
    assert [r.rtol for r in rows[6:]] == [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
    fixed = pound.converge("0.01:0.0025:3", theta=[0.5, 1.0], methods="moreau", pulse="sine",
                           Pi2=0.5, Pi3=100).rows
    assert [r.err_hist_linf for r in fixed] == [r.err_hist_linf for r in rows[:6]]
    assert pound.dt_range(0.004, 0.0005, 4)[0] == 0.004
    assert abs(pound.dt_range(0.004, 0.0005, 4)[-1] - 0.0005) < 1e-18


# ---- spectrum -------------------------------------------------------------------------------

def test_spectrum_invariants():
    s1 = pound.spectrum(Pi2_range=(0.1, 4, 12), Pi3=[0.05, 1], eps=[0.5], pulse=["sine", "cosine"],
                        method="event", threads=1)
    s3 = pound.spectrum(Pi2_range=(0.1, 4, 12), Pi3=[0.05, 1], eps=[0.5], pulse=["sine", "cosine"],
                        method="event", threads=3)
    for k in ("Pi1", "gamma", "chi", "umax", "impacts"):
        assert np.array_equal(s1[k], s3[k], equal_nan=True), k  # any split of the tasks
    assert s1.Pi2[0] == 0.1 and s1.Pi2[-1] == 4.0
    assert np.allclose(np.diff(np.log(s1.Pi2)), math.log(40) / 11, rtol=1e-12)
    assert s1.Pi1.shape == (4, 12) and [c.pulse for c in s1.curves] == ["sine"] * 2 + \
        ["cosine"] * 2 and [c.Pi3 for c in s1.curves] == [0.05, 1] * 2
    assert np.array_equal(s1.gamma, s1.umax / s1.umax_free)
    Le = 1.0 / (2 * math.pi) ** 2
    assert np.allclose(s1.Pi1, s1.umax / Le, rtol=1e-15, atol=0)
    # a point of the spectrum is the run of simulate() with its Pi terms
    j = 5
    r = pound.simulate(pulse="cosine", Pi2=s1.Pi2[j], Pi3=1, eps=0.5, method="event",
                       history=False)
    assert r.Pi1 == s1.Pi1[3, j] and r.umax_free == s1.umax_free[3, j]


@pytest.mark.skipif(not hasattr(_lib.lib, "pd_spec_sweep"), reason="no pd_spec_sweep")
def test_spectrum_on_point_stops():
    seen = []
    with pytest.raises(pound.PoundError) as e:
        pound.spectrum(Pi2_range=(0.5, 2, 5), eps=[0.2, 0.9], method="event",
                       on_point=lambda p: seen.append(p) or len(seen) == 3)
    assert e.value.status == -11 and len(seen) == 3
    assert [p.Pi2 for p in seen] == [0.5, pound.spectrum(Pi2_range=(0.5, 2, 5)).Pi2[1], seen[2].Pi2]

    def boom(p):
        raise KeyError("from the callback")
    with pytest.raises(KeyError):
        pound.spectrum(Pi2_range=(0.5, 2, 5), on_point=boom)


def test_spectra_collapse_in_pi_terms():
    """The paper's Fig. 4: amplitudes 1, 3, 9 m/s^2 at one Pi3 give one curve."""
    s = pound.spectrum(Pi2_range=(0.05, 5, 20), ap=[1, 3, 9], Pi3=0.05, pulse="cosine", Tp=0.5,
                       method="event")
    assert not np.allclose(s.umax[0], s.umax[2])
    assert np.allclose(s.Pi1[0], s.Pi1[1], rtol=1e-12) and np.allclose(s.Pi1[0], s.Pi1[2],
                                                                      rtol=1e-12)


# ---- lcp ------------------------------------------------------------------------------------

def test_lcp_identity_closed_form():
    q = np.array([-1.5, 2.0, 0.0, -0.25, 3.0])
    r = pound.lcp(np.eye(5), q)
    assert r.solved and r.status == "solved"
    assert np.allclose(r.z, np.maximum(-q, 0), atol=1e-15)
    assert np.allclose(r.w, np.maximum(q, 0), atol=1e-15)


@pytest.mark.parametrize("solver", ["auto", "lemke", "structured", "pgs"])
def test_lcp_against_enumeration(solver):
    rng = np.random.default_rng(7)
    for n in (2, 5, 9):
        A = rng.normal(size=(n, n))
        M = A @ A.T + n * np.eye(n)  # symmetric positive definite: one solution
        q = rng.normal(size=n)
        r = pound.lcp(M, q, solver=solver)
        assert r.solved, r.status
        z, w = np.zeros(n), np.zeros(n)
        Mf = np.asfortranarray(M)
        P = ctypes.POINTER(ctypes.c_double)
        assert _lib.lib.pd_lcp_enumerate(n, Mf.ctypes.data_as(P), q.ctypes.data_as(P),
                                         z.ctypes.data_as(P), w.ctypes.data_as(P)) == 0
        assert np.allclose(r.z, z, atol=1e-8) and np.allclose(r.w, M @ r.z + q, atol=1e-10)
        assert r.residual <= 1e-10 and np.all(r.z >= 0) and abs(r.z @ r.w) < 1e-10


def test_lcp_without_solution():
    r = pound.lcp([[-1.0]], [-1.0], solver="lemke")
    assert not r.solved and r.status == "no_solution"


def test_lcp_sparse_and_files(tmp_path):
    n = 6
    M = 4 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    q = np.linspace(-1, 1, n)
    f = tmp_path / "tri.lcp"
    f.write_text("%d\n" % n + "".join(" ".join("%.17g" % x for x in row) + "\n" for row in M)
                 + " ".join("%.17g" % x for x in q) + "\n")
    M2, q2 = pound.read_lcp(f)
    assert np.array_equal(M2, M) and np.array_equal(q2, q)
    dense = pound.lcp(M, q, solver="structured")
    try:
        import scipy.sparse as sp
    except ImportError:
        return
    sparse = pound.lcp(sp.csc_matrix(M), q, solver="structured")
    assert sparse.solved and np.allclose(sparse.z, dense.z, atol=1e-14)


# ---- scenes ---------------------------------------------------------------------------------

def test_scene_description_and_history():
    sc = pound.scene(EXAMPLES / "scenes" / "two-sdof.json")
    assert [s.name for s in sc.structures] == ["stiff", "flexible"] and sc.n == 2
    assert abs(sc.structures[0].T0 - 0.4) < 1e-12 and sc.structures[1].mass[0] == 1e5
    c = sc.contacts[0]
    assert (c.a, c.b, c.gap, c.eps) == ("stiff", "flexible", 0.02, 0.65)
    assert sc.excitation == {"pulse": "cosine", "dir": "+x", "ap": 3.0, "Tp": 0.6}
    r = sc.simulate()
    assert r.x.shape == (r.steps + 1, 2) and r.history.gap.shape == (r.steps + 1, 1)
    # g = gap + x_b - x_a
    assert np.allclose(r.history.gap[:, 0], 0.02 + r.x[:, 1] - r.x[:, 0], rtol=0, atol=1e-15)
    for k, st in enumerate(r.structures):
        assert abs(st.Pi2 - 0.6 / st.T0) < 1e-15
        assert st.umax[0] == np.max(np.abs(r.x[:, k]))
        assert np.allclose(st.Pi1, st.umax / r.Le, rtol=1e-15)
    assert r.contacts[0].impacts == 5
    sc.close()


def test_scene_oscillator_is_the_oscillator():
    """examples/scenes/oscillator.json: the Fig. 9 case as a scene."""
    a = pound.simulate_scene(EXAMPLES / "scenes" / "oscillator.json", history=False)
    b = pound.simulate(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6, history=False,
                       method="moreau")  # a scene's default
    assert abs(a.structures[0].umax[0] - b.umax) < 1e-12 * b.umax
    assert a.contacts[0].impacts == b.impacts


def test_chain():
    sc = pound.Scene.chain(4, ratio=2.0, T0=1.0, Pi3=0.1, eps=0.5)
    T0 = [s.T0 for s in sc.structures]
    assert len(T0) == 4 and len(sc.contacts) == 5
    assert np.allclose(T0, [1, 2, 1, 2], rtol=1e-12)
    assert sc.contacts[0].a == "wall" and sc.contacts[-1].b == "wall"
    r = sc.simulate(history=False, method="event")
    assert len(r.structures) == 4 and all(st.umax[0] > 0 for st in r.structures)


# ---- records --------------------------------------------------------------------------------

RECORD = EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2"  # shipped (examples/records)


@pytest.mark.skipif(not RECORD.exists(), reason="no records in %s" % RECORDS)
def test_record_measures():
    r = pound.record(RECORD)
    assert r.npts == len(r.acc) == len(r.t) and r.dt == 0.01
    k = int(np.argmax(np.abs(r.acc)))
    assert r.pga == abs(r.acc[k]) and abs(r.t_pga - k * r.dt) < 1e-12
    vel = np.concatenate([[0], np.cumsum(0.5 * r.dt * (r.acc[1:] + r.acc[:-1]))])
    assert np.allclose(r.vel, vel, rtol=0, atol=1e-12)
    assert r.pgv >= np.max(np.abs(r.vel)) - 1e-15 and r.pgd >= np.max(np.abs(r.disp)) - 1e-15
    p = r.pulse
    assert abs(p.wp - 2 * math.pi / p.Tp) < 1e-12 and abs(p.Le - p.ap / p.wp ** 2) < 1e-12
    assert 0 < p.r2 <= 1 and p.shape in ("sine", "cosine")
    assert np.max(np.abs(r.pulse_acc)) <= p.ap * (1 + 1e-12)
    # the Pi terms of a record's run are its fitted pulse's
    s = pound.simulate(record=RECORD, T0=0.8, gap=0.01, history=False, method="event")
    assert s.ap == p.ap and s.Tp == p.Tp and s.record == RECORD.name


# ---- the example ----------------------------------------------------------------------------

def test_paper_example(tmp_path):
    png = tmp_path / "fig5.png"
    script = HERE.parent / "examples" / "paper_spectrum.py"
    out = subprocess.run([sys.executable, str(script), str(png), "30"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=dict(os.environ))
    assert out.returncode == 0, out.stderr.decode()
    assert png.stat().st_size > 10000 and png.read_bytes()[:4] == b"\x89PNG"
