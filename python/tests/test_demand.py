"""The demand parameters (docs/scenes.md, "Demands") from Python equal the
CLI's JSON to the bit, for every method, scenes and the oscillator; the
options that set them are checked as the CLI checks its flags."""
import json
import math

import numpy as np
import pytest

import pound
from conftest import EXAMPLES

SCENE = EXAMPLES / "scenes" / "three-buildings.json"
METHODS = ["moreau", "event", "penalty", "newmark", "event-general"]
STRUCT_KEYS = ("storey_heights", "drift_ratio", "acc_max", "shear_max", "base_shear_max")
CONTACT_KEYS = ("force_equiv", "force_max")
OSC_KEYS = ("height", "drift_ratio", "acc_max", "shear_max", "force_equiv", "force_max",
            "contact_duration")


def floats(x):
    """A number or a list of them as floats, null (JSON) as NaN."""
    if isinstance(x, list):
        return np.array([np.nan if v is None else v for v in x], float)
    return np.asarray(np.nan if x is None else x, float)


def equal(a, b):
    """== on doubles (NaN equals NaN)."""
    return np.array_equal(floats(a), floats(b), equal_nan=True)


@pytest.mark.parametrize("method", METHODS)
def test_scene_demands_are_the_cli(cli, method):
    js = cli("simulate", "--scene", SCENE, "--method", method, "--contact-duration", "0.01")
    r = pound.simulate_scene(str(SCENE), history=False, method=method, contact_duration=0.01)
    assert r.contact_duration == js["contact_duration"] == 0.01
    for sp, sj in zip(r.structures, js["structures"]):
        for key in STRUCT_KEYS:
            assert equal(sp[key], sj[key]), (method, sp.name, key)
        assert np.all(sp.acc_max > 0) and np.all(sp.shear_max > 0)
        assert sp.base_shear_max == sp.shear_max[0]
        assert np.array_equal(sp.drift_ratio, sp.drift / sp.storey_heights)
    for cp, cj in zip(r.contacts, js["contacts"]):
        for key in CONTACT_KEYS:
            assert equal(cp[key], cj[key]), (method, key)
        assert cp.force_equiv == pytest.approx(math.pi * cp.max_impulse / (2 * 0.01), rel=1e-15)
        compliant = method in ("penalty", "newmark")
        assert math.isnan(cp.force_max) != compliant


@pytest.mark.parametrize("method", ["moreau", "event", "penalty", "newmark"])
def test_oscillator_demands_are_the_cli(cli, method):
    js = cli("simulate", "--method", method, "--height", "3.5", "--Pi3", "0.2")
    r = pound.simulate(method=method, height=3.5, Pi3=0.2, history=False)
    for key in OSC_KEYS:
        assert equal(r[key], js[key]), (method, key)
    assert r.impacts > 0 and math.isnan(r.force_max) != (method in ("penalty", "newmark"))
    assert r.drift_ratio == r.umax / 3.5 and r.shear_max <= r.acc_max or r.contact_time > 0
    assert r.contact_duration == 0.005  # PD_CONTACT_DURATION


def test_storey_heights_of_the_file(tmp_path, cli):
    text = json.loads(SCENE.read_text())
    text["structures"][1]["storey_heights"] = [4.0] + [3.2] * 7
    path = tmp_path / "tall.json"
    path.write_text(json.dumps(text))
    r = pound.simulate_scene(str(path), history=False)
    js = cli("simulate", "--scene", path)
    tower = r.structures[1]
    assert list(tower.storey_heights) == [4.0] + [3.2] * 7
    assert list(tower.storey_heights) == js["structures"][1]["storey_heights"]
    assert np.array_equal(tower.drift_ratio, js["structures"][1]["drift_ratio"])


@pytest.mark.parametrize("kw,says", [
    (dict(contact_duration=0), "contact_duration: must be a finite number > 0"),
    (dict(contact_duration=-1e-3), "contact_duration: must be a finite number > 0"),
    (dict(height=0), "height: the storey height must be a finite number > 0"),
    (dict(height="tall"), "height: 'tall' is not a number"),
])
def test_bad_demand_options(kw, says):
    with pytest.raises(pound.InputError, match=says):
        pound.simulate(history=False, **kw)
