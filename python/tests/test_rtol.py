"""Moreau-Jean to a tolerance (the keyword rtol, the CLI's --rtol): the
Python numbers are the CLI's to the last bit, rtol goes where the CLI sends
it (Moreau-Jean's steps, or the penalty integrator's tolerance), the
refusals are the CLI's, and the figures it reports (rtol, err_est, rtol_met,
steps_rejected, dt_min, dt_max) hold what they say."""
import math
import subprocess

import numpy as np
import pytest

import pound
from conftest import EXAMPLES, pound_bin, read_csv

OSC = dict(Pi2=1.5, Pi3=0.1, eps=0.5)
OSC_ARGS = ["--Pi2", "1.5", "--Pi3", "0.1", "--eps", "0.5"]
FIG9 = dict(pulse="sine", dir="normal", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
REVERSE = dict(pulse="cosine", dir="reverse", Tp=0.5, Pi2=0.8, Pi3=0.1, eps=0.7, xi=0.02)
THREE = EXAMPLES / "scenes" / "three-sdof.json"
TWO = EXAMPLES / "scenes" / "two-sdof.json"
TOLERANCE_KEYS = ("rtol", "err_est", "rtol_met", "steps", "steps_rejected", "dt_min", "dt_max")


def _refused_by_cli(*args):
    """The CLI's exit status and its message for a refused run."""
    out = subprocess.run([str(pound_bin())] + [str(a) for a in args], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, check=False)
    return out.returncode, out.stderr.decode()


# ---- bit for bit the CLI's --------------------------------------------------------------------

def test_oscillator_to_a_tolerance_is_the_cli(cli, same):
    js = cli("simulate", *OSC_ARGS, "--rtol", "1e-4")
    r = pound.simulate(rtol=1e-4, history=False, **OSC)
    same(r, js)  # every key of the JSON, == on doubles
    assert (r.method, r.method_by, js["method"], js["method_by"]) == \
        ("moreau", "--rtol", "moreau", "--rtol")
    assert r.umax == js["umax"] and r.err_est == js["err_est"] and r.steps == js["steps"]
    assert r.steps_rejected == js["steps_rejected"] > 0
    assert (r.dt_min, r.dt_max) == (js["dt_min"], js["dt_max"])
    assert r.rtol == 1e-4 and r.rtol_met is True and js["rtol_met"] is True
    assert 0.0 < r.err_est <= r.rtol
    assert 0.0 < r.dt_min < r.dt_max  # steps of more than one size


def test_oscillator_history_to_a_tolerance_is_the_cli_file(cli, same, tmp_path):
    """With a history the kept run is repeated for the sampler (steps count
    both), as the CLI's -o: the same figures and the same file."""
    out = tmp_path / "run.csv"
    js = cli("simulate", *OSC_ARGS, "--rtol", "1e-4", "-o", out)
    r = pound.simulate(rtol=1e-4, **OSC)
    same(r, js)
    bare = pound.simulate(rtol=1e-4, history=False, **OSC)
    assert r.umax == bare.umax and r.err_est == bare.err_est and r.steps > bare.steps
    header, data = read_csv(out)
    assert header == ["t", "u", "v", "impulse", "gap"]
    for k, name in enumerate(header):
        assert np.array_equal(r.history[name], data[:, k]), name
    dt = np.diff(r.t)
    assert dt.min() > 0.0 and dt.max() <= r.dt_max * (1 + 1e-12) and len(np.unique(dt)) > 1


def test_scene_to_a_tolerance_is_the_cli(cli, same):
    js = cli("simulate", "--scene", THREE, "--rtol", "1e-4")
    r = pound.simulate_scene(THREE, rtol=1e-4, history=False)
    same(r, js)
    assert (r.method, r.method_by) == ("moreau", "--rtol")
    assert r.err_est == js["err_est"] and r.steps == js["steps"]
    assert r.steps_rejected == js["steps_rejected"] > 0 and r.rtol == 1e-4
    for st, sj in zip(r.structures, js["structures"]):
        assert st.umax.tolist() == sj["umax"] and st.err_est == sj["err_est"]
    # the top-level estimate is the largest structure's
    assert r.err_est == max(st.err_est for st in r.structures)
    assert r.rtol_met is True and 0.0 < r.err_est <= 1e-4


def test_scene_history_to_a_tolerance_is_the_cli_file(cli, same, tmp_path):
    out = tmp_path / "scene.csv"
    js = cli("simulate", "--scene", THREE, "--rtol", "1e-4", "-o", out)
    r = pound.simulate_scene(THREE, rtol=1e-4)
    same(r, js)
    _, data = read_csv(out)
    cols = np.column_stack([r.t, r.x, r.v, r.history.gap, r.history.impulse, r.history.a])
    assert np.array_equal(cols, data)


def test_scene_object_and_chain_to_a_tolerance(cli, same):
    with pound.Scene(TWO) as sc:
        same(sc.simulate(rtol=1e-5, history=False),
             cli("simulate", "--scene", TWO, "--rtol", "1e-5"))
    same(pound.Scene.chain(4, Pi3=0.05, eps=0.5).simulate(rtol=1e-3, history=False),
         cli("simulate", "--chain", "4", "--Pi3", "0.05", "--eps", "0.5", "--rtol", "1e-3"))


def test_rtol_with_another_moreau_keyword(cli, same):
    """theta chooses moreau (method_by --theta); rtol is then its tolerance."""
    js = cli("simulate", *OSC_ARGS, "--theta", "0.6", "--rtol", "1e-3")
    r = pound.simulate(theta=0.6, rtol=1e-3, history=False, **OSC)
    same(r, js)
    assert (r.method_by, r.rtol, r.theta) == ("--theta", 1e-3, 0.6)


# ---- rtol with the penalty method: the integrator's tolerance, as before ------------------------

def test_rtol_with_penalty_is_the_integrators_tolerance(cli, same):
    js = cli("simulate", *OSC_ARGS, "--method", "penalty", "--rtol", "1e-8")
    r = pound.simulate(method="penalty", rtol=1e-8, history=False, **OSC)
    same(r, js)
    assert r.umax == js["umax"] and r.steps == js["steps"]
    default = pound.simulate(method="penalty", history=False, **OSC)  # pen.rtol 1e-10
    assert r.umax != default.umax and r.steps < default.steps  # the looser tolerance ran
    # no Moreau-Jean tolerance in the result
    assert r.rtol == 0.0 and r.rtol_met is True and math.isnan(r.err_est)
    assert r.steps_rejected == 0 and math.isnan(r.dt_min) and math.isnan(r.dt_max)
    # kc chooses penalty: rtol goes to its integrator there too
    js = cli("simulate", *OSC_ARGS, "--kc", "1e5", "--rtol", "1e-8")
    k = pound.simulate(kc=1e5, rtol=1e-8, history=False, **OSC)
    same(k, js)
    assert (k.method, k.method_by, k.rtol) == ("penalty", "--kc", 0.0)


def test_scene_rtol_with_penalty(cli, same):
    js = cli("simulate", "--scene", TWO, "--method", "penalty", "--rtol", "1e-6")
    r = pound.simulate_scene(TWO, method="penalty", rtol=1e-6, history=False)
    same(r, js)
    assert r.rtol == 0.0 and math.isnan(r.err_est)
    default = pound.simulate_scene(TWO, method="penalty", history=False)
    assert r.steps != default.steps


def test_compare_and_converge_take_rtol_as_the_penalty_tolerance():
    """compare and converge run Moreau-Jean on fixed steps: rtol there is the
    penalty rows' integrator tolerance (it chooses no method)."""
    a = pound.compare(methods="moreau,penalty", **OSC)
    b = pound.compare(methods="moreau,penalty", rtol=1e-6, **OSC)
    assert a.methods[0].err_umax_rel == b.methods[0].err_umax_rel  # moreau: untouched
    assert a.methods[0].impacts == b.methods[0].impacts
    assert a.methods[1].steps != b.methods[1].steps  # penalty: its tolerance
    c = pound.converge("0.004:0.002:2", methods="penalty", kcs=[1e4], rtol=1e-6, **OSC)
    d = pound.converge("0.004:0.002:2", methods="penalty", kcs=[1e4], **OSC)
    assert c.rows[0].steps != d.rows[0].steps


# ---- refusals ----------------------------------------------------------------------------------

def test_rtol_with_dt_is_refused_as_the_cli_refuses_it():
    with pytest.raises(pound.InputError) as e:
        pound.simulate(rtol=1e-4, dt=1e-3, **OSC)
    assert str(e.value) == ("rtol and dt: Moreau-Jean takes fixed steps (dt) or steps to a "
                            "tolerance (rtol), not both")
    assert e.value.status == -2
    with pytest.raises(pound.InputError) as e:
        pound.simulate_scene(TWO, rtol=1e-4, dt=1e-3)
    assert str(e.value).startswith("rtol and dt: Moreau-Jean takes fixed steps")
    status, msg = _refused_by_cli("simulate", *OSC_ARGS, "--rtol", "1e-4", "--dt", "1e-3")
    assert status == 2 and "--rtol and --dt: Moreau-Jean takes fixed steps (--dt)" in msg


@pytest.mark.parametrize("kw,flags,message", [
    (dict(method="event"), ["--method", "event"], "method event has none"),
    (dict(method="newmark"), ["--method", "newmark"], "method newmark has none"),
    (dict(no_accumulation=True), ["--no-accumulation"], "method event has none"),
])
def test_rtol_with_a_method_without_one_is_refused(kw, flags, message):
    with pytest.raises(pound.InputError) as e:
        pound.simulate(rtol=1e-4, history=False, **dict(OSC, **kw))
    assert str(e.value) == ("rtol: the tolerance of moreau's steps or of penalty's "
                            "integrator; " + message)
    status, msg = _refused_by_cli("simulate", *OSC_ARGS, "--rtol", "1e-4", *flags)
    assert status == 2 and "--rtol: the tolerance of moreau's steps" in msg


@pytest.mark.parametrize("value", [0.0, 1.0, 1e-13, -1e-4, 2.0])
def test_rtol_out_of_range(value):
    with pytest.raises(pound.InputError) as e:
        pound.simulate(rtol=value, history=False, **OSC)
    assert str(e.value).startswith("rtol: the relative tolerance must be in [1e-12, 1) (got ")
    status, msg = _refused_by_cli("simulate", *OSC_ARGS, "--rtol", repr(value))
    assert status == 2 and "--rtol: the relative tolerance must be in [1e-12, 1)" in msg


def test_spectrum_refuses_moreaus_tolerance():
    with pytest.raises(pound.InputError) as e:
        pound.spectrum(Pi2_range=(0.5, 2, 2), rtol=1e-4)
    assert str(e.value).startswith("rtol: a spectrum runs Moreau-Jean on fixed steps")
    s = pound.spectrum(Pi2_range=(0.5, 2, 2), method="penalty", rtol=1e-6, threads=1)
    d = pound.spectrum(Pi2_range=(0.5, 2, 2), method="penalty", threads=1)
    assert s.method == "penalty" and not np.array_equal(s.steps, d.steps)


# ---- what the figures say ----------------------------------------------------------------------

@pytest.mark.parametrize("method", ["moreau", "event", "penalty", "newmark"])
def test_fixed_steps_report_no_tolerance(cli, same, method):
    r = pound.simulate(method=method, history=False, **OSC)
    js = cli("simulate", *OSC_ARGS, "--method", method)
    same(r, js)
    assert r.rtol == 0.0 and r.rtol_met is True and r.steps_rejected == 0
    assert math.isnan(r.err_est) and js["err_est"] is None
    if method == "moreau":  # its one step
        assert r.dt_min == r.dt_max == r.dt == js["dt_min"]
    else:
        assert math.isnan(r.dt_min) and math.isnan(r.dt_max)


def test_fixed_step_scene_reports_no_tolerance(cli, same):
    r = pound.simulate_scene(THREE, history=False)
    same(r, cli("simulate", "--scene", THREE))
    assert (r.method, r.rtol, r.rtol_met, r.steps_rejected) == ("moreau", 0.0, True, 0)
    assert math.isnan(r.err_est) and all(math.isnan(st.err_est) for st in r.structures)
    assert r.dt_min == r.dt_max == r.dt


@pytest.mark.parametrize("case", [OSC, FIG9, REVERSE], ids=["Pi", "fig9", "reverse"])
@pytest.mark.parametrize("rtol", [1e-3, 1e-5, 1e-7])
def test_oscillator_tolerance_is_met(case, rtol):
    """err_est <= rtol when rtol_met, and the peaks are within rtol of the
    exact event-driven reference's."""
    r = pound.simulate(rtol=rtol, history=False, **case)
    ref = pound.simulate(method="event", history=False, **case)
    assert r.rtol == rtol and r.rtol_met is True
    assert 0.0 < r.err_est <= rtol
    assert abs(r.umax - ref.umax) <= rtol * ref.umax
    assert abs(r.umax_free - ref.umax_free) <= rtol * ref.umax_free
    assert 0.0 < r.dt_min <= r.dt_max and r.steps > 0 and r.steps_rejected >= 0


@pytest.mark.parametrize("scene", [TWO, THREE], ids=["two-sdof", "three-sdof"])
@pytest.mark.parametrize("rtol", [1e-3, 1e-5])
def test_scene_tolerance_is_met(scene, rtol):
    r = pound.simulate_scene(scene, rtol=rtol, history=False)
    ref = pound.simulate_scene(scene, method="event", history=False)
    assert r.rtol == rtol and r.rtol_met is True and 0.0 < r.err_est <= rtol
    for st, sr in zip(r.structures, ref.structures):
        assert 0.0 < st.err_est <= r.err_est
        assert np.max(np.abs(st.umax - sr.umax)) <= rtol * np.max(np.abs(sr.umax))


# ---- converge: Moreau-Jean to a tolerance as rows (moreau-rtol, rtols) ---------------------------

def test_converge_rows_to_a_tolerance_are_the_cli(cli, same):
    js = cli("converge", *OSC_ARGS, "--dt", "0.004:0.002:2", "--methods", "moreau-rtol",
             "--rtols", "1e-3,1e-5")
    c = pound.converge("0.004:0.002:2", methods="moreau-rtol", rtols=[1e-3, 1e-5], **OSC)
    same(c, js)
    assert [r.rtol for r in c.rows] == [1e-3, 1e-5] == [r["rtol"] for r in js["rows"]]
    assert [r.err_est for r in c.rows] == [r["err_est"] for r in js["rows"]]
    for r in c.rows:
        assert r.method == "moreau" and math.isnan(r.dt) and math.isnan(r.theta)
        assert 0.0 < r.err_est <= r.rtol and r.err_umax_rel <= r.rtol
    # the default rows: fixed steps, then to the tolerances 1e-2 ... 1e-6
    d = pound.converge("0.004:0.002:2", **OSC)
    same(d, cli("converge", *OSC_ARGS, "--dt", "0.004:0.002:2"))
    assert [r.rtol for r in d.rows[2:]] == [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
    assert math.isnan(d.rows[0].rtol) and math.isnan(d.rows[0].err_est)


def test_scene_converge_rows_to_a_tolerance_are_the_cli(cli, same):
    js = cli("converge", "--scene", TWO, "--dt", "0.0008:0.0004:2", "--rtols", "1e-3,1e-4")
    c = pound.converge("0.0008:0.0004:2", scene=TWO, rtols=(1e-3, 1e-4))
    same(c, js)
    assert [r.rtol for r in c.rows[2:]] == [1e-3, 1e-4]
    assert all(0.0 < r.err_est <= r.rtol for r in c.rows[2:])


def test_converge_rtols_refused():
    with pytest.raises(pound.InputError) as e:
        pound.converge("0.004:0.002:2", rtols=[1e-3, 0.0], **OSC)
    assert str(e.value) == "rtols: the tolerances must be in [1e-12, 1) (got 0)"
    with pytest.raises(pound.InputError) as e:
        pound.compare(methods="moreau-rtol", **OSC)  # converge's rows only, as the CLI's
    assert str(e.value).startswith("methods: 'moreau-rtol' is not one of moreau, penalty")
