"""The Python numbers are the CLI's to the last bit: every case is run both
ways and compared with == (the CLI prints %.17g, so doubles round-trip)."""
import numpy as np
import pytest

import pound
from conftest import EXAMPLES, RECORDS, read_csv

FIG9 = dict(pulse="sine", dir="normal", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
FIG9_ARGS = ["--pulse", "sine", "--dir", "normal", "--Tp", "0.3", "--T0", "3", "--ap", "4",
             "--gap", "0.004", "--eps", "0.6"]
CASE = dict(pulse="cosine", dir="reverse", Tp=0.5, Pi2=0.8, Pi3=0.1, eps=0.7, xi=0.02)
CASE_ARGS = ["--pulse", "cosine", "--dir", "reverse", "--Tp", "0.5", "--Pi2", "0.8", "--Pi3",
             "0.1", "--eps", "0.7", "--xi", "0.02"]
SCENE = EXAMPLES / "scenes" / "two-sdof.json"
LCP = EXAMPLES / "murty1978.lcp"


@pytest.mark.parametrize("method", ["moreau", "event", "penalty", "newmark"])
def test_simulate(cli, same, method):
    r = pound.simulate(method=method, history=False, **FIG9)
    same(r, cli("simulate", *FIG9_ARGS, "--method", method))


@pytest.mark.parametrize("method", ["moreau", "event", "penalty", "newmark"])
def test_simulate_history_is_the_cli_file(cli, same, method, tmp_path):
    """With a history the run has a sampler, as the CLI's with -o: the same
    figures and, column by column, the same file."""
    out = tmp_path / "run.csv"
    js = cli("simulate", *CASE_ARGS, "--method", method, "-o", out)
    r = pound.simulate(method=method, **CASE)
    same(r, js)
    header, data = read_csv(out)
    assert header == ["t", "u", "v", "impulse", "gap"]
    for k, name in enumerate(header):
        assert np.array_equal(r.history[name], data[:, k]), name


def test_simulate_every(cli, same, tmp_path):
    out = tmp_path / "run.csv"
    js = cli("simulate", *CASE_ARGS, "--every", "7", "-o", out)
    r = pound.simulate(every=7, **CASE)
    same(r, js)
    _, data = read_csv(out)
    assert np.array_equal(r.u, data[:, 1]) and np.array_equal(r.t, data[:, 0])


@pytest.mark.parametrize("extra,kw", [
    (["--pulse", "harmonic", "--Pi2", "1.3", "--Pi3", "0.2", "--tend", "12"],
     dict(pulse="harmonic", Pi2=1.3, Pi3=0.2, tend=12)),
    (["--theta", "0.7", "--dt", "0.002", "--kernel", "general", "--gamma", "0.3"],
     dict(theta=0.7, dt=0.002, kernel="general", gamma=0.3)),
    (["--method", "penalty", "--contact", "hertz", "--kc", "1e5", "--stepper", "rkf45"],
     dict(method="penalty", contact="hertz", kc=1e5, stepper="rkf45")),
    (["--method", "event", "--eps", "0", "--no-accumulation", "--Pi3", "0"],
     dict(method="event", eps=0, no_accumulation=True, Pi3=0)),
    (["--no-wall"], dict(no_wall=True)),
])
def test_simulate_flags(cli, same, extra, kw):
    same(pound.simulate(history=False, **kw), cli("simulate", *extra))


def test_compare(cli, same):
    same(pound.compare(**CASE), cli("compare", *CASE_ARGS))
    same(pound.compare(methods=("moreau", "penalty"), dt=0.001, **CASE),
         cli("compare", *CASE_ARGS, "--dt", "0.001", "--methods", "moreau,penalty"))


def test_converge(cli, same):
    js = cli("converge", *FIG9_ARGS, "--dt", "0.004:0.0005:4", "--theta", "0.5,0.75",
             "--methods", "moreau,penalty", "--kcs", "1e3,1e5")
    same(pound.converge("0.004:0.0005:4", theta=[0.5, 0.75], methods=("moreau", "penalty"),
                        kcs=[1e3, 1e5], **FIG9), js)
    same(pound.converge((0.004, 0.0005, 4), theta=[0.5, 0.75], methods="moreau,penalty",
                        kcs=[1e3, 1e5], **FIG9), js)
    same(pound.converge("0.01:0.00125:4", error="umax", **CASE),
         cli("converge", *CASE_ARGS, "--dt", "0.01:0.00125:4", "--error", "umax"))


def test_spectrum(cli, same):
    r = pound.spectrum(Pi2_range=(0.1, 3, 9), Pi3=[0.05, 0.5], eps=[0.3, 0.8],
                       pulse=["sine", "cosine"], dir=["normal", "reverse"], method="event")
    js = cli("spectrum", "--Pi2", "0.1:3:9", "--Pi3", "0.05,0.5", "--eps", "0.3,0.8", "--pulse",
             "sine,cosine", "--dir", "normal,reverse", "--method", "event")
    same(r.points, js["points"])
    assert r.runs == js["runs"] and r.twins == js["twins"]
    assert r.Pi1.shape == (js["curves"], 9)
    if hasattr(pound._lib.lib, "pd_spec_sweep"):  # the library's serial sweep, the same
        seen = []
        s = pound.spectrum(Pi2_range=(0.1, 3, 9), Pi3=[0.05, 0.5], eps=[0.3, 0.8],
                           pulse=["sine", "cosine"], dir=["normal", "reverse"], method="event",
                           threads=1, on_point=seen.append)
        same(s.points, js["points"])
        same(seen, js["points"])  # in order, as they complete


def test_spectrum_moreau_dimensional_linear(cli, same):
    r = pound.spectrum(Pi2="0.5:2:5", linear=True, ap=[1, 3], gap=[0.01], Tp=0.5, xi=[0, 0.05],
                       dt_per_Tp=400)
    js = cli("spectrum", "--Pi2", "0.5:2:5", "--linear", "--ap", "1,3", "--gap", "0.01",
             "--Tp", "0.5", "--xi", "0,0.05", "--dt-per-Tp", "400")
    same(r.points, js["points"])


def test_lcp(cli, same):
    M, q = pound.read_lcp(LCP)
    same(pound.lcp(M, q), cli("lcp", LCP))
    for solver in ("lemke", "structured", "pgs"):
        same(pound.lcp(M, q, solver=solver), cli("lcp", LCP, "--solver", solver))


@pytest.mark.parametrize("method", ["moreau", "event", "penalty"])
def test_scene(cli, same, method):
    same(pound.simulate_scene(SCENE, method=method, history=False),
         cli("simulate", "--scene", SCENE, "--method", method))


def test_scene_history_is_the_cli_file(cli, same, tmp_path):
    out = tmp_path / "scene.csv"
    js = cli("simulate", "--scene", SCENE, "-o", out, "--every", "3")
    r = pound.simulate_scene(SCENE, every=3)
    same(r, js)
    header, data = read_csv(out)
    assert header == ["t", "stiff.x1", "flexible.x1", "stiff.v1", "flexible.v1", "c0.gap",
                      "c0.impulse", "stiff.a1", "flexible.a1"]
    cols = np.column_stack([r.t, r.x, r.v, r.history.gap, r.history.impulse, r.history.a])
    assert np.array_equal(cols, data)
    assert list(r.history.dof) == ["stiff.1", "flexible.1"]
    assert list(r.history.contact) == ["stiff-flexible@1"]


@pytest.mark.parametrize("method", ["penalty", "newmark"])
def test_scene_forces_are_the_cli_file(cli, same, tmp_path, method):
    """The penalty methods' element forces (cK.force) and the floors'
    accelerations, column for column; their peaks force_max and acc_max."""
    out = tmp_path / "scene.csv"
    js = cli("simulate", "--scene", SCENE, "--method", method, "-o", out, "--every", "2")
    r = pound.simulate_scene(SCENE, method=method, every=2)
    same(r, js)
    header, data = read_csv(out)
    assert header[-3:] == ["stiff.a1", "flexible.a1", "c0.force"]
    cols = np.column_stack([r.t, r.x, r.v, r.history.gap, r.history.impulse, r.history.a,
                            r.history.force])
    assert np.array_equal(cols, data)
    assert np.max(r.history.force[:, 0]) <= r.contacts[0].force_max * (1 + 1e-15)


@pytest.mark.parametrize("method", ["moreau", "event"])
def test_scene_yielding_history_is_the_cli_file(cli, same, tmp_path, method):
    """A yielding row's history (the storeys' offsets up after the impulses, as
    the CLI's NAME.upK columns); its last row's (1 - alpha) up is the residual."""
    out = tmp_path / "yrow.csv"
    args = ("--chain", "3", "--Pi3", "0.3", "--Piy", "0.1", "--alpha", "0.1", "--method", method)
    js = cli("simulate", *args, "-o", out, "--every", "4")
    r = pound.Scene.chain(3, Pi3=0.3, Piy=0.1, alpha=0.1).simulate(method=method, every=4)
    same(r, js)
    header, data = read_csv(out)
    assert header[-6:] == ["S1.up1", "S2.up1", "S3.up1", "S1.a1", "S2.a1", "S3.a1"]
    cols = np.column_stack([r.t, r.x, r.v, r.history.gap, r.history.impulse, r.history.up,
                            r.history.a])
    assert np.array_equal(cols, data)
    for k, st in enumerate(r.structures):  # the offsets at the end give the residuals
        assert st.n_yield[0] > 0 and np.isclose(0.9 * r.history.up[-1, k], st.residual[0],
                                                rtol=1e-12, atol=0)


def test_scene_others(cli, same):
    for name in ("three-buildings.json", "oscillator.json"):
        f = EXAMPLES / "scenes" / name
        same(pound.simulate_scene(f, history=False), cli("simulate", "--scene", f))
    same(pound.Scene.chain(5, Pi3=0.02, eps=0.4, pulse="harmonic").simulate(
        history=False, tend=3), cli("simulate", "--chain", "5", "--Pi3", "0.02", "--eps",
                                    "0.4", "--pulse", "harmonic", "--tend", "3"))


def test_scene_compare_converge(cli, same):
    same(pound.compare(scene=SCENE, methods="moreau,penalty"),
         cli("compare", "--scene", SCENE, "--methods", "moreau,penalty"))
    same(pound.converge("0.0008:0.0002:3", scene=SCENE),
         cli("converge", "--scene", SCENE, "--dt", "0.0008:0.0002:3"))
    # the GSL-based reference measured against the exact row reference
    # the penalty elements on Newmark's fixed steps, per dt like Moreau-Jean
    same(pound.compare(scene=SCENE, methods="moreau,newmark"),
         cli("compare", "--scene", SCENE, "--methods", "moreau,newmark"))
    same(pound.converge("0.0008:0.0004:2", scene=SCENE, methods="moreau,newmark"),
         cli("converge", "--scene", SCENE, "--dt", "0.0008:0.0004:2", "--methods",
             "moreau,newmark"))
    same(pound.compare(scene=SCENE, methods="moreau,event-general"),
         cli("compare", "--scene", SCENE, "--methods", "moreau,event-general"))
    same(pound.converge("0.0008:0.0004:2", scene=SCENE, methods="moreau,event-general",
                        error="umax"),
         cli("converge", "--scene", SCENE, "--dt", "0.0008:0.0004:2", "--methods",
             "moreau,event-general", "--error", "umax"))


RECORD = EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2"  # shipped (examples/records)


@pytest.mark.skipif(not RECORD.exists(), reason="no records in %s" % RECORDS)
def test_record(cli, same):
    js = cli("record", RECORD)["records"][0]
    same(pound.record(RECORD), js)
    kw = dict(record=RECORD, T0=0.8, gap=0.01, eps=0.6)
    args = ["--record", RECORD, "--T0", "0.8", "--gap", "0.01", "--eps", "0.6"]
    same(pound.simulate(method="event", history=False, **kw),
         cli("simulate", *args, "--method", "event"))
    same(pound.simulate(history=False, scale=0.5, dir="reverse", **kw),
         cli("simulate", *args, "--scale", "0.5", "--dir", "reverse"))
    r = pound.spectrum(Pi2_range=(0.2, 2, 4), record=RECORD, Pi3=[0.05], method="event")
    js = cli("spectrum", "--Pi2", "0.2:2:4", "--record", RECORD, "--Pi3", "0.05", "--method",
             "event")
    same(r.points, js["points"])


@pytest.mark.skipif(not RECORDS.is_dir(), reason="no records in %s" % RECORDS)
def test_every_record(cli, same):
    files = sorted(p for p in RECORDS.iterdir()
                   if p.suffix.lower() in (".at2", ".v2") and p.stat().st_size < 5e6)[:8]
    if not files:
        pytest.skip("no AT2 records")
    js = cli("record", *files)["records"]
    for f, j in zip(files, js):
        same(pound.record(f), j)


@pytest.mark.parametrize("extra,kw", [
    (["--uy", "0.003", "--alpha", "0.05", "--ap", "2", "--Tp", "0.5"],
     dict(uy=0.003, alpha=0.05, ap=2, Tp=0.5)),
    (["--Piy", "0.3", "--Pi3", "10", "--xi", "0"], dict(Piy=0.3, Pi3=10, xi=0)),
])
def test_simulate_yielding(cli, same, tmp_path, extra, kw):
    """A yielding oscillator: the CLI's figures (ductility, residual, the
    energy balance) and its history file, to the bit."""
    out = tmp_path / "run.csv"
    js = cli("simulate", *extra, "-o", out)
    r = pound.simulate(**kw)
    assert "ductility" in js and "energy_residual" in js
    same(r, js)
    header, data = read_csv(out)
    assert header == ["t", "u", "v", "impulse", "gap", "up", "spring_force"]
    assert np.array_equal(r.u, data[:, 1]) and np.array_equal(r.history["up"], data[:, 5])
    assert "up" not in pound.simulate(every=50).history  # an elastic run's history has none


@pytest.mark.parametrize("method", ["newmark", "event"])
def test_simulate_yielding_methods(cli, same, method):
    """A yielding oscillator by newmark (Newton's failures reported, 0 here)
    and by the exact reference (its energy balance), as the CLI's."""
    js = cli("simulate", "--Piy", "0.2", "--alpha", "0.1", "--Pi3", "0.1", "--method", method)
    r = pound.simulate(Piy=0.2, alpha=0.1, Pi3=0.1, method=method, history=False)
    same(r, js)
    assert js["newton_failures"] == 0 and r.newton_failures == 0
    if method == "event":  # the exact reference's balance closes to rounding
        assert abs(r.energy_residual) < 1e-12


@pytest.mark.parametrize("method", ["moreau", "newmark", "event"])
def test_scene_yielding(cli, same, method):
    """A scene with yielding storeys: per storey ductility, residual,
    plastic excursion and onsets, as the CLI's; an elastic storey's NaN;
    every method's energy balance (the exact reference's too); the methods
    without yielding refuse naming uy."""
    f = EXAMPLES / "scenes" / "yielding-buildings.json"
    r = pound.simulate_scene(f, method=method, history=False)
    same(r, cli("simulate", "--scene", f, "--method", method))
    soft = r.structures[0]
    assert soft.ductility[0] > 1.5 and soft.n_yield[0] > 0 and soft.residual[1] == 0.0
    # the midpoint's identity summed (newmark's to its Newton tolerance), the
    # exact reference's integrals
    assert abs(r.energy_residual) < (1e-10 if method == "newmark" else 1e-12)
    with pytest.raises(pound.InputError, match="uy"):
        pound.simulate_scene(f, method="penalty", history=False)


@pytest.mark.parametrize("method", ["moreau", "event"])
def test_chain_yielding(cli, same, method):
    """A generated row whose every SDOF yields, as `--chain N --Piy X --alpha A`
    (by Moreau-Jean, and exactly by the row reference)."""
    r = pound.Scene.chain(6, Pi3=0.05, Piy=0.3, alpha=0.05).simulate(history=False, method=method)
    same(r, cli("simulate", "--chain", "6", "--Pi3", "0.05", "--Piy", "0.3", "--alpha", "0.05",
                "--method", method))
    mu = [st.ductility[0] for st in r.structures]
    assert max(mu) > 1.0 and all(m > 0.0 for m in mu)  # the row's ends yield (the middle may not)
    if method == "event":  # Moreau-Jean's default dt within a few per cent of the exact row
        mj = pound.Scene.chain(6, Pi3=0.05, Piy=0.3, alpha=0.05).simulate(history=False)
        mu_mj = [st.ductility[0] for st in mj.structures]
        assert np.allclose(mu, mu_mj, rtol=5e-2)


@pytest.mark.parametrize("kw,named", [
    (dict(Piy=-1), "Piy"), (dict(uy=0.01, Piy=1), "alternatives"), (dict(alpha=0.2), "uy or Piy"),
    (dict(Piy=1, alpha=0.002, method="event"), "moreau"), (dict(Piy=1, rtol=1e-3), "tolerance"),
])
def test_simulate_yielding_refused(kw, named):
    with pytest.raises(pound.InputError, match=named):
        pound.simulate(history=False, **kw)


def test_spectrum_yielding(cli, same):
    """A yielding sweep: the CLI's points (ductility, residual_uy, the
    spring's Piy, alpha, uy) and arrays, uy in metres as the CLI's --uy."""
    r = pound.spectrum(Pi2_range=(0.5, 3, 5), Pi3=[0.05, 0.3], uy=0.01, alpha=0.05)
    js = cli("spectrum", "--Pi2", "0.5:3:5", "--Pi3", "0.05,0.3", "--uy", "0.01", "--alpha",
             "0.05")
    same(r.points, js["points"])
    assert js["method"] == "event" and r.ductility.shape == (2, 5)  # xi^2 < alpha: exact
    assert list(r.ductility.ravel()) == [p["ductility"] for p in js["points"]]
