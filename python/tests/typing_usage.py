"""A user's code, type-checked by python/check.sh with `mypy --strict`
against the installed package (py.typed): every public call below must be
typed (an unannotated function would fail --strict's
disallow-untyped-calls), and the types must fit as a user writes them.
Not a test module (pytest collects test_*.py only); it also runs."""
from pathlib import Path
from typing import List

import numpy as np

import pound
import pound.plot

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent.parent / "examples"


def run() -> List[float]:
    r: pound.Result = pound.simulate(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
    umax: float = r.umax
    s = pound.spectrum(Pi2_range=(0.05, 5, 4), pulse="sine", dir=["normal", "reverse"],
                       Pi3=[0.01, 0.1], eps=0.5, threads=1)
    c = pound.compare(methods="moreau,penalty", Pi2=1.0, Pi3=0.05)
    steps: List[float] = pound.dt_range(1e-3, 1e-4, np.int64(3))
    conv = pound.converge("1e-3:2.5e-4:3", theta=[0.5, 1.0], Pi2=1.0)
    with pound.Scene.chain(3, ratio=1.5, T0=1.0, gap=0.01) as sc:
        rs = sc.simulate(history=False, tend=0.5)
        le: float = sc.Le
    rows = pound.simulate_scene(EXAMPLES / "scenes" / "two-sdof.json", history=False)
    M, q = pound.read_lcp(str(EXAMPLES / "murty1978.lcp"))
    z = pound.lcp(M, q, solver="lemke").z
    rec = pound.Record(EXAMPLES / "records" / "NGA_no_1063_RRS228.AT2")
    one = pound.simulate(record=rec, Pi2=1.0, Pi3=0.05, history=False)
    tol = pound.simulate(Pi2=1.5, Pi3=0.1, rtol=1e-4, history=False)  # Moreau-Jean to rtol
    met: bool = tol.rtol_met
    est: float = tol.err_est
    wp = pound.converge("1e-3:5e-4:2", methods="moreau-rtol", rtols=[1e-3, 1e-4], Pi2=1.0)
    assert met and est <= 1e-4 and len(wp.rows) == 2
    version: str = pound.version() or "?"
    try:
        pound.simulate(ap=-1)
    except pound.InputError as e:
        status: int = e.status
        code: str = e.code
    assert status < 0 and code and version and le > 0
    return [umax, float(s.Pi1.max()), c.err_umax_rel, steps[0], len(conv.rows), rs.impacts,
            rows.impacts, float(z.sum()), one.umax]


def draw(r: pound.Result, s: pound.Result) -> None:
    """The figures' types (Matplotlib's are Any without its stubs)."""
    fig, ax = pound.plot.history(r, scaled=True)
    fig.savefig("history.png")
    fig2, axes = pound.plot.spectrum(s, traditional=True)
    axes[1, 0].set_xlim(0.01, 10)


if __name__ == "__main__":
    print(run())
