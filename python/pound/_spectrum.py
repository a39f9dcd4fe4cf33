"""Pounding response spectra in Pi terms, as `pound spectrum --json`
computes them: the sweep of pd_spectrum, one library call per task
(pd_spec_run_task) on a pool of threads (ctypes lets go of the GIL during
the call; every task writes its own slot, so the numbers never depend on
the threads), the points from pd_spec_rows."""
import ctypes
import os
import threading
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from . import _args, _lib
from ._case import (CASE_KEYS, PD_METHOD_AUTO, Case, InputError, implied_method, number,
                    parse_dir, parse_name)
from ._lib import PD_SPEC_MAX_LIST, PdErr, err_text, lib, s
from ._osc import Result
from ._types import Floats, Int, Names, Range

# the keywords a spectrum takes besides its lists (no T0, Pi2, no_wall: it sweeps Pi2 and
# runs the no-wall twins itself)
_CASE = tuple(k for k in CASE_KEYS if k not in ("T0", "Pi2", "no_wall", "pulse", "dir", "ap",
                                                "gap", "Pi3", "eps", "xi"))
PD_SPEC_MAX_TASKS = 2000000

POINT_KEYS = ("pulse", "dir", "Pi2", "Pi3", "eps", "xi", "Pi1", "umax_free", "gamma", "chi",
              "impacts", "method", "curve", "umax", "u_toward", "u_away", "contact_time",
              "first_impact", "ap", "Tp", "T0", "gap", "dt", "tend", "steps", "cpu_s")
ARRAY_KEYS = ("Pi1", "gamma", "chi", "umax", "umax_free", "u_toward", "u_away",
              "contact_time", "first_impact", "impacts", "steps", "T0", "gap", "dt", "tend")
# a yielding sweep's too (uy or Piy, alpha): the ductility of each point and
# of its no-wall twin, the residual over uy
YIELD_KEYS = ("ductility", "ductility_free", "residual_uy")


def _list(what, v, cap):
    return _args.values(what, v, cap)


def _grid(Pi2):
    """(MIN, MAX, N) or 'MIN:MAX:N'; a list (or array) would read as values,
    which a spectrum does not take: refused, naming the range's forms."""
    if not isinstance(Pi2, (str, tuple)):
        raise InputError("Pi2: a spectrum sweeps a range, given as the tuple (MIN, MAX, N) or "
                         "'MIN:MAX:N' (got %s %r: a list is not read as a range; explicit Pi2 "
                         "values are not supported)" % (type(Pi2).__name__, Pi2))
    if isinstance(Pi2, str):
        parts = Pi2.split(":")
        if len(parts) != 3:
            raise InputError("Pi2: give MIN:MAX:N (got '%s')" % Pi2)
        Pi2 = parts
    try:
        parts = list(Pi2)
    except TypeError:
        parts = None
    if parts is None or len(parts) != 3:
        raise InputError("Pi2: give (MIN, MAX, N) (got %r)" % (Pi2,))
    lo, hi = _args.number("Pi2", parts[0], "MIN ="), _args.number("Pi2", parts[1], "MAX =")
    n = _args.integer("Pi2", parts[2], "N =")
    if not lo > 0.0 or n < 1 or n > 1000000 or (hi != lo if n == 1 else not hi > lo):
        raise InputError("Pi2: need 0 < MIN < MAX and 2 <= N <= 1e6, or MIN = MAX with N = 1 "
                         "(got %g:%g:%d)" % (lo, hi, n))
    return lo, hi, n


def build(Pi2, linear=False, pulse=None, dir=None, ap=None, xi=None, Pi3=None, gap=None,
          eps=None, dt_per_Tp=None, **case):
    """The pd_spectrum of the keywords, checked as cmd_spectrum.c checks its
    flags; (spectrum, case) (the case owns a record)."""
    unknown = sorted(set(case) - set(_CASE))
    if unknown:
        raise TypeError("unexpected keyword argument(s) %s" % ", ".join(unknown))
    sp = _lib.PdSpectrum()
    lib.pd_spec_init(sp)
    sp.pi2_min, sp.pi2_max, sp.npi2 = _grid(Pi2)
    sp.linear = 1 if _args.flag("linear", linear) else 0
    if Pi3 is not None and gap is not None:
        raise InputError("gap and Pi3 are alternatives: give one")
    if pulse is not None:
        if case.get("record") is not None:
            raise InputError("pulse: the record replaces the pulse (its fitted pulse gives Tp; "
                             "scale scales it)")
        vals = _list("pulse", pulse, 3)
        for i, v in enumerate(vals):
            sp.pulse[i] = parse_name("pulse", lib.pd_pulse_parse, v, "sine, cosine, harmonic")
        sp.npulse = len(vals)
    if dir is not None:
        vals = _list("dir", dir, 2)
        for i, v in enumerate(vals):
            sp.dir[i] = parse_dir(v)
        sp.ndir = len(vals)
    for name, vals, arr, count in (("ap", ap, sp.ap, "nap"), ("xi", xi, sp.xi, "nxi"),
                                   ("Pi3", Pi3, sp.size, "nsize"), ("gap", gap, sp.size, "nsize"),
                                   ("eps", eps, sp.eps, "neps")):
        if vals is None:
            continue
        vals = [number(name, v) for v in _list(name, vals, PD_SPEC_MAX_LIST)]
        for i, v in enumerate(vals):
            arr[i] = v
        setattr(sp, count, len(vals))
    sp.size_is_gap = 1 if gap is not None else 0
    sp.dimensional = 1 if ap is not None else 0
    if dt_per_Tp is not None:
        sp.dt_per_Tp = number("dt_per_Tp", dt_per_Tp)
        if not sp.dt_per_Tp > 0.0:
            raise InputError("dt_per_Tp: must be > 0 (got %g)" % sp.dt_per_Tp)
        if case.get("dt") is not None:
            raise InputError("dt and dt_per_Tp are alternatives: give one")
    if lib.pd_spec_tasks(sp) > PD_SPEC_MAX_TASKS:
        raise InputError("Pi2: %d runs in this sweep, at most %d"
                         % (lib.pd_spec_tasks(sp), PD_SPEC_MAX_TASKS))
    for i in range(sp.neps):
        if not 0.0 <= sp.eps[i] <= 1.0:
            raise InputError("eps: restitution must be in [0, 1] (got %g)" % sp.eps[i])
    for i in range(sp.nxi):
        if not 0.0 <= sp.xi[i] < 1.0:
            raise InputError("xi: damping ratio must be in [0, 1) (got %g)" % sp.xi[i])
    for i in range(sp.nap):
        if not sp.ap[i] > 0.0:
            raise InputError("ap: pulse amplitude must be > 0 (got %g)" % sp.ap[i])
    for i in range(sp.nsize):
        if not sp.size[i] >= 0.0:
            raise InputError("%s: must be >= 0 (got %g)"
                             % ("gap" if sp.size_is_gap else "Pi3", sp.size[i]))
    # the case flags' ranges (on a copy, as the CLI does), then the sweep's base
    checked = Case(dict(case))
    if checked.opts.rtol > 0.0:
        raise InputError("rtol: a spectrum runs Moreau-Jean on fixed steps (dt, dt_per_Tp); "
                         "Moreau-Jean to a tolerance is simulate()'s (with method='penalty', "
                         "rtol is the integrator's tolerance)")
    checked.resolve()
    k = Case(dict(case))
    k.record = checked.record
    sp.base = k.c
    if k.record is not None:
        lib.pd_osc_set_record(sp.base, k.record.rec, k.record.pulse,
                              number("scale", case.get("scale", 1.0)))
        if not sp.dimensional:
            sp.ap[0] = sp.base.ap
    sp.base.Piy = checked.c.Piy  # uy in metres made Piy (the sweep keeps Piy)
    sp.opts = k.opts  # dt and tend stay 0 (per point) unless given
    # the method given or implied (dt_per_Tp too), else one for the sweep
    m, key = implied_method(dict(case, dt_per_Tp=dt_per_Tp))
    by = k.have["method_by"]
    if by is None and m is not None:
        sp.opts.method, by = m, "--" + key.replace("_", "-")
    if by is None:
        sp.opts.method = PD_METHOD_AUTO
        lib.pd_spec_resolve_method(sp)
    k.method_by = by or "default"
    err = PdErr()
    _lib.check(lib.pd_spec_validate(sp, err), err)
    return sp, k


def _threads(threads):
    if threads is None:
        threads = int(os.environ.get("OMP_NUM_THREADS", "0") or 0) or os.cpu_count() or 1
    threads = _args.integer("threads", threads)
    if not 1 <= threads <= 4096:
        raise InputError("threads: must be in [1, 4096] (got %d)" % threads)
    return threads


def run_tasks(sp, threads=None):
    """Every task of the sweep into its slot; the lowest failed task raises."""
    ntasks = lib.pd_spec_tasks(sp)
    res = (_lib.PdSpecResult * ntasks)()
    # costliest first, so that the last tasks are short (as the CLI orders them)
    order = sorted(range(ntasks), key=lambda t: (-lib.pd_spec_cost(sp, t), t))
    threads = min(_threads(threads), max(1, ntasks))
    msgs = {}
    lock = threading.Lock()
    it = iter(order)

    def work():
        err = PdErr()
        while True:
            with lock:
                t = next(it, None)
            if t is None:
                return
            lib.pd_spec_run_task(sp, t, res[t], err)
            if res[t].status:
                with lock:
                    msgs[t] = err_text(err)

    if sp.opts.method == 2 and ntasks:
        # the penalty runs turn GSL's process-wide error handler off: once, before the threads
        first = next(it)
        err = PdErr()
        lib.pd_spec_run_task(sp, first, res[first], err)
        if res[first].status:
            msgs[first] = err_text(err)
    if threads == 1:
        work()
    else:
        pool = [threading.Thread(target=work, daemon=True) for _ in range(threads)]
        for th in pool:
            th.start()
        for th in pool:
            th.join()
    if msgs:
        bad = min(msgs)
        raise _lib.make_error(res[bad].status, msgs[bad])
    return res


def sweep_rows(sp, on_point=None):
    """Every point of the sweep through pd_spec_sweep (serial, in order; the
    numbers of pd_spec_run_task and pd_spec_rows), on_point(point) called
    as each completes (a truthy return stops the sweep: PD_ESTOPPED)."""
    npoints, npi2 = lib.pd_spec_points(sp), sp.npi2
    rows = (_lib.PdSpecRow * npoints)()
    size = ctypes.sizeof(_lib.PdSpecRow)
    method = s(lib.pd_method_name(sp.opts.method))
    failure = []

    def point(co_p, row_p, ctx):
        try:
            co = _lib.PdSpecCoords.from_address(co_p)
            p = co.curve * npi2 + co.j
            ctypes.memmove(ctypes.byref(rows, p * size), row_p, size)
            if on_point is not None and on_point(_point(rows[p], method)):
                return 1
            return 0
        except BaseException as e:  # stop the sweep; raised once it returns
            failure.append(e)
            return 1
    fn = _lib.SpecPointFn(point)
    err = PdErr()
    st = lib.pd_spec_sweep(sp, fn, None, err)
    if failure:
        raise failure[0]
    _lib.check(st, err)
    return rows


def _point(r, method):
    """A pd_spec_row as the CLI's JSON point."""
    c = r.c
    p = _elastic_point(r, method)
    if lib.pd_osc_yields(c):  # a yielding sweep's, as the CLI's JSON
        p.update(Piy=c.Piy, alpha=c.alpha, uy=lib.pd_osc_uy(c), ductility=r.ductility,
                 ductility_free=r.ductility_free, residual_uy=r.residual_uy)
    return p


def _elastic_point(r, method):
    c = r.c
    return Result(
        pulse=s(lib.pd_osc_excitation_name(c)), dir=s(lib.pd_dir_name(c.dir)), Pi2=c.Pi2,
        Pi3=c.Pi3, eps=c.eps, xi=c.xi, Pi1=r.Pi1, umax_free=r.umax_free, gamma=r.gamma,
        chi=r.chi, impacts=r.impacts, method=method, curve=r.curve, umax=r.umax,
        u_toward=r.u_toward, u_away=r.u_away, contact_time=r.contact_time,
        first_impact=r.first_impact, ap=c.ap, Tp=c.Tp, T0=r.T0, gap=r.gap, dt=r.dt,
        tend=r.tend, steps=r.steps, cpu_s=r.cpu_s)


def spectrum(Pi2: Range, linear: bool = False,
             pulse: Optional[Names] = None,
             dir: Optional[Union[Names, int, Sequence[int]]] = None, ap: Optional[Floats] = None,
             xi: Optional[Floats] = None, Pi3: Optional[Floats] = None,
             gap: Optional[Floats] = None, eps: Optional[Floats] = None,
             dt_per_Tp: Optional[float] = None, threads: Optional[Int] = None,
             on_point: Optional[Callable[[Result], Any]] = None, **case: Any) -> Result:
    """Pounding spectra, as `pound spectrum --Pi2 MIN:MAX:N ... --json`.

    Pi2: the tuple (MIN, MAX, N) or 'MIN:MAX:N', log-spaced (linear=True: equal
    steps); a list is refused (it would read as values).
    Lists (a value or a sequence; one curve per combination): pulse, dir,
    ap [m/s^2] (the dimensional view), xi, Pi3 or gap [m], eps.  dt_per_Tp:
    steps per pulse period (dt = Tp / dt_per_Tp [s]).  Other keywords as
    for simulate(): Tp, record, scale, units, method, dt (or dt_per_Tp),
    tend, theta, ...; rtol only with method='penalty' (its integrator's
    tolerance): a spectrum runs Moreau-Jean on fixed steps, and rtol for
    Moreau-Jean raises InputError.

    threads: runs at once [OMP_NUM_THREADS or all cores]; the tasks go to a
    pool of threads (pd_spec_run_task), or with threads=1 or on_point to
    the library's serial sweep pd_spec_sweep when the library has it;
    on_point(point) is then called as each point completes (a truthy return
    stops the sweep: PoundError PD_ESTOPPED).  The numbers are the same
    either way, and the CLI's.

    Returns a Result: Pi2 (N,), the arrays of shape (curves, N) Pi1 =
    umax / Le, gamma, chi (dimensionless), umax, umax_free, u_toward, u_away,
    gap [m], contact_time, first_impact, T0, dt, tend [s], impacts, steps
    (counts), curves (a dict per curve: pulse, dir,
    ap, xi, Pi3 or gap, eps, label), points (the CLI's JSON points), runs,
    twins."""
    sp, k = build(Pi2, linear, pulse, dir, ap, xi, Pi3, gap, eps, dt_per_Tp, **case)
    npoints, npi2, ncurves = lib.pd_spec_points(sp), sp.npi2, lib.pd_spec_curves(sp)
    method = s(lib.pd_method_name(sp.opts.method))
    serial = threads is not None and _threads(threads) == 1
    if hasattr(lib, "pd_spec_sweep") and (serial or on_point is not None):
        rows = sweep_rows(sp, on_point)
    elif on_point is not None:
        raise InputError("on_point: this libpound has no pd_spec_sweep")
    else:
        res = run_tasks(sp, threads)
        rows = (_lib.PdSpecRow * npoints)()
        lib.pd_spec_rows(sp, res, rows)
    points = [_point(r, method) for r in rows]
    out = Result(Pi2=np.array([lib.pd_spec_pi2(sp, j) for j in range(npi2)]))
    keys = ARRAY_KEYS + (YIELD_KEYS if lib.pd_osc_yields(sp.base) else ())
    for key in keys:
        dtype = np.int64 if key in ("impacts", "steps") else np.float64
        out[key] = np.array([p[key] for p in points], dtype=dtype).reshape(ncurves, npi2)
    curves = []
    label = ctypes.create_string_buffer(256)
    for cv in range(ncurves):
        p = points[cv * npi2]
        lib.pd_spec_curve_label(sp, cv, label, 256)
        d = Result(pulse=p["pulse"], dir=p["dir"], ap=p["ap"], xi=p["xi"], eps=p["eps"])
        if sp.size_is_gap:
            d["gap"] = p["gap"]
        else:
            d["Pi3"] = p["Pi3"]
        d["label"] = label.value.decode()
        curves.append(d)
    out.update(curves=curves, points=points, method=method, method_by=k.method_by,
               runs=lib.pd_spec_tasks(sp),
               twins=lib.pd_spec_twins(sp))
    return out
