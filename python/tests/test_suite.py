"""Suites of records from the command line (`--records FILE`, `--record`
repeated): each record's entry is the single run of that record to the last
bit, the statistics are NumPy's, one thread gives what two give, and the
targets scale each record to them."""
import json
import subprocess

import numpy as np
import pytest

from conftest import EXAMPLES, TIMING_KEYS, pound_bin

SUITE = EXAMPLES / "records" / "suite" / "suite.txt"
RECS = [SUITE.parent / line.split()[0] for line in SUITE.read_text().splitlines()
        if line.strip() and not line.startswith("#")]
OSC = ["--T0", "0.8", "--gap", "0.01", "--eps", "0.6"]
SCENE = EXAMPLES / "scenes" / "two-sdof.json"


def untimed(x):
    """x without its timings (they differ from run to run)."""
    if isinstance(x, dict):
        return {k: untimed(v) for k, v in x.items() if k not in TIMING_KEYS}
    if isinstance(x, list):
        return [untimed(v) for v in x]
    return x


def run(*args, status=0):
    out = subprocess.run([str(pound_bin())] + [str(a) for a in args], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, check=False)
    assert out.returncode == status, out.stderr.decode()
    return out


def test_shipped_suite_has_seven_records():
    assert len(RECS) == 7 and all(p.exists() for p in RECS)


@pytest.mark.parametrize("where", ["oscillator", "scene"])
def test_records_are_single_runs(cli, where):
    """records[k] is what the single run of record k prints, bit for bit."""
    flags = OSC if where == "oscillator" else ["--scene", SCENE]
    js = cli("simulate", "--records", SUITE, *flags)
    assert js["n"] == 7 and len(js["records"]) == 7
    for rec, path in zip(js["records"], RECS):
        single = cli("simulate", "--record", path, *flags)
        assert untimed(rec) == untimed(single), path.name


def test_scene_record_is_the_scene_files_record(cli, tmp_path):
    """A suite's record on a scene equals the scene file that names it."""
    scene = json.loads(SCENE.read_text())
    scene["excitation"] = {"record": str(RECS[2]), "units": "g"}
    scene.pop("tend", None)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    js = cli("simulate", "--scene", SCENE, "--records", SUITE)
    single = cli("simulate", "--scene", path)
    assert untimed(js["records"][2]) == untimed(single)


def stats_ok(stats, values):
    x = np.asarray(values, dtype=float)
    want = dict(n=len(x), mean=np.mean(x), median=np.median(x), p16=np.percentile(x, 16),
                p84=np.percentile(x, 84), min=np.min(x), max=np.max(x))
    for key, w in want.items():
        assert stats[key] == pytest.approx(w, rel=1e-14, abs=1e-300), key


def test_oscillator_stats_are_numpys(cli):
    js = cli("simulate", "--records", SUITE, *OSC)
    for key in ["umax", "Pi1", "gamma", "impacts", "max_impulse", "acc_max", "shear_max",
                "u_toward", "u_away", "umax_free", "max_impact_velocity", "contact_time",
                "force_equiv"]:
        stats_ok(js["stats"][key], [r[key] for r in js["records"]])
    # an impulsive method has no contact force: no finite value, n 0
    assert js["stats"]["force_max"]["n"] == 0 and js["stats"]["force_max"]["mean"] is None
    stats_ok(js["stats"]["drift_ratio"], [r["drift_ratio"] for r in js["records"]])


def test_scene_stats_are_numpys(cli):
    js = cli("simulate", "--records", SUITE, "--scene", EXAMPLES / "scenes" /
             "three-buildings.json", "--method", "event")
    for s, st in enumerate(js["stats"]["structures"]):
        stats_ok(st["umax"], [max(r["structures"][s]["umax"]) for r in js["records"]])
        stats_ok(st["acc_max"], [max(r["structures"][s]["acc_max"]) for r in js["records"]])
        stats_ok(st["shear_max"], [r["structures"][s]["shear_max"][0] for r in js["records"]])
        # each storey's own (pd_scene_suite_stats' per-dof statistics)
        assert [x["storey"] for x in st["storeys"]] == \
            list(range(1, len(js["records"][0]["structures"][s]["umax"]) + 1))
        for i, one in enumerate(st["storeys"]):
            for key in ["umax", "drift_ratio", "acc_max", "shear_max", "gamma", "umax_free"]:
                stats_ok(one[key], [r["structures"][s][key][i] for r in js["records"]])
    for c, ct in enumerate(js["stats"]["contacts"]):
        req = [r["contacts"][c]["required_gap"] for r in js["records"]]
        stats_ok(ct["required_gap"], req)
        for key in ["max_impulse", "contact_time", "force_equiv"]:
            stats_ok(ct[key], [r["contacts"][c][key] for r in js["records"]])
        hits = [r["contacts"][c]["impacts"] > 0 for r in js["records"]]
        assert ct["closed"] == pytest.approx(np.mean(hits), abs=1e-15)
        for rule in ["abs", "srss", "ddc"]:
            ruled = [r["contacts"][c]["rules"][rule] for r in js["records"]]
            stats_ok(ct["rules"][rule], ruled)
            over = np.mean([q > g * (1 + 1e-9) for q, g in zip(req, ruled)])
            assert ct["rule_closed"][rule] == pytest.approx(over, abs=1e-15)


def test_penalty_scene_stats_have_forces(cli):
    """A penalty suite: each contact's peak force as NumPy's."""
    js = cli("simulate", "--records", SUITE, "--scene", SCENE, "--method", "penalty")
    for c, ct in enumerate(js["stats"]["contacts"]):
        stats_ok(ct["force_max"], [r["contacts"][c]["force_max"] for r in js["records"]])
        assert ct["force_max"]["n"] == 7


def test_yielding_scene_stats_have_ductility(cli):
    """A yielding scene's suite: each structure's and storey's ductility
    (the largest storey's, NaN storeys passed over) as NumPy's."""
    js = cli("simulate", "--records", SUITE, "--scene", EXAMPLES / "scenes" /
             "yielding-buildings.json", "--target-pga", "3", "--tend", "6")
    for s, st in enumerate(js["stats"]["structures"]):
        duct = [[np.nan if d is None else d for d in r["structures"][s]["ductility"]]
                for r in js["records"]]
        stats_ok(st["ductility"], [np.nanmax(d) for d in duct])
        for i, one in enumerate(st["storeys"]):
            stats_ok(one["ductility"], [d[i] for d in duct])


def test_one_thread_is_two(cli):
    one = cli("simulate", "--records", SUITE, "--scene", SCENE, "--threads", "1")
    two = cli("simulate", "--records", SUITE, "--scene", SCENE, "--threads", "2")
    assert untimed(one) == untimed(two)


def test_targets_reach_their_values(cli):
    meas = cli("record", "--records", SUITE, "--sa", "0.8")["records"]
    pga = cli("simulate", "--records", SUITE, *OSC, "--target-pga", "3")
    sa = cli("simulate", "--records", SUITE, *OSC, "--target-sa", "5")  # T1 = T0
    for m, a, b in zip(meas, pga["records"], sa["records"]):
        assert a["scale"] * m["pga"] == pytest.approx(3.0, rel=1e-13)
        assert b["scale"] * m["sa"] == pytest.approx(5.0, rel=1e-13)


@pytest.mark.parametrize("where,ext", [("oscillator", "csv"), ("scene", "h5")])
def test_suite_files_are_single_runs(tmp_path, where, ext):
    """-o FILE.EXT with a suite: FILE.recK.EXT holds record K's histories,
    the single run's to the bit (the provenance line and timings aside)."""
    h5py = pytest.importorskip("h5py") if ext == "h5" else None
    flags = OSC if where == "oscillator" else ["--scene", SCENE]
    run("simulate", "--record", RECS[0], "--record", RECS[1], *flags, "-o",
        tmp_path / ("s." + ext), "--json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.rec1." + ext, "s.rec2." + ext]
    run("simulate", "--record", RECS[1], *flags, "-o", tmp_path / ("one." + ext), "--json")
    a, b = tmp_path / ("s.rec2." + ext), tmp_path / ("one." + ext)
    if ext == "csv":
        keep = lambda p: [ln for ln in p.read_text().splitlines()  # noqa: E731
                          if not ln.startswith(("# command", "# created", "# cpu_s"))]
        assert keep(a) == keep(b)
    else:
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            names = []
            fa.visit(names.append)
            for name in names:
                if isinstance(fa[name], h5py.Dataset):
                    assert np.array_equal(fa[name][()], fb[name][()]), name


def test_failed_suite_leaves_no_files(tmp_path):
    """A record whose run fails after an earlier record's files were
    written (its impacts' equivalent force overflows at td 1e-306; the
    first record, scaled down, has none) leaves none of the suite's files."""
    suite = tmp_path / "two.txt"
    suite.write_text("%s 0.001\n%s 200\n" % (RECS[0], RECS[1]))
    out = run("simulate", "--records", suite, *OSC, "--contact-duration", "1e-306", "-o",
              tmp_path / "s.csv", "--plot", tmp_path / "s.png", status=2)
    assert "nf2.txt" in out.stderr.decode() and "overflows" in out.stderr.decode()
    assert not list(tmp_path.glob("s.*"))


def journal_lines(path):
    return [ln for ln in path.read_text().splitlines() if ln.startswith("R ")]


RESUMED = {"scene": ["--scene", EXAMPLES / "scenes" / "three-buildings.json"],
           "yielding": ["--scene", EXAMPLES / "scenes" / "yielding-buildings.json"],
           "rtol": ["--scene", SCENE, "--method", "moreau", "--rtol", "1e-3"]}


@pytest.mark.parametrize("where,json_out", [("oscillator", False), ("oscillator", True),
                                           ("scene", True), ("yielding", True), ("rtol", True)])
def test_resumed_suite_is_uninterrupted(tmp_path, where, json_out):
    """--journal F --stop-after 3 dies (130) with three records in F; the
    same command with --resume prints what the uninterrupted suite prints
    (the records read back to the bit) and removes F; a torn last line and
    a line whose checksum fails are run again."""
    flags = OSC if where == "oscillator" else RESUMED[where]
    flags = ["--records", SUITE, *flags] + (["--json"] if json_out else [])
    full = run("simulate", *flags).stdout.decode()
    journal = tmp_path / "j.txt"
    out = run("simulate", *flags, "--journal", journal, "--stop-after", "3", status=130)
    assert not out.stdout and len(journal_lines(journal)) == 3
    lines = journal.read_text().splitlines(keepends=True)
    # a record whose checksum fails (a changed figure): run again
    lines[-1] = lines[-1][:12] + ("1" if lines[-1][12] != "1" else "2") + lines[-1][13:]
    journal.write_text("".join(lines) + "R 6 " + ("O 00" if where == "oscillator" else "S 1"))
    resumed = run("simulate", *flags, "--journal", journal, "--resume").stdout.decode()
    if json_out:
        assert untimed(json.loads(full)) == untimed(json.loads(resumed))
    else:
        assert full == resumed
    assert not journal.exists()


def fnv1a(data):
    h = 2166136261
    for b in data:
        h = ((h ^ b) * 16777619) & 0xFFFFFFFF
    return h


@pytest.mark.parametrize("name", ["=%1", "=%", "=%e!", "=%00", "=%4", "-x"])
def test_forged_journal_lines_are_refused(tmp_path, name):
    """A line whose checksum is right (forged) but whose names are not
    escaped as the writer escapes them (a lone %, one hex digit, NUL) is
    dropped and its record run again (ASan: the reader stays in bounds);
    a well-escaped name is read back (the forged kernel shows)."""
    journal = tmp_path / "j.txt"
    flags = ["--records", SUITE, *OSC, "--json"]
    full = json.loads(run("simulate", *flags).stdout.decode())
    run("simulate", *flags, "--journal", journal, "--stop-after", "2", status=130)
    first = journal.read_bytes().split(b"\n")[2]  # after the magic and the key
    fields = first.rsplit(b" #", 1)[0].split(b" ")  # R k O hex kernel kernel
    assert fields[0] == b"R" and fields[2] == b"O" and len(fields) == 6
    fields[1], fields[4] = b"2", name.encode()
    forged = b" ".join(fields)
    journal.write_bytes(journal.read_bytes() + forged + b" #%08x\n" % fnv1a(forged))
    out = json.loads(run("simulate", *flags, "--journal", journal, "--resume").stdout.decode())
    assert untimed(out) == untimed(full)
    if name == "=%4":  # the same line well escaped: read back, its name shown
        fields[4] = b"=%41%41"
        forged = b" ".join(fields)
        run("simulate", *flags, "--journal", journal, "--stop-after", "2", status=130)
        journal.write_bytes(journal.read_bytes() + forged + b" #%08x\n" % fnv1a(forged))
        out = json.loads(run("simulate", *flags, "--journal", journal,
                             "--resume").stdout.decode())
        assert out["records"][2]["kernel"] == "AA"


def test_journal_refusals(tmp_path):
    journal = tmp_path / "j.txt"
    run("simulate", "--records", SUITE, *OSC, "--journal", journal, "--stop-after", "1",
        status=130)
    cases = [
        (["--records", SUITE, *OSC, "--journal", journal], "exists: an interrupted suite"),
        (["--records", SUITE, "--T0", "0.9", "--gap", "0.01", "--eps", "0.6", "--journal",
          journal, "--resume"], "different suite (--T0 differs)"),
        ([*OSC, "--resume"], "--resume needs --journal"),
        ([*OSC, "--journal", tmp_path / "k.txt"], "the journal of a suite"),
    ]
    for args, says in cases:
        err = run("simulate", *args, status=2).stderr.decode()
        assert says in err and err.count("\n") == 1, err
    assert len(journal_lines(journal)) == 1  # the refusals left it as it was


def test_mpi_suite_is_serial(tmp_path):
    """mpirun -np 2 of the MPI build (POUND_MPI, default build-mpi/pound)
    prints the serial suite; with a journal, the ranks' records are in it."""
    import os
    import shutil
    mpi = os.environ.get("POUND_MPI", str(pound_bin().parent.parent / "build-mpi" / "pound"))
    if not os.path.exists(mpi) or not shutil.which("mpirun"):
        pytest.skip("no MPI build (make MPI=1) or no mpirun")
    flags = ["simulate", "--records", str(SUITE), "--scene", str(SCENE), "--json"]
    serial = json.loads(run(*flags).stdout.decode())
    journal = tmp_path / "j.txt"
    out = subprocess.run(["mpirun", "-np", "2", "--allow-run-as-root", "--oversubscribe", mpi,
                          *flags, "--journal", str(journal), "--stop-after", "2"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=False)
    assert out.returncode != 0 and len(journal_lines(journal)) >= 2
    out = subprocess.run(["mpirun", "-np", "2", "--allow-run-as-root", "--oversubscribe", mpi,
                          *flags, "--journal", str(journal), "--resume"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=False)
    assert out.returncode == 0, out.stderr.decode()
    assert untimed(json.loads(out.stdout.decode())) == untimed(serial)
    assert not journal.exists()


def test_record_repeated_is_a_suite(cli):
    js = cli("simulate", "--record", RECS[0], "--record", RECS[1], *OSC)
    assert [r["record"] for r in js["records"]] == ["nf1.txt", "nf2.txt"]


@pytest.mark.parametrize("args,says", [
    (["--records", "/nonexistent/suite.txt"], "cannot open the suite file"),
    (["--records", SUITE, "--record", RECS[0]], "give the suite one way"),
    (["--records", SUITE, "--target-sa", "3", "--Pi2", "1"], "--T1"),
    (["--records", SUITE, "--target-pga", "3", "--scale", "2"], "--scale and --target-pga"),
    (["--target-pga", "3"], "scales records"),
    (["--records", SUITE, "--T1", "1"], "--T1: the period of --target-sa"),
    (["--records", SUITE, "--dump-lcp", "x.h5", "--method", "moreau"], "not of a suite"),
    (["--record", "%s,%s" % (RECS[0], RECS[1]), *OSC], "given once per record"),
])
def test_bad_suites_are_refused(args, says):
    out = run("simulate", *args, status=2)
    err = out.stderr.decode()
    assert says in err and err.count("\n") == 1 and not out.stdout, err


def test_suite_file_errors_name_the_line(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("%s\n%s 0\n" % (RECS[0], RECS[1]))
    err = run("simulate", "--records", bad, *OSC, status=2).stderr.decode()
    assert "bad.txt:2" in err and "scale" in err


def test_synth_suite_is_the_shipped_one(tmp_path):
    """`pound record --synth-suite DIR` writes the shipped files byte for byte."""
    run("record", "--synth-suite", tmp_path)
    for p in RECS + [SUITE]:
        assert (tmp_path / p.name).read_bytes() == p.read_bytes(), p.name


SPEC = ["--Pi2", "0.2:5:12", "--Pi3", "0.05,0.3", "--eps", "0.6"]


def test_spectrum_records_are_single_spectra(cli):
    """Each record's spectrum in a suite's is the single sweep of that record."""
    js = cli("spectrum", "--records", SUITE, *SPEC)
    assert js["n"] == 7 and js["axis"] == "Pi2"
    for rec, path in zip(js["records"], RECS):
        single = cli("spectrum", "--record", path, *SPEC)
        assert untimed(rec["points"]) == untimed(single["points"]), path.name


def test_spectrum_stats_are_numpys(cli):
    js = cli("spectrum", "--records", SUITE, *SPEC, "--threads", "1")
    for p, st in enumerate(js["stats"]):
        for key in ("Pi1", "gamma", "umax"):
            stats_ok(st[key], [r["points"][p][key] for r in js["records"]])
    two = cli("spectrum", "--records", SUITE, *SPEC, "--threads", "2")
    assert untimed(two["stats"]) == untimed(js["stats"])
    assert untimed(two["records"]) == untimed(js["records"])


def test_spectrum_against_periods(cli):
    """--T0 MIN:MAX:N: every record on the same periods (Pi2 = its Tp / T0),
    the gap in metres; the statistics of umax at each period."""
    js = cli("spectrum", "--records", SUITE, "--T0", "0.2:2:8", "--gap", "0.01", "--eps", "0.6")
    assert js["axis"] == "T0"
    T0 = np.array([[p["T0"] for p in r["points"]] for r in js["records"]])
    assert np.all(np.abs(T0 - T0[0]) <= 1e-13 * T0[0])
    assert np.allclose(T0[0], np.geomspace(2, 0.2, 8), rtol=1e-13) or \
        np.allclose(T0[0], np.geomspace(0.2, 2, 8), rtol=1e-13)
    for r in js["records"]:
        assert all(p["gap"] == pytest.approx(0.01, rel=1e-12) for p in r["points"])
    for p, st in enumerate(js["stats"]):
        stats_ok(st["umax"], [r["points"][p]["umax"] for r in js["records"]])


def test_spectrum_suite_resumes(tmp_path):
    """A suite's spectra killed inside its first record (--stop-after, 130)
    leave FILE.rec1.partial; --resume writes the uninterrupted file byte for
    byte and removes the journals."""
    grid = ["--records", SUITE, "--Pi2", "0.1:5:12", "--Pi3", "0.05", "--eps", "0.5"]
    run("spectrum", *grid, "-o", tmp_path / "full.h5")
    run("spectrum", *grid, "-o", tmp_path / "r.h5", "--stop-after", "20", status=130)
    assert (tmp_path / "r.h5.rec1.partial").exists() and not (tmp_path / "r.h5").exists()
    run("spectrum", *grid, "-o", tmp_path / "r.h5", "--resume")
    assert (tmp_path / "r.h5").read_bytes() == (tmp_path / "full.h5").read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full.h5", "r.h5"]


def test_spectrum_suite_bad_record_leaves_no_journals(tmp_path):
    """A suite whose second record fails as bad input (its impacts'
    equivalent force overflows at td 1e-306; the first, scaled down, has
    none) exits 2 and leaves neither the file nor any record's journal."""
    suite = tmp_path / "two.txt"
    suite.write_text("%s 0.001\n%s 200\n" % (RECS[0], RECS[1]))
    out = run("spectrum", "--records", suite, "--Pi2", "0.5:2:3", "--Pi3", "0.05", "--eps",
              "0.5", "--contact-duration", "1e-306", "-o", tmp_path / "s.h5", status=2)
    assert "nf2.txt" in out.stderr.decode()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["two.txt"]


@pytest.mark.parametrize("axis", [["--T0", "0.2:2:6"], ["--Pi2", "0.2:5:6"]])
def test_spectrum_suite_charts(tmp_path, axis):
    """--plot with a suite: Pi1, gamma and umax charts (each record faint,
    the mean) against T0 or Pi2."""
    import shutil
    if not shutil.which("gnuplot"):
        pytest.skip("no gnuplot")
    png = tmp_path / "s.png"
    run("spectrum", "--records", SUITE, *axis, "--gap", "0.01", "--eps", "0.6", "--plot", png)
    for name in ["s.png", "s-gamma.png", "s-dim.png"]:
        data = (tmp_path / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000, name


@pytest.mark.parametrize("args,says", [
    (["--T0", "0.2:2:8", "--Pi3", "0.05"], "the axis of a suite's spectrum"),
    (["--records", SUITE, "--scene", SCENE, "--Pi2", "0.5:2:4"], "a scene's suite"),
])
def test_bad_spectrum_suites(args, says):
    args = list(args) + ([] if "--Pi2" in args or "--T0" in args else ["--Pi2", "0.5:2:4"])
    out = run("spectrum", *args, status=2)
    err = out.stderr.decode()
    assert says in err and err.count("\n") == 1, err


def test_python_suite_is_the_clis(cli, same):
    """pound.simulate(records=[...]) gives the CLI's suite JSON to the bit:
    every record's run and the statistics (pd_stats_of, the CLI's)."""
    import pound
    args = []
    for p in RECS:
        args += ["--record", p]
    js = cli("simulate", *args, *OSC, "--target-sa", "6")
    r = pound.simulate(records=RECS, T0=0.8, gap=0.01, eps=0.6, target_sa=6, history=False)
    same(r, js)
    assert "suite" not in r and "suite" not in js and r.target == "sa"
    # arrays as records: the library's m/s^2 unless units say otherwise
    arrays = [pound.record(p).acc for p in RECS[:2]]
    dt = pound.record(RECS[0]).dt
    ra = pound.simulate(records=arrays, record_dt=dt, T0=0.8, gap=0.01, eps=0.6, history=False)
    rp = pound.simulate(records=RECS[:2], T0=0.8, gap=0.01, eps=0.6, history=False)
    assert [x.umax for x in ra.records] == [x.umax for x in rp.records]


@pytest.mark.parametrize("kw,says", [
    (dict(records=str(RECS[0])), "a list of record files"),
    (dict(records=RECS, record=RECS[0]), "give the suite one way"),
    (dict(records=RECS, target_pga=3, target_sa=3), "one target"),
    (dict(records=RECS, target_sa=3, Pi2=1), "T1"),
    (dict(records=RECS, target_pga=3, scale=2), "scale and target_pga"),
])
def test_python_suite_refusals(kw, says):
    import pound
    with pytest.raises(pound.InputError, match=says):
        pound.simulate(history=False, **kw)


def test_python_scene_suite_is_the_clis(cli, same):
    """Scene.simulate_records gives the CLI's scene suite JSON to the bit; the
    scene's own excitation is back afterwards."""
    import pound
    scene = EXAMPLES / "scenes" / "three-buildings.json"
    args = []
    for p in RECS[:3]:
        args += ["--record", p]
    js = cli("simulate", "--scene", scene, *args, "--method", "event", "--target-pga", "4")
    with pound.Scene(scene) as sc:
        before = sc.simulate(method="event", history=False)
        r = sc.simulate_records(RECS[:3], method="event", target_pga=4)
        after = sc.simulate(method="event", history=False)
    same(r, js)
    assert after.pulse == before.pulse and after.structures[1].umax.tolist() == \
        before.structures[1].umax.tolist()
