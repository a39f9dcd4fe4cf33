"""Scenes: rows of structures read from JSON files (docs/scenes.md) or
generated (chain), run as `pound simulate --scene F --json` runs them."""
import ctypes
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _args, _demand, _lib
from ._case import SCHEME_KEYS, Case, InputError, copy_opts, number, scheme_opts
from ._lib import PD_WALL, PdErr, err_text, lib, s
from ._osc import Result, _History, history_args, history_cap, tolerance_fields
from ._types import Int, PathArg

SCENE_OPTS = SCHEME_KEYS
NAN = float("nan")


def _array(ptr, n, dtype=np.float64):
    if n <= 0 or not ptr:
        return np.zeros(0, dtype=dtype)
    return np.ctypeslib.as_array(ptr, (n,)).astype(dtype, copy=True)


class Scene:
    """A finished scene (pd_scene) owned by Python: Scene(path) reads a scene
    file, Scene.chain(N, ...) generates a row of N SDOFs between two walls.
    structures, contacts and excitation describe it; simulate() runs it."""

    def __init__(self, path: Optional[PathArg] = None, _ptr: Any = None,
                 _name: Optional[str] = None) -> None:
        """Read the scene file at path (JSON, docs/scenes.md); _ptr and _name
        are Scene.chain's."""
        self._p = None
        if _ptr is not None:
            self._p, self.path = _ptr, _name
            return
        cpath, text = _args.path("scene", path)
        p = ctypes.POINTER(_lib.PdScene)()
        err = PdErr()
        _lib.check(lib.pd_scene_load(cpath, ctypes.byref(p), err), err)
        self._p, self.path = p, text

    @classmethod
    def chain(cls, N: Int, ratio: float = 1.5, **model: Any) -> "Scene":
        """`pound simulate --chain N`: N SDOFs of unit mass between two walls,
        periods alternating T0 and ratio T0, every gap `gap` (or Pi3), every
        restitution eps; the model keywords of simulate() (pulse, dir, ap
        [m/s^2], Tp [s], T0 [s] or Pi2, gap [m] or Pi3, eps, xi; uy [m] or
        Piy with alpha: every SDOF yields, as `--chain N --uy`)."""
        N = _args.integer("chain", N)
        if not 1 <= N <= 10000000:
            raise InputError("chain: N must be in [1, 1e7] (got %d)" % N)
        ratio = number("chain_ratio", ratio)
        if not ratio > 0.0:
            raise InputError("chain_ratio: must be > 0 (got %.10g)" % ratio)
        if N > 1 and not 1e-4 <= ratio <= 1e4:
            raise InputError("chain_ratio: must be in [1e-4, 1e4] (got %.10g)" % ratio)
        k = Case(model, allowed=("pulse", "dir", "ap", "Tp", "T0", "Pi2", "gap", "Pi3", "eps",
                                 "xi", "uy", "Piy", "alpha"))
        k.finish_model()
        c = k.c
        x = _lib.PdSceneExcitation(pulse=c.pulse, dir=c.dir, ap=c.ap, Tp=c.Tp)
        p = ctypes.POINTER(_lib.PdScene)()
        err = PdErr()
        _lib.check(lib.pd_scene_chain(N, x, lib.pd_osc_T0(c), ratio, c.xi, lib.pd_osc_gap(c),
                                      c.eps, ctypes.byref(p), err), err)
        if lib.pd_osc_yields(c):  # uy or Piy: every SDOF yields, as --chain N --uy
            st = lib.pd_scene_yield_every(p, lib.pd_osc_uy(c), c.alpha, err)
            if st:
                lib.pd_scene_free(p)
            _lib.check(st, err)
        return cls(_ptr=p, _name="chain of %d" % N)

    def close(self) -> None:
        """Free the C scene now (also on leaving a with block); later uses
        raise ValueError."""
        if self._p:
            lib.pd_scene_free(self._p)
            self._p = None

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown
            pass

    def __enter__(self) -> "Scene":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    @property
    def _sc(self):
        if not self._p:
            raise ValueError("the scene is closed")
        return self._p[0]

    @property
    def n(self) -> int:
        """Degrees of freedom (one per storey)."""
        return self._sc.n

    @property
    def tend(self) -> float:
        """The file's tend [s] (0: derived)."""
        return self._sc.tend

    @property
    def Le(self) -> float:
        """The excitation's length scale Le = ap / wp^2 [m] (the Pi terms' unit)."""
        return lib.pd_scene_Le(self._p)

    @property
    def wp(self) -> float:
        """The excitation's circular frequency wp = 2 pi / Tp [rad/s]."""
        return lib.pd_scene_wp(self._p)

    def _side(self, k):
        return "wall" if k == PD_WALL else s(self._sc.st[k].name)

    @property
    def structures(self) -> List[Result]:
        """One Result per structure: name, storeys, T0 [s], xi, mass [kg] and
        stiffness [N/m] per storey, dof (its first), damping, alpha [1/s] and
        beta [s] (Rayleigh)."""
        sc = self._sc
        out = []
        for k in range(sc.nstruct):
            st = sc.st[k]
            out.append(Result(name=s(st.name), storeys=st.storeys, T0=st.T0, xi=st.xi,
                              mass=_array(st.mass, st.storeys),
                              stiffness=_array(st.stiffness, st.storeys), dof=st.dof,
                              damping="exact" if st.storeys == 1 else
                              "stiffness" if st.damping == 1 else "rayleigh",
                              alpha=st.alpha, beta=st.beta))
        return out

    @property
    def contacts(self) -> List[Result]:
        """One Result per contact: a, b (structure names or 'wall'), level_a,
        level_b (storeys, 1 = the first), gap [m], eps."""
        sc = self._sc
        out = []
        for a in range(sc.ncontact):
            ct = sc.ct[a]
            out.append(Result(a=self._side(ct.a), b=self._side(ct.b), level_a=ct.level_a,
                              level_b=ct.level_b, gap=ct.gap, eps=ct.eps))
        return out

    @property
    def excitation(self) -> Result:
        """The ground motion: pulse (or the record's name), dir ('+x', '-x'),
        ap [m/s^2], Tp [s]; a record's also record and scale."""
        x = self._sc.exc
        out = Result(pulse=s(x.record[0].name) if x.record else s(lib.pd_pulse_name(x.pulse)),
                     dir="+x" if x.dir > 0 else "-x", ap=x.ap, Tp=x.Tp)
        if x.record:
            out["record"] = s(x.record[0].name)
            out["scale"] = x.scale
        return out

    def opts(self, kw: Dict[str, Any]) -> Tuple[Any, Any]:
        """The run options (pd_run_opts) of the scheme keywords, as given and
        resolved for this scene (dt, tend [s] completed; to a tolerance,
        rtol > 0, dt stays 0)."""
        return self._opts(kw)

    def _opts(self, kw, listed=False):
        """opts(kw); listed: compare's and converge's (rtol: the penalty
        rows' integrator tolerance)."""
        unknown = sorted(set(kw) - set(SCENE_OPTS))
        if unknown:
            raise TypeError("unexpected keyword argument(s) %s (a scene run takes %s)"
                            % (", ".join(unknown), ", ".join(SCENE_OPTS)))
        o, have = scheme_opts({k: v for k, v in kw.items() if v is not None}, listed)
        out, err = _lib.PdRunOpts(), PdErr()
        _lib.check(lib.pd_scene_resolve_opts(self._p, o, out, err), err)
        self._method_by = have["method_by"] or "default"
        return o, out

    def simulate_records(self, records: Sequence[Any], history: bool = False, every: Int = 1,
                         **opts: Any) -> Result:
        """A suite of records on this scene, as `pound simulate --scene F
        --record R1 --record R2 ... --json`: each record (a file, a
        pound.Record, or an array with record_dt and units) replaces the
        excitation in turn (the scene's duration derived for it unless
        tend), r.records holds each run (as simulate() gives it) and r.stats
        per structure the suite's statistics of its largest storey's umax,
        drift_ratio, acc_max, base shear_max and gamma, and per contact how
        often it closed, the statistics of its required gap, impacts, largest
        impulse and the code rules' gaps, and how often each rule's gap would
        have been closed.  target_pga=A or target_sa=A [m/s^2] (T1 [s],
        default the first structure's period) scale each record; the scene's
        own excitation is back afterwards."""
        from ._osc import _suite_record, suite_target
        case = {k: opts.pop(k) for k in ("units", "record_format", "record_dt", "target_pga",
                                         "target_sa", "T1", "scale") if k in opts}
        if isinstance(records, (str, bytes, os.PathLike)) or not isinstance(
                records, (list, tuple)) or not records:
            raise InputError("records: a list of record files, pound.Records or arrays (a suite)")
        kind, value, T1, _ = suite_target(case, self._sc.st[0].T0)
        base = number("scale", case.get("scale", 1.0))
        sc = self._sc
        saved, saved_tend, kept, runs = sc.exc, sc.tend, [], []
        kept_sums: List[Any] = []
        saved = _lib.PdSceneExcitation.from_buffer_copy(saved)
        err = PdErr()
        try:
            for item in records:
                rec = _suite_record(item, case)
                kept.append(rec)  # the scene points at it while it runs
                scale = ctypes.c_double(base)
                if kind:
                    _lib.check(lib.pd_record_scale_to(rec.rec, rec.pulse, kind, value,
                                                      T1 or 0.0, 0.05, scale, err), err)
                lib.pd_scene_excite_record(ctypes.byref(sc.exc), rec.rec, rec.pulse, scale.value)
                sc.tend = 0.0
                _lib.check(lib.pd_scene_finish(self._p, err), err)
                runs.append(self._run(history, every, opts, keep=kept_sums))
            stats = _suite_stats(self, kept_sums)
        finally:
            for sm in kept_sums:
                lib.pd_scene_summary_free(sm)
            ctypes.memmove(ctypes.byref(sc.exc), ctypes.byref(saved), ctypes.sizeof(saved))
            sc.tend = saved_tend
            lib.pd_scene_finish(self._p, err)
        out = Result(n=len(runs))
        if kind:
            out.update(target="pga" if kind == 1 else "sa", target_value=value)
        out["records"] = runs
        out["stats"] = stats
        return out

    def simulate(self, history: bool = True, every: Int = 1, **opts: Any) -> Result:
        """The run and its contact-free twin, as `pound simulate --scene F
        --json`: per structure (r.structures) umax, u_pos, u_neg, drift,
        umax_free [m] and Pi1, gamma (one value per storey), T0 [s], Pi2; per
        contact (r.contacts) impacts, first_impact [s], max_impulse [N s],
        contact_time [s], approach [m], Pi3, chi, required_gap [m] (the
        separation it needs, exact by method="event") and rules {abs, srss,
        ddc} [m] (the codes' estimates); dt, tend [s], Le [m], ap
        [m/s^2], Tp [s], impacts (all contacts), cpu_s [s of CPU]; the demands
        (docs/scenes.md, "Demands"): per structure storey_heights [m],
        drift_ratio, acc_max [m/s^2], shear_max, base_shear_max [N], per
        contact force_equiv, force_max [N] (NaN: not a penalty method), and
        contact_duration [s]; a structure with yielding storeys ("uy" in the
        scene) also uy [m], yield_alpha, ductility, residual [m],
        plastic_excursion [m] and n_yield per storey (NaN, 0 for an elastic
        storey), and over the scene the energy balance energy_input,
        _kinetic, _strain, _damping, _hysteretic, _impact [J] with
        energy_residual (Moreau-Jean; NaN for newmark).  opts: the scheme
        keywords of simulate()
        (method, dt, tend, theta, ..., contact_duration; rtol as there:
        Moreau-Jean to a tolerance, or with method='penalty' the integrator's).
        Moreau-Jean to a tolerance: rtol (0: fixed steps), err_est (the
        largest estimated relative error of the peaks, umax, drift and
        demands of every structure, the run's and its contact-free twin's;
        NaN for fixed steps, the CLI's null) and per structure err_est (its
        own), rtol_met (True when err_est <= rtol and no step floor or budget
        stopped the refinement; True without a tolerance), steps_rejected
        (tries halved), dt_min and dt_max [s] (the smallest and largest step
        kept: dt for fixed steps, NaN for the other methods).  With
        history,
        r.history: step, t (N), x and v (N x dofs) [m, m/s], gap [m] and
        impulse [N s] (N x contacts), every every-th sample, the impulses
        summed since the last one kept (the CLI's -o file; t, x, v also as
        r.t, r.x, r.v); a (N x dofs) [m/s^2], each floor's absolute
        acceleration as the demands measure it (the held contacts' forces in
        it, an impact's impulse not); with method 'penalty' or 'newmark' force
        (N x contacts) [N], each contact element's force; a scene with
        yielding storeys also up (N x dofs) [m], each storey's plastic offset
        (0 for an elastic storey).  r.history.dof and .contact name the
        columns (NAME.k, the storey k of structure NAME; A-B@k, the contact
        between sides A and B at level k); to_xarray() makes them the
        coordinates and gives each variable its CF units."""
        return self._run(history, every, opts)

    def _run(self, history, every, opts, keep=None):
        """simulate(); with keep, the run's pd_scene_summary is appended to it
        (the caller frees it) instead of freed here."""
        history, every = history_args(history, every)
        _, o = self.opts(opts)
        sc = self._sc
        n, m = sc.n, sc.ncontact
        h = sampler = None
        yields = bool(lib.pd_scene_springs(self._p))
        forces = s(lib.pd_method_name(o.method)) in ("penalty", "newmark") and m > 0
        names = (("step", "t", "x", "v", "gap", "impulse") + (("up",) if yields else ()) +
                 ("a",) + (("force",) if forces else ()))
        if history:
            dtype = [("step", "i8"), ("t", "f8"), ("x", "f8", (n,)), ("v", "f8", (n,)),
                     ("gap", "f8", (m,)), ("impulse", "f8", (m,))]
            if yields:  # the storeys' plastic offsets, as the CLI's NAME.upK columns
                dtype.append(("up", "f8", (n,)))
            dtype.append(("a", "f8", (n,)))  # the floors' absolute accelerations, NAME.aK
            if forces:  # the elements' forces, cK.force
                dtype.append(("force", "f8", (m,)))
            h = _History(dtype, history_cap(o, every), every)
            sampler = _scene_sampler(h, n, m)
        sm = _lib.PdSceneSummary()
        err = PdErr()
        try:
            st = lib.pd_scene_summarize(self._p, o, sampler or _lib.SceneSampler(),
                                        None, sm, err)
            if h is not None and h.error is not None:
                raise h.error
            _lib.check(st, err)
            out = self._summary(sm)
            out["method_by"] = self._method_by
            if keep is not None:
                keep.append(sm)
        finally:
            if keep is None or not keep or keep[-1] is not sm:
                lib.pd_scene_summary_free(sm)
        if h is not None:
            rows = h.rows()
            hist = Result((name, np.ascontiguousarray(rows[name])) for name in names)
            hist["dof"], hist["contact"] = self._labels()
            out["history"] = hist
            for name in ("t", "x", "v"):  # shortcuts
                out[name] = hist[name]
        return out

    def _labels(self):
        """The dofs' names (NAME.k) and the contacts' (A-B@k: sides and level)."""
        sc = self._sc
        dofs = ["%s.%d" % (s(sc.st[i].name), k + 1) for i in range(sc.nstruct)
                for k in range(sc.st[i].storeys)]
        side = lambda j: "wall" if j < 0 else s(sc.st[j].name)  # noqa: E731
        contacts = []
        for a in range(sc.ncontact):
            c = sc.ct[a]
            level = c.level_b if c.a < 0 else c.level_a
            contacts.append("%s-%s@%d" % (side(c.a), side(c.b), level))
        return dofs, contacts

    def _summary(self, sm):
        sc, r = self._sc, sm.r
        out = Result(method=s(r.method), steps=r.steps, cpu_s=sm.cpu_s, cpu_s_run=r.cpu_s,
                     kernel=s(r.kernel), factor=s(r.factor), lcp_solver=s(r.lcp_solver),
                     lcp_solves=r.lcp_solves, dt=r.dt, theta=r.theta, tend=r.tend, dofs=sc.n,
                     impacts=sum(r.impacts[c] for c in range(sc.ncontact)),
                     simultaneous=r.simultaneous, tol_closed=r.tol_closed,
                     accumulations=r.accumulations, close_tol=r.close_tol,
                     impact_law=s(r.impact_law) if r.impact_law else "none",
                     law_band=r.law_band_max)
        if lib.pd_scene_springs(self._p):  # a yielding scene's energy balance [J], as the CLI's
            en = r.energy
            out.update(energy_input=en.input, energy_kinetic=en.kinetic,
                       energy_strain=en.strain, energy_damping=en.damping,
                       energy_hysteretic=en.hysteretic, energy_impact=en.impact,
                       energy_residual=en.residual)
        out.update(tolerance_fields(r, sm))
        x = self.excitation
        out["pulse"], out["dir"] = x["pulse"], x["dir"]
        if "record" in x:
            out["record"], out["scale"] = x["record"], x["scale"]
        out.update(ap=sc.exc.ap, Tp=sc.exc.Tp, Le=self.Le)
        structs = []
        for k in range(sc.nstruct):
            st = sc.st[k]
            o, ns = st.dof, st.storeys

            def part(p, o=o, ns=ns):
                return np.ctypeslib.as_array(p, (o + ns,))[o:].copy()
            one = Result(name=s(st.name), storeys=ns, T0=st.T0, Pi2=sm.Pi2[k],
                         umax=part(r.umax), u_pos=part(r.u_pos), u_neg=part(r.u_neg),
                         drift=part(r.drift), Pi1=part(sm.Pi1),
                         umax_free=part(sm.free.umax), gamma=part(sm.gamma),
                         err_est=sm.err_est_structure[k],
                         law_band=r.law_band[k])
            if st.uy:  # yielding storeys (SPEC section 7), as the CLI's JSON
                one.update(uy=np.ctypeslib.as_array(st.uy, (ns,)).copy(),
                           yield_alpha=np.ctypeslib.as_array(st.yield_alpha, (ns,)).copy(),
                           ductility=part(r.ductility), residual=part(r.residual),
                           plastic_excursion=part(r.plastic_excursion),
                           n_yield=np.ctypeslib.as_array(r.n_yield, (o + ns,))[o:].copy())
            structs.append(one)
        out["structures"] = structs
        contacts = []
        for a in range(sc.ncontact):
            ct = sc.ct[a]
            contacts.append(Result(a=self._side(ct.a), b=self._side(ct.b),
                                   level=ct.level_b if ct.a == PD_WALL else ct.level_a,
                                   level_b=ct.level_b, gap=ct.gap, eps=ct.eps, Pi3=sm.Pi3[a],
                                   impacts=r.impacts[a], first_impact=r.first_impact[a],
                                   max_impulse=r.max_impulse[a],
                                   contact_time=r.contact_time[a], approach=r.approach[a],
                                   chi=sm.chi[a], required_gap=sm.required_gap[a],
                                   rules={"abs": sm.rule_abs[a], "srss": sm.rule_srss[a],
                                          "ddc": sm.rule_ddc[a]}))
        out["contacts"] = contacts
        _demand.scene_fields(out, sc, r)
        return out

    def __repr__(self) -> str:
        if not self._p:
            return "<pound.Scene closed>"
        sc = self._sc
        return "<pound.Scene %s: %d structures, %d dofs, %d contacts>" % (
            self.path, sc.nstruct, sc.n, sc.ncontact)


def _scene_sampler(h, n, m):
    """Copy t, x, v, gap, impulse of every every-th sample into the history,
    as the CLI's scene writer keeps them (cli/scene_out.c): samples counted,
    the impulses of the samples left out added to the next one kept."""
    memmove = ctypes.memmove
    PdSceneSample = _lib.PdSceneSample
    item = h.dtype.itemsize
    off = {k: f[1] for k, f in h.dtype.fields.items()}
    with_up = "up" in off
    with_force = "force" in off
    nb, mb = 8 * n, 8 * m
    acc = np.zeros(m)
    state = {"seen": 0}
    every = h.every

    def sample(p, ctx):
        try:
            x = PdSceneSample.from_address(p)
            if every > 1:
                if m and x.impulse:
                    acc.__iadd__(np.ctypeslib.as_array(x.impulse, (m,)))
                seen = state["seen"]
                state["seen"] = seen + 1
                if seen % every:
                    return 0
            if h.n == len(h.buf):
                h.grow()
            base = h.buf.ctypes.data + h.n * item
            memmove(base, p, 16)  # step, t
            if nb:
                memmove(base + off["x"], x.x, nb)
                memmove(base + off["v"], x.v, nb)
            if mb and x.gap:
                memmove(base + off["gap"], x.gap, mb)
            if mb and every > 1:
                h.buf["impulse"][h.n] = acc
                acc[:] = 0.0
            elif mb and x.impulse:
                memmove(base + off["impulse"], x.impulse, mb)
            if with_up and nb and x.up:
                memmove(base + off["up"], x.up, nb)
            if nb and x.a_abs:
                memmove(base + off["a"], x.a_abs, nb)
            elif nb:
                h.buf["a"][h.n] = np.nan
            if with_force and mb and x.force:
                memmove(base + off["force"], x.force, mb)
            h.n += 1
            return 0
        except BaseException as e:
            h.error = e
            return 1
    return _lib.SceneSampler(sample)


def scene(path: PathArg) -> Scene:
    """Read a scene file (JSON, docs/scenes.md): a pound.Scene."""
    return Scene(path)


def _stats(st):
    return Result(n=st.n, mean=st.mean, median=st.median, p16=st.p16, p84=st.p84, min=st.min,
                  max=st.max)


def _peaks(p, yields):
    out = Result((f, _stats(getattr(p, f))) for f in
                 ("umax", "drift_ratio", "acc_max", "shear_max", "gamma", "umax_free"))
    if yields:
        out["ductility"] = _stats(p.ductility)
    return out


def _suite_stats(scene, sums):
    """A scene suite's statistics (pd_scene_suite_stats, the CLI's) of the
    runs' summaries sums."""
    arr = (_lib.PdSceneSummary * len(sums))()
    for k, sm in enumerate(sums):
        ctypes.memmove(ctypes.byref(arr[k]), ctypes.byref(sm), ctypes.sizeof(sm))
    st, err = _lib.PdSceneSuite(), PdErr()
    _lib.check(lib.pd_scene_suite_stats(scene._p, arr, len(sums), st, err), err)
    try:
        sc, yields = scene._sc, bool(lib.pd_scene_springs(scene._p))
        structs, contacts = [], []
        for k in range(sc.nstruct):
            S = sc.st[k]
            one = Result(name=s(S.name))
            one.update(_peaks(st.structure[k], yields))
            one["storeys"] = [Result(storey=i + 1, **_peaks(st.storey[S.dof + i], yields))
                              for i in range(S.storeys)]
            structs.append(one)
        for c in range(sc.ncontact):
            ct, side = st.contact[c], (lambda j: "wall" if j < 0 else s(sc.st[j].name))
            k = sc.ct[c]
            one = Result(sides="%s-%s" % (side(k.a), side(k.b)),
                         level=k.level_b if k.a < 0 else k.level_a, closed=ct.closed,
                         required_gap=_stats(ct.required_gap), impacts=_stats(ct.impacts),
                         max_impulse=_stats(ct.max_impulse),
                         contact_time=_stats(ct.contact_time),
                         force_equiv=_stats(ct.force_equiv), force_max=_stats(ct.force_max))
            one["rules"] = Result(abs=_stats(ct.rule_abs), srss=_stats(ct.rule_srss),
                                  ddc=_stats(ct.rule_ddc))
            one["rule_closed"] = Result(abs=ct.abs_closed, srss=ct.srss_closed,
                                        ddc=ct.ddc_closed)
            contacts.append(one)
        return Result(structures=structs, contacts=contacts)
    finally:
        lib.pd_scene_suite_free(st)


def simulate_scene(path: Union[PathArg, Scene], history: bool = True, every: Int = 1,
                   **opts: Any) -> Result:
    """`pound simulate --scene path --json`: Scene(path).simulate(**opts), the
    keys and units of Scene.simulate (path may be a Scene, left open)."""
    sc = path if isinstance(path, Scene) else Scene(path)
    try:
        return sc.simulate(history=history, every=every, **opts)
    finally:
        if sc is not path:
            sc.close()


# ---- compare and converge on a scene -------------------------------------------------------

def ref_decisions(rr):
    """The decisions the reference run rr rests on, as the CLI's keys."""
    return dict(simultaneous_ref=rr.simultaneous, tol_closed_ref=rr.tol_closed,
                accumulations_ref=rr.accumulations, close_tol=rr.close_tol)


class SceneMeasurer:
    """The reference of a scene and the runs measured against it (the
    scene half of cli/cmd_converge.c's measurer)."""

    def __init__(self, scene, kw):
        self.scene = scene if isinstance(scene, Scene) else Scene(scene)
        self.own = self.scene is not scene
        self.sc = self.scene._p
        self.opts, _ = self.scene._opts(kw, listed=True)  # checked and resolvable; unresolved
        self.ref = _lib.PdSceneTrace()
        self.rr = _lib.PdSceneResult()
        self.res = _lib.PdSceneResult()
        self.e = _lib.PdSceneErrors()
        self.live = False

    def alloc(self, o):
        err = PdErr()
        self.live = True
        for call in (lambda: lib.pd_scene_trace_alloc(self.ref, self.sc, o, err),
                     lambda: lib.pd_scene_result_alloc(self.sc, self.rr, err),
                     lambda: lib.pd_scene_result_alloc(self.sc, self.res, err),
                     lambda: lib.pd_scene_errors_alloc(self.sc, self.e, err)):
            _lib.check(call(), err)

    def warm_up(self, o, err):
        """cli/cmd_converge.c warm_up: ten untimed steps of o."""
        w = copy_opts(o)
        w.tend = 10.0 * (o.dt if o.dt > 0.0 else lib.pd_scene_default_dt(self.sc))
        w.no_demands = w.no_law_band = 1
        _lib.check(lib.pd_scene_run(self.sc, w, _lib.SceneSampler(), None, self.res, err), err)

    def reference(self, o, err):
        st = lib.pd_scene_measure_reference(self.sc, o, self.ref, self.rr, err)
        return st, self.rr.cpu_s

    def row(self, o, err):
        st = lib.pd_scene_measure_run(self.sc, o, self.ref, self.rr, self.res, self.e, err)
        if st:
            return st, None
        e, sc = self.e, self.scene._sc
        return st, dict(err_umax=e.err_umax_max, err_hist=e.err_hist_max, cpu_s=e.cpu_s,
                        impacts=e.impacts, steps=self.res.steps,
                        err_est=self.res.err_est_max if o.rtol > 0.0 else NAN,
                        structures=[Result(name=s(sc.st[k].name), err_umax_rel=e.err_umax[k],
                                           err_hist_linf=e.err_hist[k])
                                    for k in range(sc.nstruct)])

    def summary(self):
        """The reference's impacts and decisions (converge --json)."""
        sc = self.scene._sc
        return dict(impacts_ref=sum(self.rr.impacts[a] for a in range(sc.ncontact)),
                    **ref_decisions(self.rr))

    def close(self):
        if self.live:
            lib.pd_scene_trace_free(self.ref)
            lib.pd_scene_result_free(self.rr)
            lib.pd_scene_result_free(self.res)
            lib.pd_scene_errors_free(self.e)
            self.live = False
        if self.own:
            self.scene.close()


def compare_scene(scene, want, kw):
    """cli/cmd_compare.c compare_scene."""
    M = SceneMeasurer(scene, kw)
    try:
        err = PdErr()
        o = M.opts
        M.alloc(o)
        st = lib.pd_scene_measure_reference(M.sc, o, M.ref, M.rr, err)
        if st:
            raise _lib.make_error(st, "reference: " + err_text(err))
        sc = M.scene._sc
        rows = {}
        for m in range(len(want)):
            if not want[m]:
                continue
            om = copy_opts(o)
            om.method = m
            res, e = _lib.PdSceneResult(), _lib.PdSceneErrors()
            try:
                _lib.check(lib.pd_scene_result_alloc(M.sc, res, err), err)
                _lib.check(lib.pd_scene_errors_alloc(M.sc, e, err), err)
                st = lib.pd_scene_measure_run(M.sc, om, M.ref, M.rr, res, e, err)
                if st:
                    raise _lib.make_error(st, "%s: %s" % (s(lib.pd_method_name(m)), err_text(err)))
                rows[m] = Result(method=s(lib.pd_method_name(m)), err_umax_rel=e.err_umax_max,
                                 err_hist_linf=e.err_hist_max, impacts=e.impacts,
                                 steps=res.steps, cpu_s=e.cpu_s,
                                 structures=[Result(name=s(sc.st[k].name),
                                                    err_umax_rel=e.err_umax[k],
                                                    err_hist_linf=e.err_hist[k])
                                             for k in range(sc.nstruct)])
                rows[m]["dt"] = res.dt
            finally:
                lib.pd_scene_result_free(res)
                lib.pd_scene_errors_free(e)
        impacts_ref = sum(M.rr.impacts[a] for a in range(sc.ncontact))
        first = want.index(1)
        f = rows[first]
        out = Result(method=f["method"], err_umax_rel=f["err_umax_rel"],
                     err_hist_linf=f["err_hist_linf"], impacts=f["impacts"],
                     impacts_ref=impacts_ref, cpu_s=f["cpu_s"], cpu_s_ref=M.rr.cpu_s,
                     events_ref=M.rr.steps, **ref_decisions(M.rr), dt=f["dt"])
        for r in rows.values():
            del r["dt"]
        out["methods"] = [rows[m] for m in range(len(want)) if want[m]]
        return out
    finally:
        M.close()
