"""Pounding response spectra in Pi terms, as `pound spectrum --json`
computes them: the sweep of pd_spectrum, one library call per task
(pd_spec_run_task) on a pool of threads (ctypes lets go of the GIL during
the call; every task writes its own slot, so the numbers never depend on
the threads), the points from pd_spec_rows."""
import ctypes
import os
import threading
import warnings
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from . import _args, _lib
from ._case import (CASE_KEYS, PD_METHOD_AUTO, Case, InputError, implied_method, number,
                    parse_dir, parse_name)
from ._lib import PD_SPEC_MAX_LIST, PdErr, PoundError, err_text, lib, s
from ._osc import Result
from ._types import Floats, Int, Names, Range

# the keywords a spectrum takes besides its lists (no T0, Pi2, no_wall: it sweeps Pi2 and
# runs the no-wall twins itself)
_CASE = tuple(k for k in CASE_KEYS if k not in ("T0", "Pi2", "no_wall", "pulse", "dir", "ap",
                                                "gap", "Pi3", "eps", "xi"))
PD_SPEC_MAX_TASKS = 2000000
PD_METHOD_MOREAU = 0  # pd_method

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


def _range(what, r, T0=False):
    """A range (MIN, MAX, N) or the CLI's text 'MIN:MAX:N', checked as
    cmd_spectrum.c checks --Pi2 (T0: a suite's --T0 axis, 2 <= N): (MIN, MAX, N)."""
    if isinstance(r, str):
        parts = r.split(":")
        if len(parts) != 3:
            raise InputError("%s: give MIN:MAX:N (got '%s')" % (what, r))
    elif isinstance(r, (tuple, list, np.ndarray)) and len(r) == 3:
        parts = list(r)
    else:
        raise InputError("%s: give the range (MIN, MAX, N) or 'MIN:MAX:N' (got %r)" % (what, r))
    lo, hi = _args.number(what, parts[0], "MIN ="), _args.number(what, parts[1], "MAX =")
    n = _args.integer(what, parts[2], "N =")
    if T0:
        if not (0.0 < lo < hi) or n < 2 or n > 1000000:
            raise InputError("%s: need 0 < MIN < MAX and 2 <= N <= 1e6 (got %g:%g:%d)"
                             % (what, lo, hi, n))
    elif not lo > 0.0 or n < 1 or n > 1000000 or (hi != lo if n == 1 else not hi > lo):
        raise InputError("%s: need 0 < MIN < MAX and 2 <= N <= 1e6, or MIN = MAX with N = 1 "
                         "(got %g:%g:%d)" % (what, lo, hi, n))
    return lo, hi, n


def _values(Pi2, stacklevel):
    """Explicit Pi2 values (a value, a list, tuple or array): each > 0.  A
    3-tuple ending in an integer, the range form of older versions, is read as
    values too, with a warning naming Pi2_range."""
    if isinstance(Pi2, tuple) and len(Pi2) == 3 and isinstance(Pi2[2], (int, np.integer)) \
            and not _args.is_bool(Pi2[2]):
        warnings.warn("Pi2=%r is read as the three Pi2 values %s (a range of N values is "
                      "Pi2_range=(MIN, MAX, N) or Pi2='MIN:MAX:N'; a list of values does not "
                      "warn)" % (Pi2, ", ".join("%g" % _args.number("Pi2", v) for v in Pi2)),
                      UserWarning, stacklevel=stacklevel)
    vals = [_args.number("Pi2", v) for v in _args.values("Pi2", Pi2, 1000000)]
    for v in vals:
        if not v > 0.0:
            raise InputError("Pi2: the values must be > 0 (got %g)" % v)
    return vals


def axis_of(Pi2, Pi2_range, T0_range, linear, suite, stacklevel=4):
    """The sweep's axis: ('Pi2', (MIN, MAX, N)) for a range, ('values', [Pi2
    ...]) for explicit values, ('T0', (MIN, MAX, N)) for a suite against the
    period; the CLI's refusals (stacklevel: the user's frame, for a warning)."""
    given = [k for k, v in (("Pi2", Pi2), ("Pi2_range", Pi2_range), ("T0_range", T0_range))
             if v is not None]
    if len(given) > 1:
        raise InputError("%s and %s are alternatives: give one" % (given[0], given[1]))
    if not given:
        raise TypeError("spectrum: give Pi2 (values), Pi2_range=(MIN, MAX, N)%s"
                        % (" or T0_range=(MIN, MAX, N)" if suite else ""))
    if T0_range is not None:
        if not suite:
            raise InputError("T0_range: the axis of a suite's spectrum (records=); one record "
                             "or a pulse: Pi2 or Pi2_range")
        if _args.flag("linear", linear):
            raise InputError("linear: a suite's T0_range axis is log-spaced")
        return "T0", _range("T0_range", T0_range, T0=True)
    if Pi2_range is not None:
        return "Pi2", _range("Pi2_range", Pi2_range)
    if isinstance(Pi2, str):  # the CLI's text MIN:MAX:N
        return "Pi2", _range("Pi2", Pi2)
    if isinstance(Pi2, bytes):
        raise InputError("Pi2: give values, Pi2_range=(MIN, MAX, N) or 'MIN:MAX:N' (got %r)"
                         % (Pi2,))
    if _args.flag("linear", linear):
        raise InputError("linear: the spacing of Pi2_range (explicit Pi2 values are taken as "
                         "given)")
    return "values", _values(Pi2, stacklevel)


def build(grid, linear=False, pulse=None, dir=None, ap=None, xi=None, Pi3=None, gap=None,
          eps=None, dt_per_Tp=None, **case):
    """The pd_spectrum of the keywords on the grid (MIN, MAX, N), checked as
    cmd_spectrum.c checks its flags; (spectrum, case) (the case owns a
    record).  Its method is not resolved yet (k.method_in: the method given or
    implied, else auto): finish() resolves it and checks every point."""
    unknown = sorted(set(case) - set(_CASE))
    if unknown:
        raise TypeError("unexpected keyword argument(s) %s" % ", ".join(unknown))
    sp = _lib.PdSpectrum()
    lib.pd_spec_init(sp)
    sp.pi2_min, sp.pi2_max, sp.npi2 = grid
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
    # the method given or implied (dt_per_Tp too), else one for the sweep (finish)
    m, key = implied_method(dict(case, dt_per_Tp=dt_per_Tp))
    by = k.have["method_by"]
    if by is None and m is not None:
        sp.opts.method, by = m, "--" + key.replace("_", "-")
    if by is None:
        sp.opts.method = PD_METHOD_AUTO
    k.method_by = by or "default"
    k.method_in = sp.opts.method
    return sp, k


def on_values(sp, values):
    """One sweep per explicit Pi2 value (its grid v:v:1, the CLI's route for
    one value): copies of sp."""
    out = []
    for v in values:
        one = _lib.PdSpectrum.from_buffer_copy(sp)
        one.pi2_min = one.pi2_max = v
        one.npi2 = 1
        out.append(one)
    return out


def finish(sps, method_in, where=None):
    """The method of sweeps that make one spectrum (the sweeps of its explicit
    values), resolved as pd_spec_resolve_method resolves one sweep over all
    their points: the exact event-driven reference when every point's scan
    fits, else Moreau-Jean for all; then every point checked (where: the
    record's name, prefixed to a refusal)."""
    for sp in sps:
        sp.opts.method = method_in
        lib.pd_spec_resolve_method(sp)
    methods = set(sp.opts.method for sp in sps)
    if len(methods) > 1:  # some points over the reference's budget: Moreau-Jean for all
        for sp in sps:
            sp.opts.method = PD_METHOD_MOREAU
    err = PdErr()
    for sp in sps:
        st = lib.pd_spec_validate(sp, err)
        if st != 0:
            msg = err_text(err)
            raise _lib.make_error(st, "%s: %s" % (where, msg) if where else msg)


def _threads(threads):
    if threads is None:
        threads = int(os.environ.get("OMP_NUM_THREADS", "0") or 0) or os.cpu_count() or 1
    threads = _args.integer("threads", threads)
    if not 1 <= threads <= 4096:
        raise InputError("threads: must be in [1, 4096] (got %d)" % threads)
    return threads


def run_tasks(sps, threads=None, names=None):
    """Every task of the sweeps into its slot, on one pool of threads (one
    result array per sweep); the lowest failed task (sweep, task) raises,
    prefixed with names[sweep] when given."""
    res = [(_lib.PdSpecResult * lib.pd_spec_tasks(sp))() for sp in sps]
    jobs = [(i, t) for i, sp in enumerate(sps) for t in range(lib.pd_spec_tasks(sp))]
    # costliest first, so that the last tasks are short (as the CLI orders them)
    order = sorted(jobs, key=lambda j: (-lib.pd_spec_cost(sps[j[0]], j[1]), j))
    threads = min(_threads(threads), max(1, len(jobs)))
    msgs = {}
    lock = threading.Lock()
    it = iter(order)

    def one(job, err):
        i, t = job
        lib.pd_spec_run_task(sps[i], t, res[i][t], err)
        if res[i][t].status:
            with lock:
                msgs[job] = err_text(err)

    def work():
        err = PdErr()
        while True:
            with lock:
                job = next(it, None)
            if job is None:
                return
            one(job, err)

    if jobs and sps[0].opts.method == 2:
        # the penalty runs turn GSL's process-wide error handler off: once, before the threads
        one(next(it), PdErr())
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
        msg = msgs[bad] if names is None else "%s: %s" % (names[bad[0]], msgs[bad])
        raise _lib.make_error(res[bad[0]][bad[1]].status, msg)
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


def _rows(sps, threads, on_point, names=None):
    """The rows of each sweep: the library's serial sweep (on_point called as
    each point completes) with threads=1 or on_point, else the tasks on a
    pool of threads and pd_spec_rows."""
    serial = threads is not None and _threads(threads) == 1
    if hasattr(lib, "pd_spec_sweep") and (serial or on_point is not None):
        out = []
        for i, sp in enumerate(sps):
            try:
                out.append(sweep_rows(sp, on_point))
            except PoundError as e:
                if names is None:
                    raise
                raise _lib.make_error(e.status, "%s: %s" % (names[i], e.message)) from None
        return out
    if on_point is not None:
        raise InputError("on_point: this libpound has no pd_spec_sweep")
    res = run_tasks(sps, threads, names)
    out = []
    for sp, r in zip(sps, res):
        rows = (_lib.PdSpecRow * lib.pd_spec_points(sp))()
        lib.pd_spec_rows(sp, r, rows)
        out.append(rows)
    return out


def _merged(sps, rows):
    """The rows of one spectrum from its sweeps' (one sweep, or one per
    explicit value): point p = curve * N + j, as a sweep orders them."""
    if len(sps) == 1:
        return list(rows[0])
    ncurves = lib.pd_spec_curves(sps[0])
    return [rows[j][cv] for cv in range(ncurves) for j in range(len(sps))]


def _result(sps, k, rows, pi2):
    """A spectrum's Result from its sweeps (one, or one per explicit Pi2
    value) and their merged rows."""
    sp = sps[0]
    method = s(lib.pd_method_name(sp.opts.method))
    npi2, ncurves = len(pi2), lib.pd_spec_curves(sp)
    points = [_point(r, method) for r in rows]
    out = Result(Pi2=np.array(pi2, dtype=np.float64))
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
               runs=sum(lib.pd_spec_tasks(x) for x in sps),
               twins=sum(lib.pd_spec_twins(x) for x in sps))
    return out


def _check_tasks(sps):
    n = sum(lib.pd_spec_tasks(sp) for sp in sps)
    if n > PD_SPEC_MAX_TASKS:
        raise InputError("Pi2: %d runs in this sweep, at most %d" % (n, PD_SPEC_MAX_TASKS))


def spectrum(Pi2: Optional[Union[Floats, str]] = None, linear: bool = False,
             pulse: Optional[Names] = None,
             dir: Optional[Union[Names, int, Sequence[int]]] = None, ap: Optional[Floats] = None,
             xi: Optional[Floats] = None, Pi3: Optional[Floats] = None,
             gap: Optional[Floats] = None, eps: Optional[Floats] = None,
             dt_per_Tp: Optional[float] = None, threads: Optional[Int] = None,
             on_point: Optional[Callable[[Result], Any]] = None,
             Pi2_range: Optional[Range] = None, records: Optional[Any] = None,
             T0_range: Optional[Range] = None, **case: Any) -> Result:
    """Pounding spectra, as `pound spectrum --Pi2 MIN:MAX:N ... --json`.

    The Pi2 axis, one of: Pi2, explicit values (a value, or a list, tuple or
    array of them: each point at that Pi2 exactly, as `--Pi2 X:X:1` runs
    it; a tuple of three is three values, never a range); Pi2_range, the
    range (MIN, MAX, N) or 'MIN:MAX:N' (the CLI's --Pi2 MIN:MAX:N: N values,
    log-spaced, linear=True: equal steps; the text 'MIN:MAX:N' given as Pi2
    is that range too); with records, T0_range=(MIN, MAX, N) or 'MIN:MAX:N'
    [s] (the CLI's --T0 MIN:MAX:N: every record at the same periods, Pi2 =
    its Tp / T0, log-spaced).
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
    stops the sweep: PoundError PD_ESTOPPED; explicit values run one after
    the other, each point's curves in turn).  The numbers are the same
    either way, and the CLI's.

    Returns a Result: Pi2 (N,), the arrays of shape (curves, N) Pi1 =
    umax / Le, gamma, chi (dimensionless), umax, umax_free, u_toward, u_away,
    gap [m], contact_time, first_impact, T0, dt, tend [s], impacts, steps
    (counts), curves (a dict per curve: pulse, dir,
    ap, xi, Pi3 or gap, eps, label), points (the CLI's JSON points), runs,
    twins.

    records: a suite, as `pound spectrum --records FILE --json`: a suite
    file (one record a line, PATH [SCALE]) or a list of records (files,
    pound.Records, pound.record()'s Results or arrays with record_dt, as
    `--record` given for each); scale multiplies every record's, or
    target_pga=A or target_sa=A [m/s^2] (with T1 [s]) scales each to that
    PGA or 5 %-damped Sa(T1).  Returns a Result with the CLI's keys: suite
    (the file, or '--record'), n, axis ('Pi2' or 'T0'), records (per
    record: record, scale, Tp [s], ap [m/s^2], method, points, and the
    arrays and curves of its spectrum as above), stats (per point: curve,
    Pi2 or T0 [s], Pi3 or gap [m], eps, and the suite's n, mean, median,
    p16, p84, min, max of Pi1, gamma and umax [m]); curves; and Pi2 (N,)
    or T0 (N,) [s], the axis."""
    lists = (linear, pulse, dir, ap, xi, Pi3, gap, eps, dt_per_Tp)
    if "T0" in case:
        raise InputError("T0: a spectrum sweeps Pi2 = Tp / T0 (Pi2 or Pi2_range); a suite "
                         "against the period: records=..., T0_range=(MIN, MAX, N)")
    if records is not None:
        return _suite(records, Pi2, Pi2_range, T0_range, lists, threads, on_point, case)
    if any(key in case for key in _SUITE_KEYS):
        raise InputError("%s: scales a suite's records (records=)"
                         % next(key for key in _SUITE_KEYS if key in case))
    kind, axis = axis_of(Pi2, Pi2_range, T0_range, linear, False)
    if kind == "values":
        sp, k = build((axis[0], axis[0], 1), *lists, **case)
        sps = on_values(sp, axis)
    else:
        sp, k = build(axis, *lists, **case)
        sps = [sp]
    _check_tasks(sps)
    finish(sps, k.method_in)
    rows = _merged(sps, _rows(sps, threads, on_point))
    pi2 = axis if kind == "values" else [lib.pd_spec_pi2(sp, j) for j in range(sp.npi2)]
    return _result(sps, k, rows, pi2)


# ---- suites of records (cli/cmd_spectrum.c suite_sweep) ---------------------------------------

_SUITE_KEYS = ("target_pga", "target_sa", "T1")


class _PdSuite(ctypes.Structure):
    """pd_suite (problems/pd_problems.h): the records of a suite file."""
    _fields_ = [("n", ctypes.c_int), ("cap", ctypes.c_int),
                ("path", ctypes.POINTER(ctypes.c_char_p)),
                ("scale", ctypes.POINTER(ctypes.c_double))]


def _suite_file(path):
    """The records of a suite file (pd_suite_read: PATH [SCALE] a line, a
    relative PATH from the file's folder): [(path, scale)]."""
    read, free = lib["pd_suite_read"], lib["pd_suite_free"]
    read.restype, free.restype = ctypes.c_int, None
    read.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.POINTER(_PdSuite)),
                     ctypes.POINTER(PdErr)]
    free.argtypes = [ctypes.POINTER(_PdSuite)]
    cpath, _ = _args.path("records", path)
    out, err = ctypes.POINTER(_PdSuite)(), PdErr()
    st = read(cpath, ctypes.byref(out), err)
    if st != 0:
        raise _lib.make_error(st, "records: %s" % err_text(err))
    try:
        su = out.contents
        return [(su.path[k].decode("utf-8", "surrogateescape"), su.scale[k])
                for k in range(su.n)]
    finally:
        free(out)


def _suite_scales(items, case):
    """The suite's records and each one's scale (cli/case.c case_records:
    scale times the suite file's, or the target's factor)."""
    from ._osc import _suite_record, suite_target
    kind, value, T1, name = suite_target(case)
    base = number("scale", case.get("scale", 1.0))
    if not base > 0.0:
        raise InputError("scale: must be > 0 (got %g)" % base)
    recs, scales = [], []
    for item, factor in items:
        if kind and factor != 1.0:
            raise InputError("%s: the suite gives %s a scale (%g); with a target the target "
                             "scales every record" % (name, item, factor))
        rec = _suite_record(item, case)
        scale = ctypes.c_double(base * factor)
        if kind:
            err = PdErr()
            st = lib.pd_record_scale_to(rec.rec, rec.pulse, kind, value, T1 or 0.0, 0.05, scale,
                                        err)
            if st != 0:
                raise _lib.make_error(st, "%s: %s" % (name, err_text(err)))
        recs.append(rec)
        scales.append(scale.value)
    return recs, scales


def _suite(records, Pi2, Pi2_range, T0_range, lists, threads, on_point, case):
    """spectrum(records=...): each record's sweep (cmd_spectrum.c
    suite_spectrum) and the suite's statistics at every point (pd_stats_of)."""
    from ._osc import stats_of
    if case.get("record") is not None:
        raise InputError("records and record: give the suite one way")
    kind, axis = axis_of(Pi2, Pi2_range, T0_range, lists[0], True, stacklevel=5)
    if isinstance(records, (str, bytes, os.PathLike)):
        items, name = _suite_file(records), os.fsdecode(records)
    elif isinstance(records, (list, tuple)) and records:
        items, name = [(item, 1.0) for item in records], "--record"
    else:
        raise InputError("records: a suite file, or a list of record files, pound.Records, "
                         "pound.record() Results or arrays (with record_dt)")
    case = dict(case)
    recs, scales = _suite_scales(items, case)
    run = {key: v for key, v in case.items() if key not in ("units", "record_format",
                                                             "record_dt", "scale")}
    # the sweep on the first record (its flags checked), then each record's copy of it
    first = recs[0].pulse.Tp
    grid = ((axis[0], axis[0], 1) if kind == "values" else
            (first / axis[1], first / axis[0], axis[2]) if kind == "T0" else axis)
    sp0, k = build(grid, *lists, record=recs[0], scale=scales[0], **run)
    blocks, names = [], []
    for rec, scale in zip(recs, scales):
        sp = _lib.PdSpectrum.from_buffer_copy(sp0)
        lib.pd_osc_set_record(sp.base, rec.rec, rec.pulse, scale)
        if not sp.dimensional:
            sp.ap[0] = sp.base.ap
        if kind == "T0":  # log-spaced in T0 = log-spaced in Pi2, the same N
            sp.pi2_min, sp.pi2_max = sp.base.Tp / axis[1], sp.base.Tp / axis[0]
        sps = on_values(sp, axis) if kind == "values" else [sp]
        finish(sps, k.method_in, rec.name)
        blocks.append(sps)
        names += [rec.name] * len(sps)
    _check_tasks([sp for sps in blocks for sp in sps])
    flat = _rows([sp for sps in blocks for sp in sps], threads, on_point, names)
    entries, first_rows, at = [], None, 0
    for sps, rec, scale in zip(blocks, recs, scales):
        rows = _merged(sps, flat[at:at + len(sps)])
        at += len(sps)
        first_rows = rows if first_rows is None else first_rows
        pi2 = axis if kind == "values" else [lib.pd_spec_pi2(sps[0], j)
                                             for j in range(sps[0].npi2)]
        one = _result(sps, k, rows, pi2)
        entry = Result(record=rec.name, scale=scale, Tp=sps[0].base.Tp, ap=sps[0].base.ap,
                       method=one.method, points=one.points)
        entry.update((key, v) for key, v in one.items() if key not in entry)
        entries.append(entry)
    # the CLI's statistics at each point, named by the first record's row
    gap_key = "Pi3" if k.c.Pi3 >= 0.0 and not sp0.size_is_gap else "gap"
    stats = []
    for p, r in enumerate(first_rows):
        st = Result(curve=r.curve)
        if kind == "T0":
            st["T0"] = r.T0
        else:
            st["Pi2"] = r.c.Pi2
        st[gap_key] = r.gap if sp0.size_is_gap else r.c.Pi3
        st["eps"] = r.c.eps
        for fig in ("Pi1", "gamma", "umax"):
            st[fig] = stats_of([e.points[p][fig] for e in entries])
        stats.append(st)
    out = Result(suite=name, n=len(entries), axis="T0" if kind == "T0" else "Pi2",
                 records=entries, stats=stats, curves=entries[0].curves,
                 method_by=k.method_by, runs=sum(e.runs for e in entries))
    if kind == "T0":
        out["T0"] = entries[0].T0[0].copy()
    else:
        out["Pi2"] = entries[0].Pi2.copy()
    return out
