"""libpound through ctypes: finding the library, the mirrors of its public
structs (generated from the headers: _structs.py), the prototypes of the
functions used, errors, and the layout check run at import.

Only functions declared in the four public headers (core/pd_core.h,
lcp/pd_lcp.h, engine/pd_engine.h, problems/pd_problems.h) are used: they are
the ones libpound.so exports.
"""
import ctypes
import math
import os
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char_p, c_double, c_int, c_long, c_ubyte,
                    c_void_p)
from typing import List, Optional, Tuple

# The mirrors of the public structs, generated from the headers by
# scripts/gen_py_structs.py (the other modules take them from here).
from ._structs import (PD_SPEC_MAX_LIST, PD_WALL, PdContact, PdEnergy, PdErr, PdLcpInfo,  # noqa: F401
                       PdLcpOpts, PdMatrix, PdMeasured, PdOsc, PdOscResult, PdOscSample,
                       PdOscSummary, PdPenaltySetup, PdRecord, PdRecordMeasures, PdRecordPulse,
                       PdRunOpts, PdScene, PdSceneErrors, PdSceneExcitation, PdSceneResult,
                       PdSceneSample, PdSceneSuite, PdSceneSummary, PdSceneTrace, PdSpecCoords,
                       PdSpecResult, PdSpecRow, PdSpectrum, PdStats, PdStructure, PdSuiteContact,
                       PdSuitePeaks, PdTrace)

# ---- errors --------------------------------------------------------------------------

# the statuses and their names: generated from core/pd_core.h (_structs.py)
from ._structs import (PD_EBUDGET, PD_EINVAL, PD_EIO, PD_EMAXITER, PD_EMAXPIVOTS,  # noqa: E402,F401
                       PD_ENOMEM, PD_ENONFINITE, PD_ENOSOLUTION, PD_ENUMERICAL, PD_EPARSE,
                       PD_ESINGULAR, PD_OK, STATUS_NAMES)


class PoundError(Exception):
    """A libpound failure: `status` is the PD_E* code (negative int), `message`
    the library's one-line message (str(e) is the message)."""

    def __init__(self, message: str, status: int = PD_EINVAL) -> None:
        """message: the library's text; status: the PD_E* code (a negative int)."""
        Exception.__init__(self, message)
        self.message = message
        self.status = status

    @property
    def code(self) -> str:
        """The status's name, e.g. 'PD_EINVAL'."""
        return STATUS_NAMES.get(self.status, str(self.status))

    def __str__(self) -> str:
        return self.message


class InputError(PoundError, ValueError):
    """PD_EINVAL: an argument out of range or inconsistent (the CLI's exit 2)."""


class ParseError(PoundError, ValueError):
    """PD_EPARSE: a malformed input file (the message names the line)."""


class FileError(PoundError, OSError):
    """PD_EIO: a file could not be opened, read or written."""

    def __init__(self, message: str, status: int = PD_EIO) -> None:
        """message: the library's text (it names the file); status: PD_EIO."""
        PoundError.__init__(self, message, status)

    def __str__(self) -> str:
        return self.message


class NumericalError(PoundError, ArithmeticError):
    """PD_ENUMERICAL, PD_ENONFINITE, PD_ESINGULAR: a computation failed (a
    non-finite number, a singular matrix)."""


class SolverError(PoundError):
    """PD_ENOSOLUTION, PD_EMAXPIVOTS, PD_EMAXITER: an LCP solver gave up."""


class BudgetError(PoundError):
    """PD_EBUDGET: an event or step budget was exhausted."""


class PoundMemoryError(PoundError, MemoryError):
    """PD_ENOMEM: the library could not allocate memory (a run too large)."""


class LayoutError(ImportError):
    """The ctypes mirrors of the library's structs do not match the library."""


_ERROR_CLASSES = {
    PD_ENOMEM: PoundMemoryError, PD_EINVAL: InputError, PD_ENOSOLUTION: SolverError,
    PD_EMAXPIVOTS: SolverError, PD_ENUMERICAL: NumericalError, PD_ENONFINITE: NumericalError,
    PD_EIO: FileError, PD_EPARSE: ParseError, PD_ESINGULAR: NumericalError,
    PD_EBUDGET: BudgetError, PD_EMAXITER: SolverError,
}


def make_error(status: int, message: str) -> PoundError:
    cls = _ERROR_CLASSES.get(status, PoundError)
    return cls(message, status)


# ---- the structs' helpers ----------------------------------------------------------------

def err_text(err):
    """A pd_err's message as str."""
    return err.msg.decode("utf-8", "replace")


# Samplers get the address of a pd_osc_sample / pd_scene_sample (read with
# from_address, or copied whole with memmove).
OscSampler = CFUNCTYPE(c_int, c_void_p, c_void_p)
SceneSampler = CFUNCTYPE(c_int, c_void_p, c_void_p)


def _padded(ctype):
    """ctype followed by guard bytes: the return type of a function that
    returns ctype by value (x86-64 and aarch64 return such structs through a
    caller-provided buffer: a larger C struct cannot overrun this one)."""
    return type("Padded" + ctype.__name__, (Structure,),
                {"_fields_": [("v", ctype), ("guard", c_ubyte * 256)]})


# ---- the functions ----------------------------------------------------------------------

P = POINTER
_PROTOTYPES = {
    # core
    "pd_strerror": (c_char_p, [c_int]),
    "pd_err_clear": (None, [P(PdErr)]),
    "pd_matrix_get": (c_double, [P(PdMatrix), c_int, c_int]),
    "pd_matrix_nnz": (c_long, [P(PdMatrix)]),
    # lcp
    "pd_lcp_outcome_name": (c_char_p, [c_int]),
    "pd_lcp_default_opts": (_padded(PdLcpOpts), []),
    "pd_lcp_method_name": (c_char_p, [c_int]),
    "pd_lcp_method_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_lcp_method_list": (c_char_p, []),
    "pd_lcp_solver_alloc": (c_void_p, [c_int, c_int, c_long, P(PdErr)]),
    "pd_lcp_solver_free": (None, [c_void_p]),
    "pd_lcp_solve": (c_int, [c_void_p, P(PdMatrix), P(c_double), P(PdLcpOpts), P(c_double),
                             P(c_double), P(PdLcpInfo)]),
    "pd_lcp_read": (c_int, [c_char_p, c_int, P(c_int), P(P(c_double)), P(P(c_double)),
                            P(PdErr)]),
    "pd_lcp_enumerate": (c_int, [c_int, P(c_double), P(c_double), P(c_double), P(c_double)]),
    "pd_lcp_residual": (None, [c_int, P(c_double), P(c_double), P(c_double), P(c_double),
                               P(c_double), P(c_double), P(c_double)]),
    # engine
    "pd_factor_kind_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_steps_for": (c_long, [c_double, c_double]),
    # problems: names
    "pd_pulse_name": (c_char_p, [c_int]),
    "pd_pulse_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_dir_name": (c_char_p, [c_int]),
    "pd_dir_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_method_name": (c_char_p, [c_int]),
    "pd_method_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_impact_law_name": (c_char_p, [c_int]),
    "pd_impact_law_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_record_format_parse": (c_int, [c_char_p, P(c_int)]),
    "pd_record_units_parse": (c_int, [c_char_p, P(c_int)]),
    # records
    "pd_record_read": (c_int, [c_char_p, c_int, c_int, P(PdRecord), P(PdErr)]),
    "pd_record_free": (None, [P(PdRecord)]),
    "pd_record_from_array": (c_int, [P(PdRecord), c_char_p, P(c_double), c_long, c_double, c_int,
                                     P(PdErr)]),
    "pd_record_detect": (c_int, [c_char_p, P(c_int), P(PdErr)]),
    "pd_record_plausible": (c_int, [P(PdRecord), c_int, c_char_p, ctypes.c_size_t]),
    "pd_record_duration": (c_double, [P(PdRecord)]),
    "pd_record_measure": (c_int, [P(PdRecord), P(PdRecordMeasures), P(PdErr)]),
    "pd_record_integrate": (c_int, [P(PdRecord), P(c_double), P(c_double), P(PdErr)]),
    "pd_record_fit_pulse": (c_int, [P(PdRecord), P(PdRecordPulse), P(PdErr)]),
    "pd_record_pulse_eval": (None, [P(PdRecordPulse), c_double, P(c_double), P(c_double)]),
    # suites
    "pd_stats_of": (c_int, [P(c_double), c_int, P(PdStats), P(PdErr)]),
    "pd_scene_suite_stats": (c_int, [P(PdScene), P(PdSceneSummary), c_int, P(PdSceneSuite),
                                     P(PdErr)]),
    "pd_scene_suite_free": (None, [P(PdSceneSuite)]),
    "pd_scene_excite_record": (None, [P(PdSceneExcitation), P(PdRecord), P(PdRecordPulse),
                                      c_double]),
    "pd_record_sa": (c_int, [P(PdRecord), P(PdRecordPulse), c_double, c_double, P(c_double),
                             P(PdErr)]),
    "pd_record_scale_to": (c_int, [P(PdRecord), P(PdRecordPulse), c_int, c_double, c_double,
                                   c_double, P(c_double), P(PdErr)]),
    "pd_record_one_cycle": (c_double, [P(PdRecordPulse), c_double]),
    # the run request
    "pd_run_default_opts": (_padded(PdRunOpts), []),
    "pd_run_opts_check": (c_int, [P(PdRunOpts), P(PdErr)]),
    # the oscillator
    "pd_osc_default": (_padded(PdOsc), []),
    "pd_osc_wp": (c_double, [P(PdOsc)]),
    "pd_osc_T0": (c_double, [P(PdOsc)]),
    "pd_osc_gap": (c_double, [P(PdOsc)]),
    "pd_osc_Le": (c_double, [P(PdOsc)]),
    "pd_osc_set_T0": (None, [P(PdOsc), c_double]),
    "pd_osc_set_gap": (None, [P(PdOsc), c_double]),
    "pd_osc_set_uy": (None, [P(PdOsc), c_double]),
    "pd_osc_uy": (c_double, [P(PdOsc)]),
    "pd_osc_yields": (c_int, [P(PdOsc)]),
    "pd_osc_yield_exact": (c_int, [P(PdOsc)]),
    "pd_osc_set_record": (None, [P(PdOsc), P(PdRecord), P(PdRecordPulse), c_double]),
    "pd_osc_excitation_name": (c_char_p, [P(PdOsc)]),
    "pd_osc_check": (c_int, [P(PdOsc), P(PdErr)]),
    "pd_osc_resolve_opts": (c_int, [P(PdOsc), P(PdRunOpts), P(PdRunOpts), P(PdErr)]),
    "pd_osc_default_dt": (c_double, [P(PdOsc)]),
    "pd_osc_default_tend": (c_double, [P(PdOsc)]),
    "pd_osc_scan_points": (c_double, [P(PdOsc), c_double]),
    "pd_osc_run": (c_int, [P(PdOsc), P(PdRunOpts), OscSampler, c_void_p, P(PdOscResult),
                           P(PdErr)]),
    "pd_osc_summarize": (c_int, [P(PdOsc), P(PdRunOpts), OscSampler, c_void_p,
                                 P(PdOscSummary), P(PdErr)]),
    "pd_osc_free_exact": (None, [P(PdOsc), c_double, P(c_double), P(c_double)]),
    "pd_trace_alloc": (c_int, [P(PdTrace), P(PdRunOpts)]),
    "pd_trace_free": (None, [P(PdTrace)]),
    "pd_measure_reference": (c_int, [P(PdOsc), P(PdRunOpts), P(PdTrace), P(PdOscResult),
                                     P(PdErr)]),
    "pd_measure_run": (c_int, [P(PdOsc), P(PdRunOpts), P(PdTrace), c_double, P(PdTrace),
                               P(PdMeasured), P(PdErr)]),
    # scenes
    "pd_scene_new": (P(PdScene), [P(PdSceneExcitation)]),
    "pd_scene_free": (None, [P(PdScene)]),
    "pd_scene_add_sdof": (c_int, [P(PdScene), c_char_p, c_double, c_double, c_double,
                                  P(PdErr)]),
    "pd_scene_add_contact": (c_int, [P(PdScene), c_int, c_int, c_int, c_int, c_double,
                                     c_double, c_int, P(PdErr)]),
    "pd_scene_find": (c_int, [P(PdScene), c_char_p]),
    "pd_scene_finish": (c_int, [P(PdScene), P(PdErr)]),
    "pd_scene_load": (c_int, [c_char_p, P(P(PdScene)), P(PdErr)]),
    "pd_scene_springs": (c_int, [P(PdScene)]),
    "pd_scene_yield_every": (c_int, [P(PdScene), c_double, c_double, P(PdErr)]),
    "pd_scene_chain": (c_int, [c_int, P(PdSceneExcitation), c_double, c_double, c_double,
                               c_double, c_double, P(P(PdScene)), P(PdErr)]),
    "pd_scene_wp": (c_double, [P(PdScene)]),
    "pd_scene_Le": (c_double, [P(PdScene)]),
    "pd_scene_default_dt": (c_double, [P(PdScene)]),
    "pd_scene_resolve_opts": (c_int, [P(PdScene), P(PdRunOpts), P(PdRunOpts), P(PdErr)]),
    "pd_scene_result_alloc": (c_int, [P(PdScene), P(PdSceneResult), P(PdErr)]),
    "pd_scene_result_free": (None, [P(PdSceneResult)]),
    "pd_scene_run": (c_int, [P(PdScene), P(PdRunOpts), SceneSampler, c_void_p,
                             P(PdSceneResult), P(PdErr)]),
    "pd_scene_summarize": (c_int, [P(PdScene), P(PdRunOpts), SceneSampler, c_void_p,
                                   P(PdSceneSummary), P(PdErr)]),
    "pd_scene_summary_free": (None, [P(PdSceneSummary)]),
    "pd_scene_trace_alloc": (c_int, [P(PdSceneTrace), P(PdScene), P(PdRunOpts), P(PdErr)]),
    "pd_scene_trace_free": (None, [P(PdSceneTrace)]),
    "pd_scene_errors_alloc": (c_int, [P(PdScene), P(PdSceneErrors), P(PdErr)]),
    "pd_scene_errors_free": (None, [P(PdSceneErrors)]),
    "pd_scene_measure_reference": (c_int, [P(PdScene), P(PdRunOpts), P(PdSceneTrace),
                                           P(PdSceneResult), P(PdErr)]),
    "pd_scene_measure_run": (c_int, [P(PdScene), P(PdRunOpts), P(PdSceneTrace),
                                     P(PdSceneResult), P(PdSceneResult), P(PdSceneErrors),
                                     P(PdErr)]),
    # spectra
    "pd_spec_init": (None, [P(PdSpectrum)]),
    "pd_spec_curves": (c_long, [P(PdSpectrum)]),
    "pd_spec_points": (c_long, [P(PdSpectrum)]),
    "pd_spec_twins": (c_long, [P(PdSpectrum)]),
    "pd_spec_tasks": (c_long, [P(PdSpectrum)]),
    "pd_spec_pi2": (c_double, [P(PdSpectrum), c_int]),
    "pd_spec_coords_of": (None, [P(PdSpectrum), c_long, P(PdSpecCoords)]),
    "pd_spec_validate": (c_int, [P(PdSpectrum), P(PdErr)]),
    "pd_spec_resolve_method": (None, [P(PdSpectrum)]),
    "pd_spec_run_task": (None, [P(PdSpectrum), c_long, P(PdSpecResult), P(PdErr)]),
    "pd_spec_cost": (c_double, [P(PdSpectrum), c_long]),
    "pd_spec_rows": (None, [P(PdSpectrum), P(PdSpecResult), P(PdSpecRow)]),
    "pd_spec_curve_label": (None, [P(PdSpectrum), c_long, c_char_p, ctypes.c_size_t]),
}
# Called by pd_spec_sweep with the addresses of a pd_spec_coords and a pd_spec_row.
SpecPointFn = CFUNCTYPE(c_int, c_void_p, c_void_p, c_void_p)

# present in newer libraries only
_OPTIONAL = {
    "pd_version": (c_char_p, []),
    "pd_spec_sweep": (c_int, [P(PdSpectrum), SpecPointFn, c_void_p, P(PdErr)]),
}

_HERE = os.path.dirname(os.path.abspath(__file__))


def _candidates() -> List[str]:
    """Where the library is looked for, in order: $POUND_LIBRARY (a path), the
    copy bundled at install time (python/setup.py), the installed
    libpound.so.0 (the loader's search path), the build tree."""
    env = os.environ.get("POUND_LIBRARY")
    if env:
        return [env]
    bundled = os.path.join(_HERE, "libpound.so")
    return ([bundled] if os.path.exists(bundled) else []) + [
        "libpound.so.0", os.path.normpath(os.path.join(_HERE, "..", "..", "build", "libpound.so"))]


def _load() -> Tuple[ctypes.CDLL, str]:
    errors = []
    for name in _candidates():
        try:
            return ctypes.CDLL(name), name
        except OSError as e:
            errors.append("%s (%s)" % (name, e))
    raise ImportError("pound: libpound not found; tried " + "; ".join(errors) +
                      ". Set POUND_LIBRARY to the path of libpound.so, install it "
                      "(make install), or build it (make)")


def _bind(lib, path):
    missing = []
    for name, (res, args) in _PROTOTYPES.items():
        try:
            f = getattr(lib, name)
        except AttributeError:
            missing.append(name)
            continue
        f.restype, f.argtypes = res, args
    if missing:
        raise ImportError("pound: %s does not export %s (a libpound older than this package, "
                          "or symbols hidden)" % (path, ", ".join(missing)))
    for name, (res, args) in _OPTIONAL.items():
        f = getattr(lib, name, None)
        if f is not None:
            f.restype, f.argtypes = res, args


lib: ctypes.CDLL
library_path: str  # the file libpound was loaded from
lib, library_path = _load()
_bind(lib, library_path)


def version() -> Optional[str]:
    """The version of the library loaded (pd_version()), or None when it has no
    pd_version."""
    f = getattr(lib, "pd_version", None)
    return f().decode() if f is not None else None


def s(b):
    """A C string as str (None stays None)."""
    return None if b is None else b.decode("utf-8", "replace")


def check(status, err):
    """Raise the PoundError of a failed call."""
    if status != 0:
        msg = err_text(err) if err is not None and err.msg else s(lib.pd_strerror(status))
        raise make_error(status, msg)


def default_opts():
    return lib.pd_run_default_opts().v


def default_osc():
    return lib.pd_osc_default().v


def default_lcp_opts():
    return lib.pd_lcp_default_opts().v


# ---- the layout check ---------------------------------------------------------------------

def _fail(what, detail):
    raise LayoutError("pound: the ctypes mirror of %s does not match %s (%s): this package "
                      "and the library come from different versions of pound; reinstall the "
                      "package from the library's source tree" % (what, library_path, detail))


def _probe(ctype, call, what):
    """Bytes a call writes into a ctype it clears with memset(p, 0, sizeof *p)
    first: the C sizeof, compared with the mirror's.  The buffer is larger than
    the mirror, filled with two patterns in turn: a byte the call writes equals
    at most one of them."""
    cap = ctypes.sizeof(ctype) + 1024
    size = 0
    for fill in (0xA5, 0x5A):
        buf = (c_ubyte * cap)()
        ctypes.memset(buf, fill, cap)
        call(ctypes.cast(buf, POINTER(ctype)))
        size = max(size, len(bytes(buf).rstrip(bytes([fill]))))
    if size != ctypes.sizeof(ctype):
        _fail(what, "C writes %d bytes, the mirror has %d" % (size, ctypes.sizeof(ctype)))


def _fields(x):
    """The values of a struct's fields, recursively (padding left out)."""
    if isinstance(x, Structure):
        return tuple(_fields(getattr(x, f[0])) for f in x._fields_)
    if isinstance(x, ctypes.Array):
        return tuple(_fields(v) for v in x)
    if isinstance(x, ctypes._Pointer):
        return ctypes.cast(x, c_void_p).value
    return x


def _same(got, want):
    """got == want, NaN equal to NaN, tuples element by element."""
    if isinstance(want, tuple) and isinstance(got, tuple):
        return len(got) == len(want) and all(_same(g, w) for g, w in zip(got, want))
    return (got == want) or (isinstance(want, float) and isinstance(got, float)
                             and math.isnan(want) and math.isnan(got))


def _expect(what, got, want):
    if not _same(got, want):
        _fail(what, "got %r where the library's defaults give %r" % (got, want))


def _check_layout():
    err = PdErr()
    # pd_err: a message longer than its buffer fills it (PD_EIO, the path in it)
    long_path = b"/nonexistent-pound-layout-probe/" + b"x" * 400

    def read_lcp(e):
        n, M, q = c_int(), POINTER(c_double)(), POINTER(c_double)()
        lib.pd_lcp_read(long_path, 0, ctypes.byref(n), ctypes.byref(M), ctypes.byref(q), e)
    _probe(PdErr, read_lcp, "pd_err")

    # pd_spectrum (and inside it pd_osc, pd_run_opts): pd_spec_init clears it and sets
    # the defaults of pd_osc_default() and pd_run_default_opts()
    _probe(PdSpectrum, lib.pd_spec_init, "pd_spectrum")
    sp = PdSpectrum()
    lib.pd_spec_init(sp)
    b, o = sp.base, sp.opts
    for name, got, want in [
            ("pd_osc.pulse", b.pulse, 0), ("pd_osc.dir", b.dir, 1), ("pd_osc.ap", b.ap, 1.0),
            ("pd_osc.Tp", b.Tp, 1.0), ("pd_osc.Pi2", b.Pi2, 1.0), ("pd_osc.Pi3", b.Pi3, 0.05),
            ("pd_osc.eps", b.eps, 0.5), ("pd_osc.xi", b.xi, 0.05),
            ("pd_osc.record", bool(b.record), False),
            ("pd_run_opts.method", o.method, 3), ("pd_run_opts.dt", o.dt, 0.0),
            ("pd_run_opts.theta", o.theta, 0.5), ("pd_run_opts.gamma", o.gamma, 0.5),
            ("pd_run_opts.pen.rtol", o.pen.rtol, 1e-10),
            ("pd_run_opts.pen.atol", o.pen.atol, 1e-12),
            ("pd_run_opts.pen.stepper", s(o.pen.stepper), "rk8pd"),
            ("pd_run_opts.on_lcp", o.on_lcp, None), ("pd_run_opts.rtol", o.rtol, 0.0),
            ("pd_spectrum.npi2", sp.npi2, 0), ("pd_spectrum.npulse", sp.npulse, 1),
            ("pd_spectrum.neps", sp.neps, 1), ("pd_spectrum.dir", sp.dir[0], 1),
            ("pd_spectrum.ap", sp.ap[0], 1.0), ("pd_spectrum.xi", sp.xi[0], 0.05),
            ("pd_spectrum.size", sp.size[0], 0.05), ("pd_spectrum.eps", sp.eps[0], 0.5),
            ("pd_spectrum.dt_per_Tp", sp.dt_per_Tp, 0.0)]:
        _expect(name, got, want)
    # the by-value defaults agree with them
    d = default_opts()
    if _fields(d) != _fields(sp.opts) or _fields(default_osc()) != _fields(sp.base):
        _fail("pd_run_opts/pd_osc", "pd_run_default_opts() or pd_osc_default() differ from "
              "what pd_spec_init() sets")
    lo = default_lcp_opts()
    for name, got, want in [("pd_lcp_opts.cover", bool(lo.cover), False),
                            ("pd_lcp_opts.max_pivots", lo.max_pivots, 0),
                            ("pd_lcp_opts.tol", lo.tol, 1e-12),
                            ("pd_lcp_opts.max_iterations", lo.max_iterations, 0),
                            ("pd_lcp_opts.guess", bool(lo.guess), False)]:
        _expect(name, got, want)

    # pd_spec_coords
    sp.npi2, sp.pi2_min, sp.pi2_max = 3, 0.5, 2.0
    sp.neps, sp.eps[1] = 2, 0.7
    sp.ndir, sp.dir[1] = 2, -1
    _probe(PdSpecCoords, lambda p: lib.pd_spec_coords_of(sp, 6 + 2 * 3 + 3 + 2, p),
           "pd_spec_coords")
    co = PdSpecCoords()
    lib.pd_spec_coords_of(sp, 6 + 2 * 3 + 3 + 2, co)  # twins 6; curve 3 = dir 1, eps 1; j 2
    _expect("pd_spec_coords", (co.twin, co.dir, co.eps, co.j, co.curve), (0, 1, 1, 2, 3))
    # pd_spec_result: a task whose case is refused
    bad = PdSpectrum()
    lib.pd_spec_init(bad)
    bad.npi2, bad.pi2_min, bad.pi2_max, bad.ap[0] = 1, 1.0, 1.0, -1.0
    _probe(PdSpecResult, lambda p: lib.pd_spec_run_task(bad, 0, p, err), "pd_spec_result")
    r = PdSpecResult()
    lib.pd_spec_run_task(bad, 0, r, err)
    _expect("pd_spec_result.status", r.status, PD_EINVAL)
    _expect("pd_err.msg", err_text(err).startswith("ap (pulse amplitude)"), True)
    # pd_spec_row: rows of given task results
    one = PdSpectrum()
    lib.pd_spec_init(one)
    one.npi2, one.pi2_min, one.pi2_max = 1, 2.0, 2.0
    res = (PdSpecResult * 2)()
    res[0].umax, res[1].umax, res[1].impacts = 4.0, 2.0, 7
    _probe(PdSpecRow, lambda p: lib.pd_spec_rows(one, res, p), "pd_spec_row")
    row = PdSpecRow()
    lib.pd_spec_rows(one, res, row)
    _expect("pd_spec_row", (row.c.Pi2, row.T0, row.umax, row.umax_free, row.gamma,
                            row.impacts, row.curve), (2.0, 0.5, 2.0, 4.0, 0.5, 7, 0))

    # pd_osc_summary / pd_osc_result / pd_osc_sample: a refused case, then ten steps
    c = default_osc()
    c.ap = -1.0
    _probe(PdOscSummary, lambda p: lib.pd_osc_summarize(c, None, OscSampler(), None, p, err),
           "pd_osc_summary")
    c = default_osc()
    o = default_opts()
    o.method, o.dt, o.tend = 0, 0.001, 0.01  # Moreau-Jean
    seen = []

    def sample(p, ctx):
        x = PdOscSample.from_address(p)
        seen.append((x.step, x.t, x.gap, x.u))
        return 0
    sm = PdOscSummary()
    check(lib.pd_osc_summarize(c, o, OscSampler(sample), None, sm, err), err)
    gap = lib.pd_osc_gap(c)
    _expect("pd_osc_result", (sm.r.dt, sm.r.tend, sm.r.theta, sm.r.gamma, sm.r.steps,
                              s(sm.r.kernel), sm.free.steps, sm.r.impacts),
            (0.001, 0.01, 0.5, 0.5, 10, "scalar", 10, 0))
    _expect("pd_osc_sample", (len(seen), seen[0][0], seen[-1][0],
                              abs(seen[-1][1] - 0.01) < 1e-12,
                              abs(seen[-1][2] - (gap - seen[-1][3])) < 1e-12),
            (11, 0, 10, True, True))
    # fixed steps: no tolerance (rtol 0, err_est NAN, rtol_met 1, dt_min = dt_max = dt)
    _expect("pd_osc_result.rtol", (sm.r.rtol, sm.r.err_est, sm.r.rtol_met, sm.r.steps_rejected,
                                   sm.r.dt_min, sm.r.dt_max, sm.free.rtol_met),
            (0.0, math.nan, 1, 0, 0.001, 0.001, 1))
    _expect("pd_osc_summary.err_est", (sm.err_est, sm.rtol_met), (math.nan, 1))
    tr = PdTrace()
    lib.pd_trace_alloc(tr, o)
    _expect("pd_trace", (tr.n, tr.cap, tr.dt), (0, 12, 0.001))
    lib.pd_trace_free(tr)
    # Moreau-Jean to a tolerance (pd_run_opts.rtol): the asked tolerance and an estimate
    o.dt, o.rtol = 0.0, 1e-3
    sm = PdOscSummary()
    check(lib.pd_osc_summarize(c, o, OscSampler(), None, sm, err), err)
    r = sm.r
    _expect("pd_osc_result.rtol", (r.rtol, r.rtol_met in (0, 1), math.isfinite(r.err_est),
                                   r.steps_rejected >= 0, 0.0 < r.dt_min <= r.dt_max, r.tend),
            (1e-3, True, True, True, True, 0.01))
    _expect("pd_osc_summary.err_est", (sm.err_est, sm.rtol_met),
            (max(r.err_est, sm.free.err_est), r.rtol_met & sm.free.rtol_met))

    # pd_lcp_info: a solve without a solver is refused after the info is cleared
    M = (c_double * 1)(2.0)
    q = (c_double * 1)(-1.0)
    z, w = (c_double * 1)(), (c_double * 1)()
    mat = PdMatrix(kind=1, rows=1, cols=1, values=M)
    _probe(PdLcpInfo, lambda p: lib.pd_lcp_solve(None, mat, q, None, z, w, p), "pd_lcp_info")
    info = PdLcpInfo()
    _expect("pd_lcp_solve", lib.pd_lcp_solve(None, mat, q, None, z, w, info), PD_EINVAL)
    _expect("pd_lcp_info", (info.outcome, s(info.solver)), (3, "?"))
    # pd_matrix: dense and compressed columns read back
    vals = (c_double * 4)(1.0, 2.0, 3.0, 4.0)  # [[1, 3], [2, 4]] column-major
    dense = PdMatrix(kind=1, rows=2, cols=2, values=vals)
    colptr, rowind = (c_int * 3)(0, 1, 3), (c_int * 3)(1, 0, 1)
    csc = PdMatrix(kind=2, rows=2, cols=2, values=vals, colptr=colptr, rowind=rowind)
    _expect("pd_matrix", (lib.pd_matrix_get(dense, 0, 1), lib.pd_matrix_nnz(dense),
                          lib.pd_matrix_get(csc, 1, 0), lib.pd_matrix_get(csc, 0, 1),
                          lib.pd_matrix_get(csc, 0, 0), lib.pd_matrix_nnz(csc)),
            (3.0, 4, 1.0, 2.0, 0.0, 3))

    # records: read (refused: the record cleared), measured and fitted in memory
    _probe(PdRecord, lambda p: lib.pd_record_read(long_path, 0, 0, p, err), "pd_record")
    acc = (c_double * 3)(0.0, 1.0, 0.0)
    rec = PdRecord(name=b"probe", npts=3, dt=0.01, acc=acc)
    _probe(PdRecordMeasures, lambda p: lib.pd_record_measure(rec, p, err),
           "pd_record_measures")
    m = PdRecordMeasures()
    check(lib.pd_record_measure(rec, m, err), err)
    _expect("pd_record_measures", (m.pga, m.t_pga, abs(m.pgv - 0.01) < 1e-15,
                                   abs(m.t_pgv - 0.02) < 1e-15), (1.0, 0.01, True, True))
    _probe(PdRecordPulse, lambda p: lib.pd_record_fit_pulse(rec, p, err), "pd_record_pulse")

    # scenes: two SDOFs, a contact between them and one with the right wall
    exc = PdSceneExcitation(pulse=1, dir=1, ap=3.0, Tp=0.6)
    sc = lib.pd_scene_new(exc)
    if not sc:
        raise MemoryError("pound: out of memory")
    try:
        for call in (lambda: lib.pd_scene_add_sdof(sc, b"stiff", 0.4, 0.05, 2e5, err),
                     lambda: lib.pd_scene_add_sdof(sc, b"flexible", 1.2, 0.03, 1e5, err),
                     lambda: lib.pd_scene_add_contact(sc, 0, 1, 1, 1, 0.02, 0.65, 0, err),
                     lambda: lib.pd_scene_add_contact(sc, 1, 1, PD_WALL, 0, 0.03, 0.5, 1, err),
                     lambda: lib.pd_scene_finish(sc, err)):
            check(call(), err)
        S = sc[0]
        st, ct = S.st[1], S.ct[1]
        _expect("pd_scene", (S.nstruct, S.ncontact, S.n, S.finished, S.exc.pulse, S.exc.ap,
                             S.exc.Tp, bool(S.exc.record), lib.pd_scene_find(sc, b"flexible")),
                (2, 2, 2, 1, 1, 3.0, 0.6, False, 1))
        _expect("pd_structure", (st.name, st.storeys, st.mass[0], st.xi, st.dof,
                                 abs(st.T0 - 1.2) < 1e-12, S.st[0].name),
                (b"flexible", 1, 1e5, 0.03, 1, True, b"stiff"))
        _expect("pd_contact", (ct.a, ct.b, ct.level_a, ct.level_b, ct.gap, ct.eps, ct.entry,
                               S.ct[0].b), (1, PD_WALL, 1, 0, 0.03, 0.5, 1, 1))
        _probe(PdSceneResult, lambda p: (lib.pd_scene_result_alloc(sc, p, err),
                                         lib.pd_scene_result_free(p)), "pd_scene_result")
        sr = PdSceneResult()
        check(lib.pd_scene_result_alloc(sc, sr, err), err)
        _expect("pd_scene_result.nstruct", (sr.n, sr.m, sr.nstruct, bool(sr.err_est)),
                (2, 2, 2, True))
        lib.pd_scene_result_free(sr)
        o = default_opts()
        o.theta = 5.0  # refused after the summary is cleared
        _probe(PdSceneSummary, lambda p: (lib.pd_scene_summarize(sc, o, SceneSampler(), None,
                                                                 p, err),
                                          lib.pd_scene_summary_free(p)), "pd_scene_summary")
        o = default_opts()
        o.dt, o.tend = 0.001, 0.003
        _probe(PdSceneTrace, lambda p: (lib.pd_scene_trace_alloc(p, sc, o, err),
                                        lib.pd_scene_trace_free(p)), "pd_scene_trace")
        _probe(PdSceneErrors, lambda p: (lib.pd_scene_errors_alloc(sc, p, err),
                                         lib.pd_scene_errors_free(p)), "pd_scene_errors")
        seen = []

        def scene_sample(p, ctx):
            x = PdSceneSample.from_address(p)
            seen.append((x.step, x.t, x.x[1], x.gap[1]))
            return 0
        ss = PdSceneSummary()
        check(lib.pd_scene_summarize(sc, o, SceneSampler(scene_sample), None, ss, err), err)
        try:
            _expect("pd_scene_result", (ss.r.n, ss.r.m, ss.r.steps, ss.r.dt, ss.r.tend,
                                        s(ss.r.method), ss.r.impacts[1], ss.Pi2[0]),
                    (2, 2, 3, 0.001, 0.003, "moreau", 0, 0.6 / S.st[0].T0))
            _expect("pd_scene_sample", (len(seen), seen[-1][0],
                                        abs(seen[-1][1] - 0.003) < 1e-12,
                                        abs(seen[-1][3] - (0.03 - seen[-1][2])) < 1e-12),
                    (4, 3, True, True))
            _expect("pd_scene_result.rtol", (ss.r.rtol, ss.r.err_est[1], ss.r.err_est_max,
                                             ss.r.rtol_met, ss.r.steps_rejected, ss.r.dt_min,
                                             ss.r.dt_max, ss.r.nstruct),
                    (0.0, math.nan, math.nan, 1, 0, 0.001, 0.001, 2))
            _expect("pd_scene_summary.err_est", (ss.err_est, ss.rtol_met,
                                                 ss.err_est_structure[0]),
                    (math.nan, 1, math.nan))
        finally:
            lib.pd_scene_summary_free(ss)
        # to a tolerance: each structure's estimate, the larger of the run's and its twin's
        o.dt, o.rtol = 0.0, 1e-3
        ss = PdSceneSummary()
        check(lib.pd_scene_summarize(sc, o, SceneSampler(), None, ss, err), err)
        try:
            r, f = ss.r, ss.free
            _expect("pd_scene_result.rtol", (r.rtol, r.nstruct, r.rtol_met in (0, 1),
                                             math.isfinite(r.err_est_max),
                                             r.err_est_max == max(r.err_est[0], r.err_est[1]),
                                             0.0 < r.dt_min <= r.dt_max),
                    (1e-3, 2, True, True, True, True))
            _expect("pd_scene_summary.err_est",
                    (ss.err_est, ss.rtol_met, ss.err_est_structure[0],
                     ss.err_est_structure[1]),
                    (max(r.err_est_max, f.err_est_max), r.rtol_met & f.rtol_met,
                     max(r.err_est[0], f.err_est[0]), max(r.err_est[1], f.err_est[1])))
        finally:
            lib.pd_scene_summary_free(ss)
    finally:
        lib.pd_scene_free(sc)


_check_layout()
