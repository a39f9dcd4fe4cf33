"""Figures of pound's results on Matplotlib (imported when a function is
called: `import pound` never needs it).

    import pound, pound.plot
    r = pound.simulate(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
    fig, ax = pound.plot.history(r)          # u(t), the wall at u = gap, impacts marked
    s = pound.spectrum(Pi2=(0.05, 5, 60), pulse="sine", dir=["normal", "reverse"],
                       Pi3=[0.01, 0.1, 1], eps=0.5)
    fig, axes = pound.plot.spectrum(s, traditional=True)   # the paper's Fig. 5

Every function draws into the Axes given (or a new figure), returns
(Figure, Axes) -- an array of Axes for several panels -- and never calls
show(): the caller saves or shows the figure.  Nothing is computed here but
where to put the marks: the numbers are the result's.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

if TYPE_CHECKING:  # Matplotlib is optional: its types for the checker only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["history", "spectrum", "record", "impact_times"]

G = 9.80665  # m/s^2 in one g (records are often read in g)


def _pyplot() -> Any:
    """matplotlib.pyplot, or an ImportError that says what to install."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("pound.plot needs Matplotlib, which is not importable (%s): install "
                          "python3-matplotlib (Debian) or `pip install matplotlib`; the rest "
                          "of pound works without it" % e) from None
    return plt


def _axes(ax: Optional[Axes]) -> Tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure, ax
    return _pyplot().subplots(figsize=(9, 4), layout="constrained")


def _history_of(r: Mapping[str, Any]) -> Mapping[str, Any]:
    h = r.get("history")
    if h is None or "t" not in h:
        raise ValueError("pound.plot: the result has no history (run it with history=True)")
    return h


def _onsets(impulse: np.ndarray) -> np.ndarray:
    """The samples that carry an impulse after one that carries none: the
    library's definition of an impact (problems/scene_run.c), so one per
    impact of a Moreau-Jean run."""
    p = np.asarray(impulse) > 0.0
    before = np.concatenate([[False], p[:-1]])
    return np.flatnonzero(p & ~before)


def _index(what: str, value: Any, n: int, of: str) -> int:
    """value as an index in [0, n): an int (Python's or NumPy's; anything
    else, a bool too, raises TypeError); a negative one or one past the end
    raises ValueError naming what and the valid range (Python's wrap-around
    of -1 would pick the last one without a word)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError("pound.plot: %s must be an integer index, got %r" % (what, value))
    k = int(value)
    if not 0 <= k < n:
        valid = "only 0" if n == 1 else "0 to %d" % (n - 1) if n else "none"
        raise ValueError("pound.plot: %s = %d is out of range: the result has %d %s (valid: %s)"
                         % (what, k, n, of, valid))
    return k


def impact_times(r: Mapping[str, Any], contact: int = 0) -> Tuple[np.ndarray, np.ndarray]:
    """(indices, times [s]) of the impacts in a result's history.

    A sample whose impulse is > 0 after one whose impulse is 0 is an impact
    (the library counts impacts so: for Moreau-Jean one marker per counted
    impact; for a sampled reference, impacts between two samples show as
    one).  The oscillator's event-driven reference places its impacts
    more closely (its samples carry the impulses of the impacts between
    them, but at the next sample): there an impact is a sample pair across
    which the velocity turns from toward the wall (v > 0) to away (v < 0)
    while the gap is within one sample's travel of zero; its time is the
    gap's linear closing time t[k-1] + gap[k-1] / v[k-1] and the index is k.
    contact: the scene contact's index, 0 to the number of contacts - 1 (an
    oscillator has one, contact 0); another (a negative index too: -1 is not
    the last contact) raises ValueError naming the valid range."""
    h = _history_of(r)
    t = np.asarray(h["t"], dtype=float)
    imp = np.asarray(h["impulse"], dtype=float)
    a = _index("contact", contact, imp.shape[1] if imp.ndim == 2 else 1,
               "contacts" if imp.ndim == 2 else "contact (an oscillator)")
    if imp.ndim == 2:
        imp = imp[:, a]
    k = _onsets(imp)
    if not _exact_oscillator(r, h) or not r.get("impacts"):
        return k, t[k]
    # the oscillator without impulses in its samples (the exact reference)
    v, gap = np.asarray(h["v"], dtype=float), np.asarray(h["gap"], dtype=float)
    if len(t) < 2:
        return k, t[k]
    dt = np.diff(t)
    turn = (v[:-1] > 0.0) & (v[1:] < 0.0)
    reach = gap[:-1] <= 1.5 * v[:-1] * dt + 1e-12 * abs(float(r.get("gap", 0.0)))
    k = np.flatnonzero(turn & reach) + 1
    when = t[k - 1] + np.clip(gap[k - 1] / v[k - 1], 0.0, dt[k - 1])
    return k, when


def _exact_oscillator(r: Mapping[str, Any], h: Mapping[str, Any]) -> bool:
    """An oscillator's history from the exact event-driven reference."""
    return "u" in h and np.ndim(h["impulse"]) == 1 and r.get("method") == "event"


def _scales(r: Mapping[str, Any], scaled: bool) -> Tuple[float, float, str, str]:
    """(time unit, length unit, labels): seconds and metres, or t/Tp and u/Le."""
    if not scaled:
        return 1.0, 1.0, "t [s]", "[m]"
    Tp, ap = float(r["Tp"]), float(r["ap"])
    Le = float(r["Le"]) if "Le" in r else ap * (Tp / (2.0 * np.pi)) ** 2
    return Tp, Le, "t / Tp", "/ Le"


def _osc_history(r: Mapping[str, Any], ax: Axes, impacts: bool, wall: bool,
                 scaled: bool) -> None:
    h = _history_of(r)
    ts, ls, tlabel, ulabel = _scales(r, scaled)
    t, u = np.asarray(h["t"]) / ts, np.asarray(h["u"]) / ls
    ax.plot(t, u, lw=1.2, color="C0", label="u (%s)" % r.get("method", "run"))
    # no_wall: the reference reports no gap (NaN), a stepper's run goes past u = gap
    # without an impact (with a wall, the gap goes negative only at an impact step)
    min_gap = float(r.get("min_gap", 0.0))
    has_wall = not (np.isnan(min_gap) or (min_gap < 0.0 and not r.get("impacts")))
    if wall and has_wall and "gap" in r:
        ax.axhline(float(r["gap"]) / ls, color="k", ls="--", lw=1.0,
                   label="wall (gap = %.4g m)" % float(r["gap"]))
    if impacts:
        k, when = impact_times(r)
        if len(k):
            # a stepper's at its sample; the reference's on the wall (u = gap when it strikes)
            exact = _exact_oscillator(r, h)
            at = np.full(len(k), float(r["gap"]) / ls) if exact else u[k]
            ax.plot(when / ts, at, ls="none", marker="o", mfc="none", color="C3",
                    label="impacts (%d)" % len(k))
    ax.set_xlabel(tlabel)
    ax.set_ylabel("u " + ulabel)
    what = "record %s" % r["record"] if "record" in r else "%s pulse" % r.get("pulse", "?")
    ax.set_title("%s, %s: umax = %.4g m, %d impacts"
                 % (what, r.get("dir", "?"), float(r.get("umax", np.nan)),
                    int(r.get("impacts", 0))))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")


def _scene_dofs(r: Mapping[str, Any]) -> Tuple[Dict[str, int], List[Tuple[str, int]]]:
    """The first dof of each structure (dofs are numbered structure by
    structure, storey 1 first) and the (structure, level) curves drawn:
    the storeys in a contact, else the top storey."""
    first: Dict[str, int] = {}
    top: Dict[str, int] = {}
    o = 0
    for st in r["structures"]:
        first[st["name"]] = o
        top[st["name"]] = int(st["storeys"])
        o += int(st["storeys"])
    levels: Dict[str, set] = {name: set() for name in first}
    for ct in r["contacts"]:
        if ct["a"] != "wall":
            levels[ct["a"]].add(int(ct["level"]))
        if ct["b"] != "wall":
            levels[ct["b"]].add(int(ct["level_b"]))
    curves = [(name, lv) for name in first for lv in sorted(levels[name] or {top[name]})]
    return first, curves


def _scene_history(r: Mapping[str, Any], ax: Axes, impacts: bool, wall: bool,
                   scaled: bool) -> None:
    h = _history_of(r)
    ts, ls, tlabel, ulabel = _scales(r, scaled)
    t, x = np.asarray(h["t"]) / ts, np.asarray(h["x"]) / ls
    first, curves = _scene_dofs(r)
    # one colour per structure, its higher storeys darker; one legend entry per structure
    names = list(first)
    color = {name: "C%d" % (i % 10) for i, name in enumerate(names)}
    for name in names:
        lvs = [lv for n, lv in curves if n == name]
        storeys = next(int(s["storeys"]) for s in r["structures"] if s["name"] == name)
        for j, lv in enumerate(lvs):
            label = "_nolegend_" if j else name if storeys == 1 else "%s, storey%s %s" % (
                name, "s" if len(lvs) > 1 else "", ",".join(str(v) for v in lvs))
            ax.plot(t, x[:, first[name] + lv - 1], lw=1.0, color=color[name],
                    alpha=0.4 + 0.6 * (j + 1) / len(lvs), label=label)
    walls = set()
    pairs: Dict[Tuple[str, str], int] = {}
    for ct in r["contacts"]:
        pairs[(ct["a"], ct["b"])] = pairs.get((ct["a"], ct["b"]), 0) + int(ct["impacts"])
    labelled = set()
    for a, ct in enumerate(r["contacts"]):
        if wall and "wall" in (ct["a"], ct["b"]):
            # gap = gap0 + x_b - x_a: a wall on side a stands at x = -gap0, on side b at +gap0
            pos = -float(ct["gap"]) if ct["a"] == "wall" else float(ct["gap"])
            if pos not in walls:
                walls.add(pos)
                ax.axhline(pos / ls, color="k", ls="--", lw=1.0,
                           label="wall (%+.4g m)" % pos)
        if not impacts:
            continue
        k, when = impact_times(r, a)
        if not len(k):
            continue
        pair = (ct["a"], ct["b"])
        for side, lv in ((ct["a"], ct["level"]), (ct["b"], ct["level_b"])):
            if side == "wall":
                continue
            label = "_nolegend_" if pair in labelled else \
                "impacts %s-%s (%d)" % (pair[0], pair[1], pairs[pair])
            labelled.add(pair)
            ax.plot(when / ts, x[k, first[side] + int(lv) - 1], ls="none", marker="o",
                    ms=5, mfc="none", color=color[side], label=label)
    ax.set_xlabel(tlabel)
    ax.set_ylabel("x " + ulabel)
    ax.set_title("scene: %d structures, %d contacts, %d impacts (%s)"
                 % (len(r["structures"]), len(r["contacts"]), int(r.get("impacts", 0)),
                    r.get("method", "?")))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def history(r: Mapping[str, Any], ax: Optional[Axes] = None, impacts: bool = True,
            wall: bool = True, scaled: bool = False) -> Tuple[Figure, Axes]:
    """The history of a run with its impacts: an oscillator's (pound.simulate)
    u(t) [m] against t [s] with the wall drawn at u = gap [m] (dashed) and
    each impact marked (open circles) on the wall; a scene's (Scene.simulate,
    pound.simulate_scene) x(t) [m] of every storey that is in a contact (the
    top storey of a structure in none), the walls at their gaps, each
    contact's impacts marked on both structures' curves.  scaled=True draws
    t / Tp and u / Le (the paper's dimensionless history, Fig. 3).

    The marks are the history's own (impact_times: the samples that carry
    an impulse after one that does not).  Returns (Figure, Axes)."""
    fig, ax = _axes(ax)
    h = _history_of(r)
    if "x" in h:
        _scene_history(r, ax, impacts, wall, scaled)
    elif "u" in h:
        _osc_history(r, ax, impacts, wall, scaled)
    else:
        raise ValueError("pound.plot.history: neither an oscillator's (u) nor a scene's (x) "
                         "history")
    return fig, ax


def _curve_label(c: Mapping[str, Any], vary: Sequence[str]) -> str:
    names = {"Pi3": "$\\Pi_3$", "gap": "gap [m]", "eps": "$\\epsilon$", "xi": "$\\xi$",
             "ap": "$a_p$ [m/s$^2$]"}
    parts = ["%s = %g" % (names[k], c[k]) for k in vary]
    return ", ".join(parts) if parts else str(c.get("label", ""))


def spectrum(s: Mapping[str, Any], axes: Optional[Any] = None, traditional: bool = False,
             y: str = "Pi1") -> Tuple[Figure, np.ndarray]:
    """Pounding spectra in Pi terms (pound.spectrum's result), as the paper's
    Figs. 5 and 6: one panel per pulse and direction (normal, reverse), one
    curve per Pi3 (or gap [m]), eps, xi, ap, log-log Pi1 = umax / Le = umax
    wp^2 / ap against Pi2 = Tp / T0 (y: another key of shape (curves, N),
    e.g. 'gamma' or 'impacts').  traditional=True adds a second row: the
    amplification gamma = umax / umax_free against the gap ratio chi =
    gap / umax_free (log x), the view the paper compares with.

    axes: an array of Axes of (rows, panels) to draw into.  Returns
    (Figure, the 2-D array of Axes)."""
    curves = list(s["curves"])
    panels: List[Tuple[str, str]] = []
    for c in curves:
        if (c["pulse"], c["dir"]) not in panels:
            panels.append((c["pulse"], c["dir"]))
    rows = 2 if traditional else 1
    if axes is None:
        fig, axes = _pyplot().subplots(rows, len(panels), figsize=(5.5 * len(panels), 4 * rows),
                                       squeeze=False, layout="constrained")
    else:
        axes = np.asarray(axes, dtype=object).reshape(rows, len(panels))
        fig = axes[0, 0].figure
    keys = [k for k in ("Pi3", "gap", "eps", "xi", "ap")
            if len({c[k] for c in curves if k in c}) > 1]
    Pi2 = np.asarray(s["Pi2"])
    Y = np.asarray(s[y])
    drawn = [0] * len(panels)
    for k, c in enumerate(curves):
        j = panels.index((c["pulse"], c["dir"]))
        label, colour = _curve_label(c, keys), "C%d" % (drawn[j] % 10)
        drawn[j] += 1
        axes[0, j].plot(Pi2, Y[k], lw=1.5, color=colour, label=label)
        if traditional:
            axes[1, j].plot(np.asarray(s["chi"])[k], np.asarray(s["gamma"])[k], lw=1.5,
                            color=colour, label=label)
    ylabel = {"Pi1": "$\\Pi_1 = u_{max}\\,\\omega_p^2 / a_p = u_{max} / L_e$",
              "gamma": "$\\gamma = u_{max} / u_{max,free}$"}.get(y, y)
    for j, (pulse, d) in enumerate(panels):
        ax = axes[0, j]
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("$\\Pi_2 = T_p / T_0$")
        ax.set_ylabel(ylabel)
        ax.set_title("%s, %s" % ("one-%s pulse" % pulse if pulse in ("sine", "cosine") else
                                 "harmonic" if pulse == "harmonic" else "record " + pulse, d))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="lower left", fontsize="small")
        if traditional:
            ax = axes[1, j]
            ax.set_xscale("log")
            ax.set_xlabel("$\\chi$ = gap / $u_{max,free}$")
            ax.set_ylabel("$\\gamma = u_{max} / u_{max,free}$")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(loc="upper right", fontsize="small")
    return fig, axes


def record(rec: Mapping[str, Any], ax: Optional[Axes] = None, in_g: bool = True
           ) -> Tuple[Figure, Axes]:
    """A record (pound.record's result): its ground acceleration and the
    fitted one-cycle pulse (pulse_acc) against t [s], in g (in_g=False:
    m/s^2), the peak (pga at t_pga) marked.  Returns (Figure, Axes)."""
    fig, ax = _axes(ax)
    unit = G if in_g else 1.0
    t = np.asarray(rec["t"])
    ax.plot(t, np.asarray(rec["acc"]) / unit, lw=0.7, color="0.45", label=str(rec["name"]))
    p = rec["pulse"]
    # every figure in the axis' unit (the labels too)
    uname = "g" if in_g else "m/s$^2$"
    ax.plot(t, np.asarray(rec["pulse_acc"]) / unit, lw=1.6, color="C3",
            label="fitted %s pulse: Tp = %.3g s, ap = %.3g %s" % (p["shape"], p["Tp"],
                                                               p["ap"] / unit, uname))
    k = int(np.argmin(np.abs(t - float(rec["t_pga"]))))
    ax.plot([t[k]], [np.asarray(rec["acc"])[k] / unit], ls="none", marker="v", color="k",
            label="pga = %.3g %s" % (float(rec["pga"]) / unit, uname))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("ground acceleration [%s]" % ("g" if in_g else "m/s$^2$"))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig, ax
