"""The case of a run from keyword arguments, built as the command line builds
it from its flags (cli/case.c): the same library calls in the same order, so
that the numbers are the CLI's to the last bit."""
import ctypes
import math
import os
from collections.abc import Mapping
from typing import Any, Optional

import numpy as np

from . import _args, _demand, _lib
from ._args import number
from ._lib import InputError, PdErr, PdRecord, PdRecordPulse, err_text, lib
from ._types import ArrayLike, PathArg

# Keyword arguments and the CLI flags they mirror (the names without "--",
# "-" written "_").
MODEL_KEYS = ("pulse", "dir", "ap", "Tp", "T0", "Pi2", "gap", "Pi3", "eps", "xi", "uy", "Piy",
              "alpha")
RECORD_KEYS = ("record", "scale", "units", "record_format", "record_dt")


def _a_path(x: Any) -> bool:
    """A file's name (a path, or text that is no number): a list of them is
    a suite of records, not an array of samples written as text."""
    if isinstance(x, os.PathLike):
        return True
    if not isinstance(x, (str, bytes)):
        return False
    try:
        float(x)
        return False
    except ValueError:
        return True
SCHEME_KEYS = ("method", "dt", "tend", "theta", "gamma", "allow_unstable", "no_accumulation",
               "no_wall", "kernel", "factor", "lcp_solver", "contact", "kc", "kc_abs", "rtol",
               "atol", "stepper", "close_tol", "impact_law", "contact_duration")
CASE_KEYS = MODEL_KEYS + RECORD_KEYS + SCHEME_KEYS
# cli/case.c: the keywords only one method takes choose it (moreau 0,
# event 1, penalty 2) unless method says another; the flags only
# (allow_unstable, no_accumulation) when true.  rtol is two methods': alone it
# chooses moreau (Moreau-Jean to a tolerance), with penalty it is the
# integrator's tolerance (case_rtol below)
IMPLIES = {"dt": 0, "theta": 0, "gamma": 0, "allow_unstable": 0, "kernel": 0, "factor": 0,
           "lcp_solver": 0, "dt_per_Tp": 0, "no_accumulation": 1, "close_tol": 1,
           "impact_law": 1, "kc": 2,
           "kc_abs": 2, "atol": 2, "contact": 2, "stepper": 2}
from ._structs import PD_METHOD_AUTO, PD_METHOD_NEWMARK  # noqa: E402  (generated from pd_problems.h)
PD_RTOL_MIN = 1e-12  # the tightest tolerance of Moreau-Jean's steps

STEPPERS = {"rk8pd": b"rk8pd", "rkf45": b"rkf45", "rk4imp": b"rk4imp", "msbdf": b"msbdf"}
CASE_MAX_STEPS = 2e9
PD_OSC_MAX_SCAN = 2.5e7


def fmt(x):
    """%.10g, as the CLI's messages print numbers."""
    return "%.10g" % x


def parse_name(what, parser, value, choices):
    """A name through the library's parser (a str without NUL, as bytes)."""
    out = ctypes.c_int()
    if parser(_args.name(what, value, choices), ctypes.byref(out)) != 0:
        raise InputError("%s: %s is not one of %s" % (what, _args.show(value), choices))
    return out.value


def parse_dir(value):
    """'normal'/'reverse', or the number +1/-1 (not a bool)."""
    if isinstance(value, (int, float, np.integer, np.floating)) and not _args.is_bool(value):
        if value in (1, -1):
            return int(value)
        raise InputError("dir: %s is not one of normal, reverse (or 1, -1)" % _args.show(value))
    return parse_name("dir", lib.pd_dir_parse, value, "normal, reverse")


def record_samples(acc):
    """The samples of a ground motion given as an array (record=, every entry
    point's: simulate, compare, converge, spectrum, Record.from_array), as
    a contiguous 1-D float64 array: real numbers only (_args.real_array:
    no bools, strings, complex numbers; a masked array only when nothing is
    masked), each refusal naming record.  Their finiteness is the library's
    to check (pd_record_from_array names the sample)."""
    a = _args.real_array("record", acc, finite=False)
    if a.ndim != 1:
        raise InputError("record: expected a 1-D array of accelerations (got shape %s)"
                         % (a.shape,))
    return np.ascontiguousarray(a)


def record_of_result(rec, kw=None, what="record"):
    """pound.record(path)'s Result given as a record: its samples acc [m/s^2]
    every dt [s], named as the file (Record.from_array: the file's record to
    the bit).  A dict without the samples (the CLI's `pound record --json`,
    the measures only) raises InputError naming what to give instead.  kw:
    a single run's keywords, whose units, record_dt and record_format would
    contradict the Result's own (a suite's apply to its files and arrays)."""
    missing = [k for k in ("acc", "dt") if k not in rec]
    if missing:
        raise InputError("%s: a dict without the samples (%s): pound.record(path)'s Result "
                         "has them (acc [m/s^2], dt [s]); or give the record's file, a "
                         "pound.Record(path), or the accelerations with record_dt"
                         % (what, ", ".join(missing)))
    for key in ("units", "record_dt", "record_format"):
        if kw and kw.get(key) is not None and (key != "units" or kw[key] != "m/s2"):
            raise InputError("%s: pound.record()'s Result gives its samples in m/s^2 every "
                             "dt = %s s (it takes no %s)" % (key, rec["dt"],
                                                             key))
    name = rec.get("name", "array")
    return Record.from_array(rec["acc"], rec["dt"], "m/s2",
                             name if isinstance(name, str) else "array")


class Record:
    """A strong-motion record read and its pulse fitted by the library
    (pd_record_read, pd_record_fit_pulse); owns the C arrays.  Give it as
    record= to simulate() or spectrum(); pound.record(path) measures one."""

    def __init__(self, path: PathArg, units: Optional[str] = None,
                 format: str = "auto") -> None:
        """Read the record at path (format 'auto', 'at2', 'v2', 'text').
        units: of a two-column text record, 'g', 'm/s2', 'cm/s2' ['g']; an AT2
        or V2 file states its own, and units given for one raise InputError
        (as the CLI's --units)."""
        self._owned = False
        cpath, self.path = _args.path("record", path)
        fmt_code = parse_name("record_format", lib.pd_record_format_parse, format,
                              "auto, at2, v2, text")
        unit_code = parse_name("units", lib.pd_record_units_parse,
                               "g" if units is None else units, "g, m/s2, cm/s2")
        if units is not None:
            f, err = ctypes.c_int(fmt_code), PdErr()
            if fmt_code == 0 and lib.pd_record_detect(cpath, f, err):
                raise InputError(err_text(err))
            if f.value != 3:  # PD_RECORD_TEXT
                raise InputError("units: %s is read as %s, whose file states its units (units "
                                 "is for two-column text records)" % (
                                     self.path, "a PEER AT2 record (in g)" if f.value == 1
                                     else "a COSMOS V2 record"))
        self.units_code = unit_code
        self.rec = PdRecord()
        self.pulse = PdRecordPulse()
        err = PdErr()
        st = lib.pd_record_read(cpath, fmt_code, unit_code, self.rec, err)
        if st == 0:
            self._owned = True
            st = lib.pd_record_fit_pulse(self.rec, self.pulse, err)
        if st != 0:
            msg = err_text(err)
            if fmt_code != 0 and st != _lib.PD_ENOMEM:  # the user chose how to read it: say so
                msg = "%s (read as record_format %s)" % (msg, format)
            self.close()
            raise _lib.make_error(st, msg)
        self._warn_units()

    def _warn_units(self):
        """The CLI's warning for a peak acceleration implausible in its units."""
        buf = ctypes.create_string_buffer(512)
        if not lib.pd_record_plausible(self.rec, self.units_code, buf, len(buf)):
            import warnings
            # the library's words name the CLI's flag; Python's keyword is units=
            msg = buf.value.decode("utf-8", "replace").replace("(--units)", "(units=)")
            warnings.warn(msg, stacklevel=4)

    @classmethod
    def from_array(cls, acc: ArrayLike, dt: float, units: str = "m/s2",
                   name: str = "array") -> "Record":
        """A record from the accelerations acc[k] (in units: 'g', 'm/s2',
        'cm/s2'; by default the library's own m/s^2, as Record.acc gives
        them back) at t_k = k dt [s] (pd_record_from_array):
        the same values as a file's give the same record, bit for bit.
        acc: a 1-D array or list of real numbers (ints or floats); bools,
        strings, complex numbers and masked arrays with an entry masked raise
        InputError naming record (record_samples)."""
        self = cls.__new__(cls)
        self._owned = False
        self.path = None
        a = record_samples(acc)
        dt = number("record_dt", dt)
        unit_code = parse_name("units", lib.pd_record_units_parse, units, "g, m/s2, cm/s2")
        self.units_code = unit_code
        self.rec = PdRecord()
        self.pulse = PdRecordPulse()
        err = PdErr()
        st = lib.pd_record_from_array(self.rec, str(name).encode(), a.ctypes.data_as(
            ctypes.POINTER(ctypes.c_double)), a.size, dt, unit_code, err)
        if st == 0:
            self._owned = True
            st = lib.pd_record_fit_pulse(self.rec, self.pulse, err)
        if st != 0:
            msg = err_text(err)
            self.close()
            raise _lib.make_error(st, msg)
        self._warn_units()
        return self

    def close(self) -> None:
        """Free the C arrays now (a closed record is not to be used)."""
        if self._owned:
            lib.pd_record_free(self.rec)
            self._owned = False

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown
            pass

    @property
    def name(self) -> str:
        """The record's name (its file's, or from_array's name)."""
        return self.rec.name.decode("utf-8", "replace")

    @property
    def acc(self) -> np.ndarray:
        """The ground accelerations [m/s^2] (a copy)."""
        return np.ctypeslib.as_array(self.rec.acc, (self.rec.npts,)).copy()


def _check_scheme(o, have):
    """cli/case.c check_scheme: the ranges of the scheme options, each error
    naming the option."""
    if have.get("dt") and not o.dt > 0.0:
        raise InputError("dt: the step must be > 0 (got %s)" % fmt(o.dt))
    if have.get("tend") and not o.tend > 0.0:
        raise InputError("tend: must be > 0 (got %s)" % fmt(o.tend))
    if not 0.0 <= o.gamma <= 1.0:
        raise InputError("gamma: must be in [0, 1] (got %s)" % fmt(o.gamma))
    if not o.allow_unstable and not 0.5 <= o.theta <= 1.0:
        raise InputError("theta: %s is outside [1/2, 1], where Moreau-Jean is not "
                         "unconditionally stable (allow_unstable=True runs it)" % fmt(o.theta))
    if not 0.0 <= o.theta <= 2.0:
        raise InputError("theta: must be in [0, 2] (got %s)" % fmt(o.theta))
    if have.get("kc") and not o.pen.kc_mult > 0.0:
        raise InputError("kc: the contact stiffness multiple must be > 0 (got %s)"
                         % fmt(o.pen.kc_mult))
    if o.pen.kc_abs < 0.0:
        raise InputError("kc_abs: the contact stiffness must be >= 0 (got %s)"
                         % fmt(o.pen.kc_abs))
    if not 0.0 < o.pen.rtol < 1.0:
        raise InputError("rtol: the relative tolerance must be in (0, 1) (got %s)"
                         % fmt(o.pen.rtol))
    if not o.pen.atol > 0.0:
        raise InputError("atol: the absolute tolerance must be > 0 (got %s)" % fmt(o.pen.atol))
    if not 0.0 <= o.close_tol <= 1.0:
        raise InputError("close_tol: the closing tolerance must be in [0, 1] (in units of Le; "
                         "got %s)" % fmt(o.close_tol))
    _demand.check_opts(o, have)


def scheme_opts(kw, listed=False):
    """pd_run_opts from the scheme keywords (pd_run_default_opts() first):
    (opts, which were given).  Unknown keys are the caller's.  As cli/case.c
    case_finish: the method given or implied (case_method), rtol to the
    method that takes it (case_rtol), then the ranges (check_scheme).
    listed: the methods are the caller's list (compare, converge: rtol is
    then the penalty rows' integrator tolerance and chooses no method)."""
    o = _lib.default_opts()
    have = {}
    rtol = None
    for key in SCHEME_KEYS:
        if key not in kw or kw[key] is None:
            continue
        v = kw[key]
        have[key] = True
        if key == "method":
            o.method = parse_name("method", lib.pd_method_parse, v,
                                  "moreau, event, penalty, auto, event-general, newmark")
        elif key in ("dt", "tend", "theta", "gamma", "close_tol", "contact_duration"):
            setattr(o, key, number(key, v))
        elif key in ("allow_unstable", "no_accumulation", "no_wall"):
            setattr(o, key, 1 if _args.flag(key, v) else 0)
        elif key == "kernel":
            o.kernel = 1 if _args.choice(key, v, ("auto", "general")) == "general" else 0
        elif key == "factor":
            o.factor = parse_name("factor", lib.pd_factor_kind_parse, v,
                                  "auto, scalar, dense, cholmod")
        elif key == "impact_law":
            o.impact_law = parse_name("impact_law", lib.pd_impact_law_parse, v, "staged, single")
        elif key == "lcp_solver":
            o.lcp_solver = parse_name("lcp_solver", lib.pd_lcp_method_parse, v,
                                      _lib.s(lib.pd_lcp_method_list()))
        elif key == "contact":
            o.pen.law = 1 if _args.choice(key, v, ("kelvin", "hertz")) == "hertz" else 0
        elif key == "kc":
            o.pen.kc_mult = number(key, v)
        elif key == "kc_abs":
            o.pen.kc_abs = number(key, v)
        elif key == "rtol":
            rtol = number(key, v)
        elif key == "atol":
            o.pen.atol = number(key, v)
        elif key == "stepper":
            o.pen.stepper = STEPPERS[_args.choice(key, v, STEPPERS)]
    have["method_by"] = _method_by(o, kw, listed)
    if rtol is not None:
        case_rtol(o, rtol, have, listed)
    _check_scheme(o, have)
    return o, have


def case_rtol(o, rtol, have, listed=False, dt_key="dt"):
    """cli/case.c case_rtol: rtol to the method that takes it.  Moreau-Jean
    (method moreau or auto, which it makes moreau) steps to the tolerance
    (o.rtol); with method penalty (or listed methods) it is the GSL
    integrator's tolerance (o.pen.rtol); refused with dt (fixed steps) and
    with the methods that have none."""
    if not PD_RTOL_MIN <= rtol < 1.0:
        raise InputError("rtol: the relative tolerance must be in [%g, 1) (got %s)"
                         % (PD_RTOL_MIN, fmt(rtol)))
    if o.method == 2 or listed:
        o.pen.rtol = rtol
        return
    if o.method not in (0, PD_METHOD_AUTO):
        raise InputError("rtol: the tolerance of moreau's steps or of penalty's integrator; "
                         "method %s has none" % _lib.s(lib.pd_method_name(o.method)))
    if have.get("dt"):
        raise InputError("rtol and %s: Moreau-Jean takes fixed steps (%s) or steps to a "
                         "tolerance (rtol), not both" % (dt_key, dt_key))
    o.method = 0
    o.rtol = rtol


def implied_method(kw, extra=()):
    """cli/case.c case_method: (method, the keyword that chose it), or
    (None, None) when no keyword only one method takes was given."""
    first = {}
    for key in list(kw) + list(extra):
        if key in IMPLIES and kw.get(key) not in (None, False) and IMPLIES[key] not in first:
            first[IMPLIES[key]] = key
    chosen = sorted(first.items())
    if len(chosen) > 1:
        names = ("moreau", "event", "penalty")
        raise InputError("%s and %s belong to different methods (%s, %s): give method"
                         % (chosen[0][1], chosen[1][1], names[chosen[0][0]],
                            names[chosen[1][0]]))
    return chosen[0] if chosen else (None, None)


def _method_by(o, kw, listed=False):
    """The method given, else the implied one set in o: what chose it (rtol
    alone chooses moreau, as cli/case.c case_method, but not among listed
    methods)."""
    if "method" in kw and o.method != PD_METHOD_AUTO:
        return "--method"
    m, key = implied_method(kw)
    if m is None and not listed and kw.get("rtol") is not None:
        m, key = 0, "rtol"
    if m is None:
        return None
    o.method = m
    return "--" + key.replace("_", "-")


class Case:
    """The one-wall oscillator of a set of keywords: c (pd_osc) and opts
    (pd_run_opts, resolved by resolve()), as `pound simulate` builds them
    (listed: compare's and converge's, whose methods are a list: see
    scheme_opts)."""

    def __init__(self, kw, allowed=CASE_KEYS, listed=False):
        unknown = sorted(set(kw) - set(allowed))
        if unknown:
            raise TypeError("unexpected keyword argument%s %s (the case takes %s)"
                            % ("s" if len(unknown) > 1 else "", ", ".join(unknown),
                               ", ".join(allowed)))
        kw = {k: v for k, v in kw.items() if v is not None}
        self.kw = kw
        self.record = None
        c = _lib.default_osc()
        self.opts, self.have = scheme_opts(kw, listed)
        if "pulse" in kw:
            c.pulse = parse_name("pulse", lib.pd_pulse_parse, kw["pulse"],
                                 "sine, cosine, harmonic")
        if "dir" in kw:
            c.dir = parse_dir(kw["dir"])
        for key in ("ap", "Tp", "Pi2", "Pi3", "eps", "xi", "Piy", "alpha"):
            if key in kw:
                setattr(c, key, number(key, kw[key]))
        self.T0 = number("T0", kw["T0"]) if "T0" in kw else None
        self.gap = number("gap", kw["gap"]) if "gap" in kw else None
        self.uy = number("uy", kw["uy"]) if "uy" in kw else None
        self.c = c
        self.pulse_key = next((k for k in ("pulse", "ap", "Tp") if k in kw), None)

    def finish_model(self):
        """cli/case.c case_record, the T0 and gap forms and check_case."""
        kw, c = self.kw, self.c
        if "record" in kw:
            if self.pulse_key:
                raise InputError("%s: the record replaces the pulse (its fitted pulse gives ap "
                                 "and Tp; scale scales it)" % self.pulse_key)
            scale = number("scale", kw.get("scale", 1.0))
            if not scale > 0.0:
                raise InputError("scale: must be > 0 (got %s)" % fmt(scale))
            rec = kw["record"]
            if isinstance(rec, Record):
                pass
            elif isinstance(rec, Mapping):  # pound.record(path)'s Result: its acc and dt
                rec = record_of_result(rec, kw)
            elif isinstance(rec, (list, tuple)) and rec and all(map(_a_path, rec)):
                raise InputError("record: %d files given: a run takes one record (a path, a "
                                 "pound.Record or an array of accelerations); a suite: "
                                 "records=[...]" % len(rec))
            elif not isinstance(rec, (str, bytes, os.PathLike)):
                # a ground motion as an array: its samples every record_dt, in units
                if "record_dt" not in kw:
                    raise InputError("record_dt: give the sampling interval of the record "
                                     "array [s]")
                if "record_format" in kw:
                    raise InputError("record_format: goes with a record file, not an array")
                # in units=, or the library's own m/s^2 (what pound.record(p).acc holds)
                rec = Record.from_array(rec, kw["record_dt"], kw.get("units") or "m/s2")
            else:
                if "record_dt" in kw:
                    raise InputError("record_dt: goes with a record array (a file gives its "
                                     "own)")
                rec = Record(rec, kw.get("units"), kw.get("record_format", "auto"))
            self.record = rec
            lib.pd_osc_set_record(c, rec.rec, rec.pulse, scale)
        elif "scale" in kw:
            raise InputError("scale: goes with record")
        if self.T0 is not None and "Pi2" in kw:
            raise InputError("T0 and Pi2 are alternatives: give one")
        if self.gap is not None and "Pi3" in kw:
            raise InputError("gap and Pi3 are alternatives: give one")
        if self.T0 is not None:
            lib.pd_osc_set_T0(c, self.T0)
        if self.gap is not None:
            lib.pd_osc_set_gap(c, self.gap)
        self.check_yield()
        if self.uy is not None:
            lib.pd_osc_set_uy(c, self.uy)
        err = PdErr()
        _lib.check(lib.pd_osc_check(c, err), err)
        self.check_derived(self.opts, self.have)

    def check_yield(self):
        """cli/case.c check_yield: the yielding spring's keys, and the runs
        that model it."""
        kw, c, o = self.kw, self.c, self.opts
        key = "uy" if self.uy is not None else "Piy"
        if self.uy is not None and "Piy" in kw:
            raise InputError("uy and Piy are alternatives: give one")
        if self.uy is not None and not (self.uy > 0.0 and math.isfinite(self.uy)):
            raise InputError("uy: the yield displacement must be > 0 m (got %s)" % fmt(self.uy))
        if "Piy" in kw and not (c.Piy > 0.0 and math.isfinite(c.Piy)):
            raise InputError("Piy: the dimensionless yield displacement must be > 0 (got %s)"
                             % fmt(c.Piy))
        if "alpha" in kw and not 0.0 <= c.alpha <= 1.0:
            raise InputError("alpha: the post-yield stiffness ratio must be in [0, 1] (got %s)"
                             % fmt(c.alpha))
        if self.uy is None and "Piy" not in kw:
            if "alpha" in kw:
                raise InputError("alpha: needs the yield displacement (uy or Piy)")
            return
        if o.method == 1 and not lib.pd_osc_yield_exact(c):
            raise InputError("%s: the exact reference models a yielding spring whose sliding "
                             "phase is underdamped, xi < sqrt(alpha) (or xi 0, or alpha 0; got xi "
                             "%s, alpha %s): method='moreau' runs it"
                             % (key, fmt(c.xi), fmt(c.alpha)))
        if o.method not in (0, 1, PD_METHOD_NEWMARK, PD_METHOD_AUTO):
            raise InputError("%s: a yielding oscillator runs by method 'event', 'moreau' or "
                             "'newmark' (the adaptive penalty does not model yielding yet; got "
                             "method %s)" % (key, _lib.s(lib.pd_method_name(o.method))))
        if o.rtol > 0.0:
            raise InputError("%s: a yielding oscillator runs at a fixed step (dt), not to a "
                             "tolerance (rtol)" % key)

    def check_derived(self, o, have, dt_key="dt"):
        """cli/case.c pd_cli_case_check_derived: the run's size bounded."""
        c = self.c
        T0, Le, gap = lib.pd_osc_T0(c), lib.pd_osc_Le(c), lib.pd_osc_gap(c)
        if not (math.isfinite(T0) and T0 > 0.0 and math.isfinite(2 * math.pi / T0)):
            raise InputError("T0: the oscillator's period T0 = Tp / Pi2 = %.3g s is out of range"
                             % T0)
        if not (Le > 0.0 and math.isfinite(Le)):
            raise InputError("ap: Le = ap (Tp / 2 pi)^2 = %.3g m is out of range" % Le)
        if not (math.isfinite(gap) and math.isfinite(c.Pi3)):
            raise InputError("gap: the gap is too large for ap and Tp (Pi3 = gap / Le "
                             "overflows)")
        tend = o.tend if have.get("tend") else lib.pd_osc_default_tend(c)
        dt = o.dt if have.get("dt") else lib.pd_osc_default_dt(c)
        if not math.isfinite(tend):
            raise InputError("T0: tend = Tp + 2 T0 overflows")
        if o.rtol > 0.0:  # to a tolerance: no step count of its own
            return
        if have.get("dt") and not dt < tend:
            raise InputError("%s: the step %.3g s is not shorter than the run (tend = %.3g s)"
                             % (dt_key, dt, tend))
        if not tend / dt <= CASE_MAX_STEPS:
            raise InputError("dt: %.3g steps of %.3g s over %.3g s (at most %.0e)"
                             % (tend / dt, dt, tend, CASE_MAX_STEPS))
        scan = lib.pd_osc_scan_points(c, tend)
        if o.method == 1 and not scan <= PD_OSC_MAX_SCAN:
            raise InputError("T0: the event-driven reference would scan %.3g points (64 per "
                             "period T0 = %.3g s over %.3g s; at most %.3g: method='moreau' "
                             "runs it)" % (scan, T0, tend, PD_OSC_MAX_SCAN))

    def resolve(self):
        """Check the case and complete dt and tend (pd_osc_resolve_opts)."""
        self.finish_model()
        err = PdErr()
        _lib.check(lib.pd_osc_resolve_opts(self.c, self.opts, self.opts, err), err)
        if self.opts.rtol == 0.0 and self.opts.tend / self.opts.dt > 2e9:
            raise InputError("dt: %g s over %g s is more than 2e9 steps"
                             % (self.opts.dt, self.opts.tend))
        return self


def copy_opts(o):
    """A copy of a pd_run_opts (its stepper string is a static or a bytes
    object kept alive by STEPPERS)."""
    return _lib.PdRunOpts.from_buffer_copy(o)
