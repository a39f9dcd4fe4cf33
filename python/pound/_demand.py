"""The demand parameters of a run (docs/scenes.md, "Demands"), read from the
library's results into a Result with the keys and values of the CLI's JSON:
peak absolute floor accelerations (their smooth part), storey and base
shears, drift ratios, and the equivalent and actual peak contact forces."""
import numpy as np

from ._args import number
from ._lib import InputError

PD_STOREY_HEIGHT = 3.0  # m, the default storey height (PD_STOREY_HEIGHT)


def _fmt(x):
    return "%.10g" % x


def check_opts(o, have):
    """contact_duration, as cli/case.c checks --contact-duration."""
    if have.get("contact_duration") and not o.contact_duration > 0.0:
        raise InputError("contact_duration: must be a finite number > 0 [s] (got %s)"
                         % _fmt(o.contact_duration))


def pop_height(case):
    """The oscillator's storey height keyword (the CLI's --height) taken out
    of case: a finite number > 0 [m], PD_STOREY_HEIGHT when absent."""
    value = case.pop("height", None)
    if value is None:
        return PD_STOREY_HEIGHT
    h = number("height", value)
    if not h > 0.0:
        raise InputError("height: the storey height must be a finite number > 0 [m] (got %s)"
                         % _fmt(h))
    return h


def osc_fields(out, r, height):
    """The oscillator's demands per unit mass into out (cmd_simulate.c's JSON)."""
    out.update(height=height, drift_ratio=r.umax / height, acc_max=r.acc_max,
               shear_max=r.shear_max, force_equiv=r.force_equiv, force_max=r.force_max,
               contact_duration=r.contact_duration)


def scene_fields(out, sc, r):
    """A scene's demands into out: per structure (one value per storey) and per
    contact, as `pound simulate --scene F --json`."""
    n, m = max(sc.n, 1), max(sc.ncontact, 1)
    acc = np.ctypeslib.as_array(r.acc_max, (n,))
    shear = np.ctypeslib.as_array(r.shear_max, (n,))
    ratio = np.ctypeslib.as_array(r.drift_ratio, (n,))
    for k, st in enumerate(out["structures"]):
        c = sc.st[k]
        o, ns = c.dof, c.storeys
        st.update(storey_heights=np.ctypeslib.as_array(c.height, (ns,)).copy(),
                  drift_ratio=ratio[o:o + ns].copy(), acc_max=acc[o:o + ns].copy(),
                  shear_max=shear[o:o + ns].copy(), base_shear_max=float(shear[o]))
    f_max = np.ctypeslib.as_array(r.force_max, (m,))
    f_eq = np.ctypeslib.as_array(r.force_equiv, (m,))
    for a, ct in enumerate(out["contacts"]):
        ct.update(force_equiv=float(f_eq[a]), force_max=float(f_max[a]))
    out["contact_duration"] = r.contact_duration
