"""Linear complementarity problems (`pound lcp`) and records (`pound record`)."""
import ctypes
import time
from typing import Any, Optional, Tuple

import numpy as np

from . import _args, _lib
from ._case import InputError, Record, parse_name
from ._lib import PdErr, PdMatrix, err_text, lib, s
from ._osc import Result
from ._types import ArrayLike, Int, PathArg

_libc = ctypes.CDLL(None)
_libc.free.argtypes = [ctypes.c_void_p]
_libc.free.restype = None

_FORMATS = {"auto": 0, "plain": 1, "siconos": 2}
_DPTR = ctypes.POINTER(ctypes.c_double)
PD_LCP_LEMKE_NMAX = 2048  # lcp/pd_lcp.h


def read_lcp(path: PathArg, format: str = "auto") -> Tuple[np.ndarray, np.ndarray]:
    """Read an LCP file (plain: n, M row by row, q; or Siconos): (M, q) as
    NumPy arrays (pd_lcp_read)."""
    fmt_code = _FORMATS[_args.choice("format", format, _FORMATS)]
    cpath, _ = _args.path("read_lcp", path)
    n, M, q = ctypes.c_int(), _DPTR(), _DPTR()
    err = PdErr()
    _lib.check(lib.pd_lcp_read(cpath, fmt_code, ctypes.byref(n),
                               ctypes.byref(M), ctypes.byref(q), err), err)
    try:
        nn = n.value
        Ma = np.ctypeslib.as_array(M, (nn * nn,)).reshape((nn, nn), order="F").copy()
        qa = np.ctypeslib.as_array(q, (nn,)).copy()
    finally:
        _libc.free(ctypes.cast(M, ctypes.c_void_p))
        _libc.free(ctypes.cast(q, ctypes.c_void_p))
    return Ma, qa


def lcp(M: Any, q: ArrayLike, solver: str = "auto", cover: Optional[ArrayLike] = None,
        max_pivots: Int = 0, max_iterations: Int = 0, tol: Optional[float] = None) -> Result:
    """Solve z >= 0, w = M z + q >= 0, z'w = 0 with a solver of the table
    (pd_lcp_solve), as `pound lcp FILE --json`: a Result with status
    ('solved', 'no_solution', 'max_pivots', 'numerical', 'max_iterations'),
    solver, n, z, w, pivots, iterations, residual, complementarity,
    infeasibility, scale, cpu_s.  An unsolved problem is a status, not an
    exception; bad input raises InputError.

    M: a square array (dense), or a SciPy sparse matrix (compressed columns);
    solver: 'auto', 'lemke', 'structured', 'pgs'; cover: Lemke's covering
    vector (one value or n); max_pivots, max_iterations: the budgets (0:
    from n); tol: the solver's tolerance (in (0, 1e-3)).  The problem is
    dimensionless (z, w in the units of q; cpu_s in s of CPU).  M, q and
    cover must be finite: the library refuses what is
    not (PD_EINVAL without a message), so they are checked here first."""
    method = parse_name("solver", lib.pd_lcp_method_parse, solver,
                        s(lib.pd_lcp_method_list()))
    keep = []
    if hasattr(M, "tocsc"):
        A = M.tocsc()
        A.sort_indices()
        n = A.shape[0]
        if A.shape != (n, n) or n < 1:
            raise InputError("M: must be square (got %dx%d)" % A.shape)
        vals = np.ascontiguousarray(_args.real_array("M", A.data, finite=False).reshape(-1))
        colptr = np.ascontiguousarray(A.indptr, dtype=np.int32)
        rowind = np.ascontiguousarray(A.indices, dtype=np.int32)
        _args.nonfinite_at("M", vals, lambda k: (int(rowind[k]), int(
            np.searchsorted(colptr, k, side="right") - 1)))
        keep += [vals, colptr, rowind]
        mat = PdMatrix(kind=2, rows=n, cols=n, values=vals.ctypes.data_as(_DPTR),
                       colptr=colptr.ctypes.data_as(ctypes.POINTER(ctypes.c_int)),
                       rowind=rowind.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
        nnz = len(vals) + 1
    else:
        A = _args.real_array("M", M)
        if A.ndim != 2 or A.shape[0] != A.shape[1] or A.shape[0] < 1:
            raise InputError("M: must be a square matrix (got shape %s)" % (A.shape,))
        n = A.shape[0]
        vals = np.asfortranarray(A)
        keep.append(vals)
        mat = PdMatrix(kind=1, rows=n, cols=n, values=vals.ctypes.data_as(_DPTR))
        nnz = 0
    qa = np.ascontiguousarray(_args.real_array("q", q)).reshape(-1)
    if qa.shape != (n,):
        raise InputError("q: expected %d entries (got %d)" % (n, qa.size))
    # the options before the solver is allocated (nothing to free on a refusal)
    opts = _lib.default_lcp_opts()
    if cover is not None:
        cv = np.atleast_1d(_args.real_array("cover", cover)).reshape(-1)
        if cv.size == 1:
            cv = np.full(n, cv[0])
        if cv.shape != (n,) or not np.all(cv > 0):
            raise InputError("cover: expected 1 or n = %d positive values" % n)
        keep.append(cv)
        opts.cover = cv.ctypes.data_as(_DPTR)
    for key, v in (("max_pivots", max_pivots), ("max_iterations", max_iterations)):
        k = _args.integer(key, v)
        if k < 0:
            raise InputError("%s: must be >= 0 (got %d)" % (key, k))
        setattr(opts, key, k)
    if tol is not None:
        tolv = _args.number("tol", tol)
        if not 0.0 < tolv < 1e-3:
            raise InputError("tol: must lie in (0, 1e-3), got %g" % tolv)
        opts.tol = tolv
    err = PdErr()
    solver_p = lib.pd_lcp_solver_alloc(method, n, nnz, err)
    if not solver_p:
        raise _lib.make_error(err.status or _lib.PD_ENOMEM, err_text(err))
    z, w = np.zeros(n), np.zeros(n)
    info = _lib.PdLcpInfo()
    try:
        t0 = time.thread_time()
        st = lib.pd_lcp_solve(solver_p, mat, qa.ctypes.data_as(_DPTR), opts,
                              z.ctypes.data_as(_DPTR), w.ctypes.data_as(_DPTR), info)
        cpu = time.thread_time() - t0
    finally:
        lib.pd_lcp_solver_free(solver_p)
    if st == _lib.PD_EINVAL:
        # pd_lcp_solve refuses without a message; everything else it refuses was
        # checked above (finite M, q and cover > 0, budgets >= 0, tol), so what is left
        # is the size, as in the CLI (whose reader refuses non-finite data)
        name = s(lib.pd_lcp_method_name(method))
        if n > PD_LCP_LEMKE_NMAX:
            raise InputError("lcp: n = %d is more than the %s solver takes (Lemke: at most "
                             "%d unknowns)" % (n, name, PD_LCP_LEMKE_NMAX))
        raise InputError("lcp: the %s solver refused the problem (PD_EINVAL, n = %d)"
                         % (name, n))
    return Result(status=s(lib.pd_lcp_outcome_name(info.outcome)), solver=s(info.solver), n=n,
                  z=z, w=w, pivots=info.pivots, iterations=info.iterations,
                  residual=info.residual, complementarity=info.complementarity,
                  infeasibility=info.infeasibility, scale=info.scale, cpu_s=cpu,
                  solved=(st == 0))


def record(path: PathArg, units: Optional[str] = None, format: str = "auto") -> Result:
    """A strong-motion record's measures and fitted pulse, as `pound record F
    --json` (units: of a two-column text file ['g']; refused for AT2 and V2,
    which state theirs): name, npts, dt [s], duration [s], pga [m/s^2], pgv
    [m/s], pgd [m], t_pga, t_pgv, t_pgd [s], arias [m/s], t5_75, t5_95 [s],
    pulse {Tp [s], vp [m/s], ap [m/s^2], wp [rad/s], Le [m], fp [Hz], nu,
    gamma, t0 [s], r2, shape, t_start [s]}, with the arrays t, acc [m/s^2], vel [m/s], disp [m]
    (pd_record_integrate) and pulse_acc (the paper's one-cycle pulse)."""
    r = Record(path, units, format)
    try:
        rec, p = r.rec, r.pulse
        m = _lib.PdRecordMeasures()
        err = PdErr()
        _lib.check(lib.pd_record_measure(rec, m, err), err)
        out = Result(name=r.name, npts=rec.npts, dt=rec.dt,
                     duration=lib.pd_record_duration(rec))
        for k, _ in _lib.PdRecordMeasures._fields_:
            out[k] = getattr(m, k)
        # the CLI's key order
        out = Result((k, out[k]) for k in ("name", "npts", "dt", "duration", "pga", "pgv",
                                            "pgd", "t_pga", "t_pgv", "t_pgd", "arias",
                                            "t5_75", "t5_95"))
        out["pulse"] = Result(Tp=p.Tp, vp=p.vp, ap=p.ap, wp=p.wp, Le=p.Le, fp=p.fp, nu=p.nu,
                              gamma=p.gamma, t0=p.t0, r2=p.r2, shape=s(lib.pd_pulse_name(p.shape)),
                              t_start=p.t_start, polarity=p.polarity, iterations=p.iterations)
        n = rec.npts
        vel, disp = np.zeros(n), np.zeros(n)
        _lib.check(lib.pd_record_integrate(rec, vel.ctypes.data_as(_DPTR),
                                           disp.ctypes.data_as(_DPTR), err), err)
        out["t"] = np.arange(n) * rec.dt
        out["acc"] = r.acc
        out["vel"], out["disp"] = vel, disp
        out["pulse_acc"] = np.array([lib.pd_record_one_cycle(p, t) for t in out["t"]])
        return out
    finally:
        r.close()
