"""The one-wall oscillator: simulate, compare, converge (cli/cmd_simulate.c,
cli/cmd_compare.c, cli/cmd_converge.c reproduced from library calls)."""
import ctypes
import math
import os
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _args, _demand, _lib
from ._case import Case, InputError, copy_opts, number
from ._lib import PdErr, err_text, lib, s
from ._types import Floats, Int, Names, PathArg, Range

if TYPE_CHECKING:
    from ._scene import Scene

NAN = float("nan")


# CF units of the histories' variables (the CLI's files give the same): a scene's
# (its impulses in N s), and the oscillator's (per unit mass: its impulse in m/s)
UNITS = {"u": "m", "v": "m/s", "x": "m", "gap": "m", "impulse": "N s", "a": "m/s^2",
         "force": "N", "up": "m"}
OSC_UNITS = {"t": "s", "u": "m", "v": "m/s", "impulse": "m/s", "gap": "m", "up": "m"}


class Result(dict):
    """A dict whose keys are also attributes (r.umax is r['umax']), with a
    short repr and, when pandas or xarray is installed, to_pandas() and
    to_xarray() of its history (of a spectrum: its points, one row each, and
    its arrays along (curve, Pi2)).  Values are in SI units (s, m, m/s, m/s^2,
    N s; impulses of the oscillator per unit mass, m/s) and the Pi terms
    are dimensionless; each function's docstring lists its keys."""

    def __getattr__(self, key: str) -> Any:
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def __dir__(self) -> List[str]:
        return list(self.keys()) + list(dict.__dir__(self))

    def __repr__(self) -> str:
        def short(v):
            if isinstance(v, np.ndarray):
                return "array(%s)" % "x".join(str(d) for d in v.shape)
            if isinstance(v, Result):
                return "Result(%d keys)" % len(v)
            if isinstance(v, list):
                return "[%d items]" % len(v)
            if isinstance(v, float):
                return "%.6g" % v
            return repr(v)
        items = ["%s=%s" % (k, short(v)) for k, v in self.items()]
        more = len(items) - 12
        return "Result(%s%s)" % (", ".join(items[:12]), ", ... %d more" % more if more > 0 else "")

    def _table(self):
        """The rows of a table-like result as a list of dicts, or None: a
        spectrum's points (one per point of the sweep: its curve's pulse,
        dir, Pi3 or gap, eps, xi, ap and its Pi2 with the results),
        converge's rows, compare's methods."""
        for key in TABLE_KEYS:
            rows = self.get(key)
            if isinstance(rows, list) and rows and all(isinstance(r, dict) for r in rows):
                return [dict(r) for r in rows]
        return None

    def _columns(self):
        """The history's arrays as columns: a 2-D array k of n columns gives
        k[0] ... k[n-1].  Columns of different lengths raise ValueError
        naming them (not pandas' 'All arrays must be of the same length')."""
        h = self["history"] if "history" in self else self
        cols = {}
        for k, v in h.items():
            if isinstance(v, np.ndarray) and v.ndim == 1:
                cols[k] = v
            elif isinstance(v, np.ndarray) and v.ndim == 2:
                for j in range(v.shape[1]):
                    cols["%s[%d]" % (k, j)] = v[:, j]
        lengths = {}
        for k, v in cols.items():
            lengths.setdefault(len(v), k)
        if len(lengths) > 1:
            raise ValueError("to_pandas: the arrays are not of one length (%s), not a table"
                             % ", ".join("%s: %d" % (k, n) for n, k in lengths.items()))
        return cols

    def _scalars(self):
        return {k: v for k, v in self.items()
                if isinstance(v, (int, float, str, np.integer, np.floating))}

    def to_pandas(self) -> Any:
        """The history as a pandas DataFrame indexed by t (the scalars in
        df.attrs); a table-like result as a long (tidy) DataFrame, one row
        per row of it: a spectrum's points (one per point of the sweep:
        every swept parameter, pulse, dir, Pi3 or gap, eps, xi, ap, Pi2, and
        every result, Pi1, gamma, ...), converge's rows, compare's methods;
        the other results without a history: a Series of the scalars."""
        import pandas as pd
        if "history" not in self:
            rows = self._table()
            if rows is not None:
                df = pd.DataFrame(rows)
                df.attrs.update(self._scalars())
                return df
        cols = self._columns()
        if not cols:
            return pd.Series(self._scalars())
        df = pd.DataFrame(cols)
        if "t" in df:
            df = df.set_index("t")
        df.attrs.update(self._scalars())
        return df

    def to_xarray(self) -> Any:
        """The history as an xarray Dataset with t as its coordinate (a scene's
        x, v along (t, dof), gap and impulse along (t, contact)); the scalars as
        attributes.  A spectrum: its arrays along (curve, Pi2), the curves'
        pulse, dir, ap, xi, Pi3 or gap, eps and label as coordinates along
        curve."""
        import xarray as xr
        if "history" not in self and "curves" in self and "Pi2" in self:
            return self._spectrum_xarray(xr)
        h = self["history"] if "history" in self else self
        if "t" not in h:
            raise ValueError("to_xarray: no history (run with history=True)")
        data: Dict[str, Any] = {}
        coords: Dict[str, Any] = {"t": ("t", h["t"], {"units": "s", "long_name": "time"})}
        units = OSC_UNITS if "u" in h else UNITS  # the oscillator's history has u, a scene's x
        for k, v in h.items():
            if k == "t" or not isinstance(v, np.ndarray):
                continue
            second = {"x": "dof", "v": "dof", "a": "dof", "up": "dof", "gap": "contact",
                      "impulse": "contact", "force": "contact"}.get(k, k + "_index")
            attrs = {"units": units[k]} if k in units else {}
            data[k] = (("t",) if v.ndim == 1 else ("t", second)), v, attrs
        for dim in ("dof", "contact"):  # a scene's names of its dofs and contacts
            if dim in h and len(h[dim]):
                coords[dim] = (dim, list(h[dim]))
        return xr.Dataset(data, coords=coords, attrs=self._scalars())

    def _spectrum_xarray(self, xr):
        curves = self["curves"]
        data = {k: (("curve", "Pi2"), v) for k, v in self.items()
                if isinstance(v, np.ndarray) and v.ndim == 2}
        coords = {"Pi2": self["Pi2"], "curve": np.arange(len(curves))}
        for key in ("pulse", "dir", "ap", "xi", "Pi3", "gap", "eps", "label"):
            if all(key in c for c in curves):
                coords[key] = ("curve", [c[key] for c in curves])
        return xr.Dataset(data, coords=coords, attrs=self._scalars())


# the keys of table-like results (to_pandas): a spectrum's points, converge's rows,
# compare's methods
TABLE_KEYS = ("points", "rows", "methods")


class _History:
    """Samples copied whole (memmove) into a growing NumPy record array."""

    def __init__(self, dtype, cap, every):
        self.dtype = np.dtype(dtype)
        self.buf = np.zeros(max(int(cap), 16), dtype=self.dtype)
        self.n = 0
        self.every = int(every)
        self.error = None

    def grow(self):
        new = np.zeros(2 * len(self.buf), dtype=self.dtype)
        new[:self.n] = self.buf[:self.n]
        self.buf = new

    def rows(self):
        return self.buf[:self.n]


OSC_SAMPLE = [("step", "i8"), ("t", "f8"), ("u", "f8"), ("v", "f8"), ("impulse", "f8"),
              ("gap", "f8"), ("impacts", "i8"), ("up", "f8")]


def _osc_sampler(h):
    size = ctypes.sizeof(_lib.PdOscSample)
    memmove, c_long = ctypes.memmove, ctypes.c_long

    def sample(p, ctx):
        try:
            if h.every > 1 and c_long.from_address(p).value % h.every:
                return 0
            if h.n == len(h.buf):
                h.grow()
            memmove(h.buf.ctypes.data + h.n * size, p, size)
            h.n += 1
            return 0
        except BaseException as e:  # stop the run; raised once it returns
            h.error = e
            return 1
    return _lib.OscSampler(sample)


def history_cap(o, every):
    """Rows to start a history with: a fixed-step run's samples, or (steps
    to a tolerance, dt 0: their number unknown) a start that grows."""
    if o.rtol > 0.0 or not o.dt > 0.0:
        return 4096
    return lib.pd_steps_for(o.tend, o.dt) // every + 2


def tolerance_fields(r, sm):
    """The figures of Moreau-Jean to a tolerance (cmd_simulate.c's JSON): rtol
    (0: fixed steps), err_est (NaN: fixed steps), rtol_met (a bool),
    steps_rejected, dt_min, dt_max [s] (NaN: not Moreau-Jean)."""
    return dict(rtol=r.rtol, err_est=sm.err_est, rtol_met=bool(sm.rtol_met),
                steps_rejected=r.steps_rejected, dt_min=r.dt_min, dt_max=r.dt_max)


def history_args(history, every):
    """The history switch and its stride, checked (every >= 1, an integer)."""
    history = _args.flag("history", history)
    every = _args.integer("every", every)
    if every < 1:
        raise InputError("every: must be >= 1 (got %d)" % every)
    return history, every


def osc_result_fields(r):
    """A pd_osc_result as a dict."""
    return {k: (s(getattr(r, k)) if k == "kernel" else getattr(r, k))
            for k, _ in _lib.PdOscResult._fields_}


def _case_json(case, out):
    c = case.c
    out["Pi2"] = c.Pi2
    out["Pi3"] = c.Pi3
    out["eps"] = c.eps
    out["xi"] = c.xi
    out["ap"] = c.ap
    out["Tp"] = c.Tp
    out["T0"] = lib.pd_osc_T0(c)
    out["gap"] = lib.pd_osc_gap(c)
    out["pulse"] = s(lib.pd_osc_excitation_name(c))
    out["dir"] = s(lib.pd_dir_name(c.dir))
    if c.record:
        out["record"] = case.record.name
        out["scale"] = c.scale


def simulate(history: bool = True, every: Int = 1, **case: Any) -> Result:
    """One run of the pounding oscillator and its no-wall twin, as
    `pound simulate [flags] --json`.

    Keywords mirror the CLI's flags (defaults in brackets): pulse
    'sine'|'cosine'|'harmonic' ['sine'], dir 'normal'|'reverse' (or +1/-1)
    ['normal'], ap [1] m/s^2, Tp [1] s, T0 s or Pi2 [1], gap m or Pi3 [0.05],
    eps [0.5], xi [0.05]; record (a file, a pound.Record, or pound.record()'s
    Result: its acc [m/s^2] every dt), scale [1], units ['g' for a text
    file, 'm/s2' for an array], record_format ['auto']; method
    'auto'|'moreau'|'event'|'penalty' ['auto': the exact event-driven reference, or Moreau-Jean
    where its scan would be over budget; a keyword only one method takes,
    dt, theta, kc, ..., chooses that method, as on the command line: r.method
    and r.method_by say which and why], dt [min(Tp, T0)/2000], tend [Tp + 2 T0], theta [0.5],
    gamma [0.5], allow_unstable, no_accumulation, no_wall, kernel
    'auto'|'general', factor, lcp_solver, contact 'kelvin'|'hertz', kc,
    kc_abs, rtol, atol, stepper; height [3] m and contact_duration [0.005] s
    of the demands; a yielding spring: uy [m] or Piy = uy wp^2 / ap, and
    alpha [0] (docs/methods.md, "Yielding oscillators"; method 'moreau').

    rtol, as the CLI's --rtol: Moreau-Jean to a tolerance, in [1e-12, 1):
    steps chosen so that every peak (umax, u_toward, u_away, the drift,
    acc_max) is within rtol of its value, relative, with an estimate of its
    error (err_est); rtol alone chooses method 'moreau' (method_by
    '--rtol'); with method='penalty' (or kc, ...) it is the GSL integrator's
    tolerance [1e-10], as before.  With dt it raises InputError (fixed steps
    or steps to a tolerance, not both), and with the methods that have no
    tolerance (event, newmark).

    Returns a Result with the keys of the CLI's JSON: umax, u_toward,
    u_away, umax_free [m]; Pi1 = umax / Le, gamma = umax / umax_free, chi =
    gap / umax_free, Pi2, Pi3 (dimensionless); impacts, accumulations,
    steps (counts); first_impact, contact_time, dt, tend [s];
    first_impact_velocity, max_impact_velocity [m/s]; max_impulse per unit
    mass [m/s]; min_gap, gap [m]; ap [m/s^2], Tp, T0 [s]; cpu_s [s of
    CPU]; method, method_by, pulse, dir, kernel (names); the demands per
    unit mass (docs/scenes.md, "Demands"): drift_ratio, acc_max [m/s^2],
    shear_max, force_equiv, force_max [N/kg] (NaN: not a penalty method),
    height [m], contact_duration [s]; Moreau-Jean to a tolerance: rtol (0:
    fixed steps), err_est (the estimated relative error of the peaks, the
    larger of the run's and its twin's; NaN for fixed steps, the CLI's null),
    rtol_met (True when err_est <= rtol and no step floor or budget stopped
    the refinement; True without a tolerance), steps_rejected (tries halved),
    dt_min and dt_max [s] (the smallest and largest step kept: dt for fixed
    steps, NaN for the other methods); steps counts every step taken (with
    history the kept run is repeated for the sampler, as the CLI's -o).
    A yielding run adds uy [m], Piy, alpha, ductility (umax / uy),
    residual [m], n_yield, plastic_excursion [m], hysteretic_energy and the
    energy balance energy_input, _kinetic, _strain, _damping, _impact
    [J/kg] with energy_residual (a fraction of the input; NaN for newmark),
    and newton_failures (method 'newmark': steps whose Newton iterations
    failed, each redone at the spring's initial stiffness; 0 for the
    methods without Newton iterations).
    With history,
    records=[...] (files, pound.Records, pound.record() Results or arrays
    with record_dt): a
    suite, as `pound simulate --record F1 --record F2 ...`: r.records, one
    Result per record (each what simulate(record=...) gives), r.stats, per
    figure (umax, Pi1, gamma, impacts, max_impulse, acc_max, shear_max,
    drift_ratio; a yielding run's ductility) the suite's n, mean, median,
    p16, p84, min and max; target_pga=A or target_sa=A [m/s^2] (with T1 [s],
    default T0) scale each record to that PGA or 5 %-damped Sa(T1).
    r.history: the arrays step, t, u, v, impulse, gap, impacts of every
    every-th step (the CLI's -o file: t [s], u [m], v [m/s], impulse per
    unit mass since the last sample [m/s], gap delta - u [m]; and the
    impacts begun since the last sample; a yielding run's also up, the
    plastic offset [m]), with t, u, v, impulse also as r.t, r.u, r.v,
    r.impulse."""
    if "records" in case:
        return _simulate_suite(history, every, case)
    history, every = history_args(history, every)
    height = _demand.pop_height(case)
    k = Case(case).resolve()
    o = k.opts
    h = sampler = None
    if history:
        h = _History(OSC_SAMPLE, history_cap(o, every), every)
        sampler = _osc_sampler(h)
    sm = _lib.PdOscSummary()
    err = PdErr()
    st = lib.pd_osc_summarize(k.c, o, sampler or _lib.OscSampler(),  # type: ignore[call-overload]
                              None, sm, err)
    if h is not None and h.error is not None:
        raise h.error
    _lib.check(st, err)
    r = sm.r
    out = Result(method=s(lib.pd_method_name(o.method)),
                 method_by=k.have["method_by"] or "default", umax=r.umax, Pi1=sm.Pi1,
                 u_toward=r.u_toward, u_away=r.u_away, impacts=r.impacts,
                 accumulations=r.accumulations, first_impact=r.first_impact,
                 first_impact_velocity=r.first_impact_velocity,
                 max_impact_velocity=r.max_impact_velocity, max_impulse=r.max_impulse,
                 contact_time=r.contact_time, min_gap=r.min_gap, umax_free=sm.free.umax,
                 gamma=sm.gamma, chi=sm.chi, steps=r.steps, cpu_s=sm.cpu_s)
    out.update(tolerance_fields(r, sm))
    _demand.osc_fields(out, r, height)
    _case_json(k, out)
    out.update(dt=r.dt, theta=r.theta, gamma_active=r.gamma, tend=r.tend, kernel=s(r.kernel))
    if lib.pd_osc_yields(k.c):  # the yielding spring (SPEC section 7), as the CLI's JSON
        en = r.energy
        out.update(uy=lib.pd_osc_uy(k.c), Piy=k.c.Piy, alpha=k.c.alpha, ductility=r.ductility,
                   residual=r.residual, n_yield=r.n_yield,
                   plastic_excursion=r.plastic_excursion,
                   hysteretic_energy=r.hysteretic_energy, ductility_free=sm.free.ductility,
                   energy_input=en.input, energy_kinetic=en.kinetic, energy_strain=en.strain,
                   energy_damping=en.damping, energy_impact=en.impact,
                   energy_residual=en.residual)
        out.update(newton_failures=r.newton_failures)  # as the CLI's (0: no Newton)
    if h is not None:
        rows = h.rows()
        hist = Result((name, np.ascontiguousarray(rows[name])) for name, _ in OSC_SAMPLE
                      if name != "up" or "ductility" in out)  # up: a yielding run's
        out["history"] = hist
        for name in ("t", "u", "v", "impulse"):  # shortcuts (gap is the case's gap)
            out[name] = hist[name]
    return out


# ---- compare ------------------------------------------------------------------------------

_METHOD_CODE = {"moreau": 0, "penalty": 2, "event-general": 4, "newmark": 5}  # pd_method
_NMETHOD = 6
# converge's rows also Moreau-Jean to a tolerance (not a pd_method: want[MOREAU_RTOL])
MOREAU_RTOL = _NMETHOD
_CONVERGE_CODE = {"moreau": 0, "moreau-rtol": MOREAU_RTOL, "penalty": 2, "newmark": 5,
                  "event-general": 4}
DEFAULT_RTOLS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)  # converge --rtols



SUITE_FIGS = ("umax", "Pi1", "gamma", "impacts", "max_impulse", "acc_max", "shear_max",
              "drift_ratio", "u_toward", "u_away", "umax_free", "max_impact_velocity",
              "contact_time", "force_equiv", "force_max",
              "ductility")  # the CLI's stats (ductility: yielding runs)


def stats_of(values: Sequence[float]) -> "Result":
    """The suite's statistics of values (pd_stats_of: NaN left out): n,
    mean, median, p16, p84 (linear between order statistics), min, max."""
    a = np.ascontiguousarray(np.asarray(values, dtype=float))
    st, err = _lib.PdStats(), PdErr()
    _lib.check(lib.pd_stats_of(a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(a), st,
                               err), err)
    return Result(n=st.n, mean=st.mean, median=st.median, p16=st.p16, p84=st.p84, min=st.min,
                  max=st.max)


def _suite_record(item, case):
    """One entry of records=: a pound.Record, a file, pound.record(path)'s
    Result (its acc [m/s^2] every dt), or an array (record_dt, units)."""
    from ._case import Record, record_of_result
    if isinstance(item, Record):
        return item
    if isinstance(item, Mapping):
        return record_of_result(item, what="records")
    if isinstance(item, (str, bytes, os.PathLike)):
        return Record(item, case.get("units"), case.get("record_format", "auto"))
    if "record_dt" not in case:
        raise InputError("record_dt: give the sampling interval of the record arrays [s]")
    return Record.from_array(item, case["record_dt"], case.get("units") or "m/s2")


def suite_target(case, T1_default=None, T1_says=""):
    """A suite's scaling keywords (taken out of case): (kind, value, T1,
    name) with kind 0 (none), 1 (target_pga) or 2 (target_sa, at T1 or
    T1_default; T1_says names the default in the message when neither is
    there), the checks of cli/case.c."""
    target = [k for k in ("target_pga", "target_sa") if k in case]
    if len(target) > 1:
        raise InputError("target_pga and target_sa: a suite is scaled to one target")
    kind, value = (0, 0.0) if not target else (1 if target[0] == "target_pga" else 2,
                                               number(target[0], case.pop(target[0])))
    if target and not 0.0 < value <= 1e3:
        raise InputError("%s: the target must be in (0, 1000] m/s^2" % target[0])
    T1 = number("T1", case.pop("T1")) if "T1" in case else None
    if T1 is not None and kind != 2:
        raise InputError("T1: the period of target_sa")
    if kind == 2 and T1 is None:
        if T1_default is None:
            raise InputError("target_sa: give the period of Sa(T1) with T1%s" % T1_says)
        T1 = T1_default
    if target and "scale" in case:
        raise InputError("scale and %s: the target sets each record's scale" % target[0])
    return kind, value, T1, target[0] if target else None


def _simulate_suite(history, every, case):
    """simulate(records=[...]): every record's run and the suite's statistics."""
    items = case.pop("records")
    if isinstance(items, (str, bytes, os.PathLike)) or not isinstance(items, (list, tuple)) \
            or not items:
        raise InputError("records: a list of record files, pound.Records or arrays (a suite)")
    if "record" in case:
        raise InputError("records and record: give the suite one way")
    kind, value, T1, _ = suite_target(case, number("T0", case["T0"]) if "T0" in case else None,
                                      " (or the oscillator's T0)")
    base = number("scale", case.pop("scale", 1.0))
    runs = []
    for item in items:
        rec = _suite_record(item, case)
        scale = ctypes.c_double(base)
        if kind:
            err = PdErr()
            _lib.check(lib.pd_record_scale_to(rec.rec, rec.pulse, kind, value, T1 or 0.0, 0.05,
                                              scale, err), err)
        kw = {k: v for k, v in case.items() if k not in ("units", "record_format",
                                                          "record_dt")}
        runs.append(simulate(history, every, record=rec, scale=scale.value, **kw))
    out = Result(n=len(runs))
    if kind:
        out.update(target="pga" if kind == 1 else "sa", target_value=value)
    out["records"] = runs
    out["stats"] = Result((f, stats_of([r[f] for r in runs])) for f in SUITE_FIGS
                          if all(f in r for r in runs))
    return out


def parse_methods(methods, codes=None):
    """('moreau', 'penalty', 'newmark', 'event-general') -> want[] by pd_method
    code (codes: converge's, with 'moreau-rtol' at want[MOREAU_RTOL])."""
    codes = _METHOD_CODE if codes is None else codes
    if isinstance(methods, str):
        methods = methods.split(",")
    want = [0] * (max(codes.values()) + 1)
    if methods is None or (hasattr(methods, "__len__") and len(methods) == 0):
        raise InputError("methods: give %s" % ", ".join(codes))
    for m in _args.values("methods", methods):
        want[codes[_args.choice("methods", m, codes)]] = 1
    return want


def _scenes_only(want, scene):
    """event-general measures scenes only (the CLI's message)."""
    if want[4] and scene is None:
        raise InputError("methods: event-general is a reference for scenes (--scene, --chain); "
                         "the oscillator's reference is exact")


class _Traces:
    """The reference's and a run's u on the output grid (pd_trace)."""

    def __init__(self, o):
        self.ref, self.work = _lib.PdTrace(), _lib.PdTrace()
        if lib.pd_trace_alloc(self.ref, o) or lib.pd_trace_alloc(self.work, o):
            self.close()
            raise _lib.PoundMemoryError("out of memory for the histories", _lib.PD_ENOMEM)

    def close(self):
        lib.pd_trace_free(self.ref)
        lib.pd_trace_free(self.work)


def compare(methods: Names = ("moreau",), scene: Optional[Union[PathArg, "Scene"]] = None,
            **case: Any) -> Result:
    """Errors against the event-driven reference, as `pound compare --json`:
    err_umax_rel = |umax - umax_ref| / umax_ref and err_hist_linf =
    max_k |u(t_k) - u_ref(t_k)| / umax_ref on t_k = k dt, for Moreau-Jean
    and/or penalty (methods; scenes also 'event-general', the GSL-based
    reference).  scene=path (or a pound.Scene): the scene's (per structure).

    Returns a Result: method, err_umax_rel, err_hist_linf (of the first
    method; dimensionless, relative to the reference's umax), impacts and
    impacts_ref (counts), umax and umax_ref [m], dt [s], cpu_s and cpu_s_ref
    [s of CPU], and methods: one Result per method asked.  The case keywords
    are simulate()'s, but rtol: the penalty rows' integrator tolerance
    (Moreau-Jean runs on fixed steps dt here)."""
    want = parse_methods(methods)
    _scenes_only(want, scene)
    if scene is not None:
        from ._scene import compare_scene
        return compare_scene(scene, want, case)
    k = Case(case, listed=True).resolve()
    o, err = k.opts, PdErr()
    tr = _Traces(o)
    try:
        rr = _lib.PdOscResult()
        st = lib.pd_measure_reference(k.c, o, tr.ref, rr, err)
        if st:
            raise _lib.make_error(st, "reference: " + err_text(err))
        res: List[Any] = [None] * _NMETHOD
        for m in range(_NMETHOD):
            if not want[m]:
                continue
            om = copy_opts(o)
            om.method = m
            res[m] = _lib.PdMeasured()
            st = lib.pd_measure_run(k.c, om, tr.ref, rr.umax, tr.work, res[m], err)
            if st:
                raise _lib.make_error(st, "%s: %s" % (s(lib.pd_method_name(m)), err_text(err)))
    finally:
        tr.close()
    first = next(m for m in range(_NMETHOD) if want[m])
    f = res[first]
    out = Result(method=s(lib.pd_method_name(first)), err_umax_rel=f.err_umax_rel,
                 err_hist_linf=f.err_hist_linf, impacts=f.r.impacts, impacts_ref=rr.impacts,
                 cpu_s=f.r.cpu_s, cpu_s_ref=rr.cpu_s, umax=f.r.umax, umax_ref=rr.umax,
                 events_ref=rr.steps, accumulations_ref=rr.accumulations, dt=o.dt,
                 Pi2=k.c.Pi2, Pi3=k.c.Pi3, eps=k.c.eps)
    out["methods"] = [Result(method=s(lib.pd_method_name(m)), err_umax_rel=res[m].err_umax_rel,
                             err_hist_linf=res[m].err_hist_linf, impacts=res[m].r.impacts,
                             steps=res[m].r.steps, cpu_s=res[m].r.cpu_s)
                      for m in range(_NMETHOD) if want[m]]
    return out


# ---- converge -----------------------------------------------------------------------------

def dt_range(dt_max: float, dt_min: float, n: Int) -> List[float]:
    """The steps [s] of the CLI's --dt MAX:MIN:N: n values log-spaced from
    dt_max [s] down to dt_min [s] (cli/cmd_converge.c dt_at); 1 <= n <= 64."""
    dt_max, dt_min = number("dt", dt_max, "MAX ="), number("dt", dt_min, "MIN =")
    n = _args.integer("dt", n, "N =")
    if not (dt_min > 0.0) or dt_max < dt_min or n < 1 or n > 64:
        raise InputError("dt: need MAX >= MIN > 0 and 1 <= N <= 64 (got %g:%g:%d)"
                         % (dt_max, dt_min, n))
    if n > 1 and not dt_max > dt_min:
        raise InputError("dt: MAX equals MIN: one step size is N = 1 (got %g:%g:%d)"
                         % (dt_max, dt_min, n))
    if n == 1:
        return [dt_max]
    return [dt_max * math.pow(dt_min / dt_max, i / (n - 1)) for i in range(n)]


def _steps(dts):
    """The rows' steps and the finest: a 'MAX:MIN:N' string or a (MAX, MIN, N)
    tuple whose N is an int (the CLI's range, its finest step MIN), or a
    sequence of steps (the finest their minimum)."""
    if isinstance(dts, str):
        parts = dts.split(":")
        if len(parts) != 3:
            raise InputError("dt: '%s' is not MAX:MIN:N" % dts)
        try:
            dts = (float(parts[0]), float(parts[1]), int(parts[2]))
        except ValueError:
            raise InputError("dt: '%s' is not MAX:MIN:N" % (dts,)) from None
    if isinstance(dts, tuple) and len(dts) == 3 and isinstance(dts[2], (int, np.integer)) \
            and not isinstance(dts[2], bool):
        return dt_range(*dts), float(dts[1]), float(dts[0])
    steps = [number("dt", x) for x in _args.values("dt", dts)]
    if len(steps) > 64 or not all(x > 0.0 for x in steps):
        raise InputError("dt: give 1 to 64 steps > 0")
    return steps, min(steps), steps[0]


def converge(dts: Union[Range, Sequence[float]], theta: Floats = (0.5,),
             methods: Names = ("moreau", "moreau-rtol"), kcs: Optional[Floats] = None,
             error: str = "hist", scene: Optional[Union[PathArg, "Scene"]] = None,
             rtols: Optional[Floats] = None, **case: Any) -> Result:
    """Error and cost as dt shrinks, as `pound converge --dt ... --json`: one
    row per (dt, theta) for Moreau-Jean ('moreau'), one per dt for 'newmark',
    one per tolerance of rtols [1e-2, 1e-3, 1e-4, 1e-5, 1e-6] for
    Moreau-Jean to a tolerance ('moreau-rtol': its histories at its own steps,
    compared on the finest grid through the cubic between the steps' ends),
    one per contact stiffness multiple kc (kcs [1e2, 1e3, 1e4, 1e5, 1e6]) on
    the finest grid for penalty, and (scenes, 'event-general' in methods) one
    for the GSL-based reference; methods ['moreau', 'moreau-rtol'], the
    CLI's; order = log(err_prev / err) / log(dt_prev / dt) between
    successive fixed-step rows of one theta, on err_hist_linf (error='hist')
    or err_umax_rel ('umax').

    dts: 'MAX:MIN:N' or (MAX, MIN, N) with an int N (the CLI's --dt), or a
    sequence of steps [s].  rtols: the moreau-rtol rows' tolerances, in
    [1e-12, 1) (the CLI's --rtols).  kcs: multiples of the structure's
    stiffness (dimensionless).  Returns a Result: rows (one Result per row:
    method ('moreau' for moreau-rtol's rows too), theta, dt [s] (NaN for a
    moreau-rtol row), rtol and err_est (a moreau-rtol row's tolerance and
    its own estimate of its peaks' relative error; NaN for the others), kc,
    err_umax_rel, err_hist_linf (dimensionless), cpu_s [s of CPU], order,
    impacts, steps) and cpu_s_ref [s of CPU]; a scene's also impacts_ref and
    the reference's decisions.  The case keywords are simulate()'s, but rtol:
    the penalty rows' integrator tolerance (rtols sets the moreau-rtol
    rows')."""
    steps, dt_min, dt_first = _steps(dts)
    thetas = [number("theta", t) for t in _args.values("theta", theta)]
    if len(thetas) > 32:
        raise InputError("theta: give 1 to 32 values")
    want = parse_methods(methods, _CONVERGE_CODE)
    _scenes_only(want, scene)
    want_moreau, want_penalty, want_general, want_newmark = want[0], want[2], want[4], want[5]
    want_rtol = want[MOREAU_RTOL]
    tols = list(DEFAULT_RTOLS) if rtols is None else \
        [number("rtols", x) for x in _args.values("rtols", rtols)]
    if not 1 <= len(tols) <= 32:
        raise InputError("rtols: give 1 to 32 values")
    for x in tols:
        if not 1e-12 <= x < 1.0:
            raise InputError("rtols: the tolerances must be in [1e-12, 1) (got %g)" % x)
    kcs = [1e2, 1e3, 1e4, 1e5, 1e6] if kcs is None else \
        [number("kcs", x) for x in _args.values("kcs", kcs)]
    if any(not x > 0.0 for x in kcs):
        raise InputError("kcs: stiffness multiples must be > 0")
    _args.choice("error", error, ("hist", "umax"))
    if not _args.flag("allow_unstable", case.get("allow_unstable")):
        for t in thetas:
            if not 0.5 <= t <= 1.0:
                raise InputError("theta: %g is outside [1/2, 1] (allow_unstable=True)" % t)
    case = dict(case, dt=dt_first)
    meas: Any
    if scene is not None:
        from ._scene import SceneMeasurer
        meas = SceneMeasurer(scene, case)
    else:
        meas = _OscMeasurer(Case(case, listed=True).resolve())
    try:
        rows, ref_cpu = _rows(meas, steps, dt_min, thetas, want_moreau, want_penalty, kcs,
                              error, want_general, want_newmark, tols if want_rtol else ())
        out = Result(rows=rows, cpu_s_ref=ref_cpu)
        if scene is not None:
            out.update(meas.summary())
    finally:
        meas.close()
    return out


class _OscMeasurer:
    sc = None

    def __init__(self, case):
        self.case = case
        self.opts = case.opts
        self.tr = None
        self.rr = _lib.PdOscResult()

    def alloc(self, o):
        self.tr = _Traces(o)

    def reference(self, o, err):
        st = lib.pd_measure_reference(self.case.c, o, self.tr.ref, self.rr, err)
        return st, self.rr.cpu_s

    def warm_up(self, o, err):
        """The oscillator's runs load no library on first use."""

    def row(self, o, err):
        m = _lib.PdMeasured()
        st = lib.pd_measure_run(self.case.c, o, self.tr.ref, self.rr.umax, self.tr.work, m, err)
        return st, dict(err_umax=m.err_umax_rel, err_hist=m.err_hist_linf, cpu_s=m.r.cpu_s,
                        impacts=m.r.impacts, steps=m.r.steps,
                        err_est=m.r.err_est if o.rtol > 0.0 else NAN)

    def close(self):
        if self.tr is not None:
            self.tr.close()


def _rows(M, steps, dt_min, thetas, want_moreau, want_penalty, kcs, error, want_general=False,
          want_newmark=False, rtols=()):
    """cli/cmd_converge.c compute_rows (rtols: the moreau-rtol rows')."""
    o = copy_opts(M.opts)
    err = PdErr()
    # scenes: the reference once, on the comparison grid (converge_grid)
    once = M.sc is not None
    o.dt = max(dt_min, min(max(steps), 10.0 * lib.pd_scene_default_dt(M.sc))) if once \
        else dt_min
    ref_cpu = 0.0
    M.alloc(o)
    rows = []

    def reference():
        nonlocal ref_cpu
        st, cpu = M.reference(o, err)
        ref_cpu = max(ref_cpu, cpu)  # fmax: the CLI keeps the largest
        if st:
            raise _lib.make_error(st, err_text(err))

    def row(first=False):
        if first:
            M.warm_up(o, err)
        tol = o.rtol > 0.0
        r = Result(method=s(lib.pd_method_name(o.method)),
                   theta=o.theta if o.method == 0 and not tol else NAN,
                   dt=NAN if tol else o.dt, rtol=o.rtol if tol else NAN,
                   kc=o.pen.kc_mult if o.method in (2, 5) else NAN)
        st, m = M.row(o, err)
        if st:
            raise _lib.make_error(st, err_text(err))
        r.update(err_umax_rel=m["err_umax"], err_hist_linf=m["err_hist"], cpu_s=m["cpu_s"],
                 order=NAN, impacts=m["impacts"], steps=m["steps"],
                 err_est=m["err_est"] if tol else NAN)
        if "structures" in m:
            r["structures"] = m["structures"]
        rows.append(r)

    if once:
        reference()
    for d in steps if want_moreau else ():
        o.dt = d
        if not once:
            reference()
        for t in thetas:
            o.theta = t
            o.method = 0
            row(not rows)
    for i, d in enumerate(steps if want_newmark else ()):  # penalty elements, Newmark's dt
        o.dt = d
        if not once:
            reference()
        o.method = 5
        row(i == 0)
    for i, tol in enumerate(rtols):  # to a tolerance: measured on the finest grid
        o.dt = dt_min
        o.method = 0
        if not once and i == 0:
            reference()
        o.dt = 0.0
        o.rtol = tol
        try:
            row(i == 0)
        finally:
            o.rtol = 0.0
    if want_penalty:
        o.dt = dt_min
        if not once:
            reference()
        for i, kc in enumerate(kcs):
            o.method = 2
            o.pen.kc_mult = kc
            o.pen.kc_abs = 0.0
            row(i == 0)
    if want_general:  # one more point: the GSL-based reference on the finest grid
        o.dt = dt_min
        o.method = 4
        if not once:
            reference()
        row()
    key = "err_umax_rel" if error == "umax" else "err_hist_linf"
    for i, r in enumerate(rows):
        for q in range(i - 1, -1, -1):
            p = rows[q]
            if (p["method"] == "moreau" and r["method"] == "moreau" and math.isnan(p["rtol"])
                    and math.isnan(r["rtol"]) and p["theta"] == r["theta"]) \
                    or (p["method"] == "newmark" and r["method"] == "newmark"):
                r["order"] = _order(p[key], r[key], p["dt"], r["dt"])
                break
    # the CLI's column order
    keys = ("method", "theta", "dt", "rtol", "err_est", "kc", "err_umax_rel", "err_hist_linf",
            "cpu_s", "order", "impacts", "steps", "structures")
    return [Result((k, r[k]) for k in keys if k in r) for r in rows], ref_cpu


def _cdiv(a, b):
    """a / b with IEEE results where Python raises."""
    if b == 0.0:
        if a == 0.0 or math.isnan(a):
            return NAN
        return math.copysign(math.inf, a) * math.copysign(1.0, b)
    return a / b


def _clog(x):
    """C's log (math.log calls it) with IEEE results where Python raises."""
    if x == 0.0:
        return -math.inf
    if math.isnan(x) or x < 0.0:
        return NAN
    return math.log(x)


def _order(e0, e1, d0, d1):
    """log(e0 / e1) / log(d0 / d1) as C computes it."""
    return _cdiv(_clog(_cdiv(e0, e1)), _clog(_cdiv(d0, d1)))
