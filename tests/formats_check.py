#!/usr/bin/python3
"""formats_check.py: every kind of file pound writes, read back with h5py
and numpy, and compared with docs/formats.md.

    /usr/bin/python3 tests/formats_check.py build/pound

The script reads the tables of docs/formats.md: datasets (shape, dtype,
units) and attributes (type, units). In a temporary folder it runs pound to
produce each kind of file: oscillator and scene histories (HDF5 and CSV),
LCP dumps (a scene's and an oscillator's), convergence tables, spectra and
scene spectra (HDF5 and CSV), and the spectrum journal. For each file it
asserts:

- the datasets and their shapes, dtypes and `units` are what the page
  promises, with shapes consistent with the --json summary of the same
  command (for example rows = steps / every + 1);
- every attribute is documented, with its type and `<name>_units`;
- the provenance: `format`, `command` (equal to the arguments used, shell
  quoted; spectra without -o/--plot/--json/--threads/--resume/--stop-after),
  `pound_version` (that of `pound --version`, else PD_VERSION in
  core/pd_core.h) and `created` (UTC ISO 8601, now; absent from spectra);
- a few values against --json, such as max |u| = umax within 1e-12;
- every group opened by xarray (engine="h5netcdf", Debian's python3-xarray
  and python3-h5netcdf; skipped, and said so, without them): no phony
  dimension, each variable along the dims the page names with the lengths
  h5py reads, the dimensions with values coordinates, text attributes str;
  and, when netCDF-C's ncdump is installed (netcdf-bin), every HDF5 file
  read by `ncdump -h` without a phony dimension.

It exits 1 with one line per mismatch, and always prints one summary line.
It needs Debian's python3-h5py and python3-numpy.
"""
import datetime
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

try:
    import h5py
    import numpy as np
except ImportError as e:  # the wrong interpreter: say which one is needed
    sys.exit(f"formats_check: {e} (run with /usr/bin/python3, which has h5py and numpy)")
try:  # the files opened by xarray too (python3-xarray, python3-h5netcdf)
    import h5netcdf  # noqa: F401  (xarray's engine="h5netcdf")
    import xarray as xr
except ImportError:
    xr = None
NCDUMP = shutil.which("ncdump")  # netCDF-C's (Debian's netcdf-bin), when installed

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOC = os.path.join(ROOT, "docs", "formats.md")
SCENE = os.path.join(ROOT, "examples", "scenes", "two-sdof.json")
YSCENE = os.path.join(ROOT, "examples", "scenes", "yielding-buildings.json")
PROVENANCE = ["format", "command", "pound_version", "created"]
SPECTRUM_DROPPED = {"-o": 1, "--plot": 1, "--threads": 1, "--stop-after": 1, "--json": 0, "--resume": 0}

failures = []
checks = 0


def check(ok, msg):
    """One assertion: remembered when it fails."""
    global checks
    checks += 1
    if not ok:
        failures.append(msg)
    return ok


def text(v):
    """An HDF5 text attribute as str (h5py gives bytes for fixed-length strings)."""
    return v.decode() if isinstance(v, (bytes, np.bytes_)) else v


def close(a, b, rel=1e-12):
    """Equal within rel (NaN equals NaN; None, JSON's null, is NaN)."""
    a = float("nan") if a is None else float(a)
    b = float("nan") if b is None else float(b)
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


# ---- the page ------------------------------------------------------------------

def cells(line):
    """The cells of a Markdown table row (\\| is a pipe inside a cell)."""
    parts = re.split(r"(?<!\\)\|", line.strip())[1:-1]
    return [p.strip().replace("\\|", "|") for p in parts]


def unquote(c):
    return c.strip().strip("`")


def parse_doc(path):
    """{format: {"datasets": [...], "attrs": {object: {name: (type, units)}}}},
    with "Provenance" for the provenance table."""
    doc, section, lines = {}, None, open(path, encoding="utf-8").read().splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("## "):
            m = re.search(r"\(`(pound [^`]+ \d+)`\)", line)
            section = m.group(1) if m else ("Provenance" if "Provenance" in line else None)
            if section:
                doc.setdefault(section, {"datasets": [], "attrs": {}})
        if section and line.startswith("|") and i + 1 < len(lines) and lines[i + 1].startswith("| ---"):
            head = cells(line)
            rows = []
            i += 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(cells(lines[i]))
                i += 1
            if head[0] == "dataset":
                for r in rows:
                    c = dict(zip(head, r))
                    doc[section]["datasets"].append(
                        {"name": unquote(c["dataset"]), "shape": unquote(c["shape"]),
                         "dims": tuple(d.strip() for d in unquote(c.get("dims", "()")).strip("()").split(",") if d.strip()),
                         "dtype": c["dtype"], "units": c["units"],
                         "valueless": "without values" in c.get("contents", ""),
                         "yielding": YIELDING.match(c.get("contents", "")) is not None,
                         "penalty": PENALTY.match(c.get("contents", "")) is not None})
            elif head[0].startswith("root attribute") or head[0].startswith("attribute of"):
                m = re.match(r"attribute of `([^`]+)`", head[0])
                obj = m.group(1) if m else "/"
                q = re.search(r"\((\w+)\)", head[0])
                key = obj + (":" + q.group(1) if q else "")
                for r in rows:  # a yielding run's only: their own table, key:yielding
                    k = key + (":yielding" if YIELDING.match(r[3]) else "")
                    doc[section]["attrs"].setdefault(k, {})[unquote(r[0])] = \
                        (r[1], None if r[2] == "—" else r[2])
            continue
        i += 1
    return doc


# a row the page marks "a yielding oscillator's only", "a yielding sweep's only" or
# "a yielding structure's only"
YIELDING = re.compile(r"a yielding (oscillator|sweep|structure)'s only")
PENALTY = re.compile(r"penalty and newmark only")


def pattern(name):
    """A documented path (NAME, K, NNNN placeholders) as a regular expression."""
    rx = re.escape(name).replace("NAME", r"[^/]+").replace("NNNN", r"\d{4}")
    rx = re.sub(r"(^|/)K(/|$)", r"\1\\d+\2", rx)
    return re.compile("^" + rx + "$")


# ---- running pound -------------------------------------------------------------

def run(pound, args, cwd, want=0):
    """pound with args in cwd: its stdout (checked exit status want)."""
    p = subprocess.run([pound] + args, cwd=cwd, capture_output=True, text=True, timeout=120)
    check(p.returncode == want, f"pound {shlex.join(args)}: exit {p.returncode} (want {want}): {p.stderr.strip()[:300]}")
    return p.stdout


def command_of(args, spectrum=False):
    """What the files' `command` must be for these arguments."""
    kept, i = [], 0
    while i < len(args):
        if spectrum and i > 0 and args[i] in SPECTRUM_DROPPED:
            i += 1 + SPECTRUM_DROPPED[args[i]]
            continue
        kept.append(args[i])
        i += 1
    return "pound" + "".join(" " + shlex.quote(a) for a in kept)


def version_of(pound):
    """`pound --version`'s number, else PD_VERSION of core/pd_core.h."""
    try:
        p = subprocess.run([pound, "--version"], capture_output=True, text=True, timeout=30)
        m = re.match(r"pound (\S+)", p.stdout)
        if p.returncode == 0 and m:
            return m.group(1)
    except OSError:
        pass
    m = re.search(r'#define PD_VERSION "([^"]+)"', open(os.path.join(ROOT, "core", "pd_core.h")).read())
    return m.group(1) if m else None


# ---- checking a file -----------------------------------------------------------

class Ctx:
    def __init__(self, pound, tmp, doc, version):
        self.pound, self.tmp, self.doc, self.version = pound, tmp, doc, version
        self.files = 0
        self.xarray_groups, self.xarray_skipped, self.ncdumped = 0, False, 0
        self.t0 = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)


def check_provenance(ctx, where, get, fmt, command, reproducible):
    """get(name): the value or None."""
    check(get("format") == fmt, f"{where}: format {get('format')!r}, want {fmt!r}")
    check(get("command") == command, f"{where}: command {get('command')!r}, want {command!r}")
    check(get("pound_version") == ctx.version, f"{where}: pound_version {get('pound_version')!r}, want {ctx.version!r}")
    created = get("created")
    if reproducible:
        check(created is None, f"{where}: a reproducible file has created = {created!r}")
        return
    ok = created is not None and re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", created)
    if check(ok, f"{where}: created {created!r} is not UTC ISO 8601 (YYYY-MM-DDTHH:MM:SSZ)"):
        t = datetime.datetime.strptime(created, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=datetime.timezone.utc)
        now = datetime.datetime.now(datetime.timezone.utc)
        check(ctx.t0 - datetime.timedelta(seconds=2) <= t <= now + datetime.timedelta(seconds=2),
              f"{where}: created {created} is not the time of the run ({ctx.t0:%Y-%m-%dT%H:%M:%SZ} .. {now:%H:%M:%SZ})")


def check_attrs(where, obj, documented, extra=()):
    """obj's attributes against documented {name: (type, units)}: every one
    present with its type and units companion, none undocumented."""
    names = set(obj.attrs.keys())
    for name, (typ, units) in documented.items():
        if not check(name in names, f"{where}: attribute {name} missing"):
            continue
        v = obj.attrs[name]
        if typ == "text":
            check(isinstance(v, (bytes, np.bytes_, str)), f"{where}: attribute {name} is not text")
            check(name + "_units" not in names, f"{where}: text attribute {name} has units")
            continue
        arr = np.asarray(v)
        check(arr.dtype == np.float64, f"{where}: attribute {name} is {arr.dtype}, want float64")
        check((arr.ndim == 1) == ("(" in typ), f"{where}: attribute {name} has shape {arr.shape}, the page says {typ}")
        u = obj.attrs.get(name + "_units")
        check(u is not None and text(u) == units, f"{where}: {name}_units = {text(u)!r}, want {units!r}")
    known = set(documented) | {n + "_units" for n in documented} | set(extra)
    for n in sorted(names - known):
        check(False, f"{where}: attribute {n} is not in docs/formats.md")


def check_h5(ctx, path, fmt, command, env, reproducible=False, root_qualifier=None, units_all=None,
             yielding=False, penalty=False):
    """An HDF5 file against the page: provenance, datasets (shape from env,
    which may be a function of the path), attributes (a yielding run's
    rows too when yielding, else none of them).  The open file."""
    ctx.files += 1
    where = os.path.basename(path)
    spec = ctx.doc[fmt]
    f = h5py.File(path, "r")
    check_provenance(ctx, where, lambda n: text(f.attrs[n]) if n in f.attrs else None, fmt, command, reproducible)
    for n in ("format", "command", "pound_version", "created"):
        if n in f.attrs:
            check(isinstance(f.attrs[n], (bytes, np.bytes_)), f"{where}: {n} is not text")
    prov = {n: ctx.doc["Provenance"]["attrs"]["/"][n] for n in PROVENANCE if n in f.attrs}
    root = dict(spec["attrs"].get("/", {}))
    if root_qualifier:
        root.update(spec["attrs"]["/:" + root_qualifier])
    if yielding:
        root.update(spec["attrs"].get("/:yielding", {}))
    check_attrs(where + " /", f, {**root, **prov})
    found, shapes = [], {}

    def walk(g, prefix):  # every link's name (visititems names a hard-linked dataset once)
        for k in g:
            o = g[k]
            if isinstance(o, h5py.Dataset):
                found.append(prefix + k)
            elif isinstance(o, h5py.Group):
                walk(o, prefix + k + "/")
    walk(f, "")
    datasets = [d for d in spec["datasets"] if (yielding or not d["yielding"]) and
                (penalty or not d.get("penalty"))]
    for d in datasets:
        check(any(pattern(d["name"]).match(n) for n in found), f"{where}: no dataset {d['name']}")
    for n in found:
        ds = f[n]
        docd = [d for d in datasets if pattern(d["name"]).match(n)]
        if not check(len(docd) == 1, f"{where}: dataset {n} matches {len(docd)} rows of docs/formats.md"):
            continue
        d = docd[0]
        want_units = units_all or d["units"]
        check(text(ds.attrs.get("units")) == want_units, f"{where}: {n}.units = {text(ds.attrs.get('units'))!r}, want {want_units!r}")
        check(ds.dtype.name == d["dtype"], f"{where}: {n} is {ds.dtype.name}, want {d['dtype']}")
        want = eval(d["shape"], {}, env(n) if callable(env) else env)
        check(ds.shape == want, f"{where}: {n} has shape {ds.shape}, want {d['shape']} = {want}")
        check(len(d["dims"]) == ds.ndim, f"{where}: {n}: the page names dims {d['dims']} for {ds.ndim} axes")
        shapes[n] = (d["dims"], ds.shape)
    for key, documented in spec["attrs"].items():
        if key.startswith("/") or key.endswith(":yielding"):
            continue
        if yielding:
            documented = {**documented, **spec["attrs"].get(key + ":yielding", {})}
        rx = pattern(key)
        groups = []
        f.visititems(lambda n, o: groups.append(n) if isinstance(o, h5py.Group) and rx.match(n) else None)
        check(groups, f"{where}: no group {key}")
        for g in groups:
            check_attrs(f"{where} /{g}", f[g], documented)
    check_xarray(ctx, path, f, spec, shapes)
    return f


def check_xarray(ctx, path, f, spec, shapes):
    """Every group of the file opened by xarray (engine="h5netcdf"): no
    phony_dim; each variable along the dims the page names, of the lengths
    h5py reads; a dimension with values (a 1-D dataset of its name) a
    coordinate, one without values (NAME "This is a netCDF dimension but
    not a netCDF variable") absent from the variables; text attributes str."""
    if NCDUMP:  # netCDF-C reads it too, every axis named
        p = subprocess.run([NCDUMP, "-h", path], capture_output=True, text=True, timeout=60)
        check(p.returncode == 0 and "phony_dim" not in p.stdout,
              f"{os.path.basename(path)}: ncdump -h: exit {p.returncode} {p.stderr.strip()[:200]}"
              f"{' (phony dims)' if 'phony_dim' in p.stdout else ''}")
        ctx.ncdumped += 1
    if xr is None:
        ctx.xarray_skipped = True
        return
    where = os.path.basename(path) + " (xarray)"
    groups = [""]
    f.visititems(lambda n, o: groups.append(n) if isinstance(o, h5py.Group) else None)
    for g in groups:
        try:
            ds = xr.open_dataset(path, engine="h5netcdf", group=g or None)
        except Exception as e:  # phony dimensions refused, or a malformed scale
            check(False, f"{where}: group /{g}: {type(e).__name__}: {e}")
            continue
        with ds:
            check(not any(str(d).startswith("phony_dim") for d in ds.dims), f"{where}: /{g}: phony dims {dict(ds.dims)}")
            names = [n for n in shapes if n.rpartition("/")[0] == g]
            for n in names:
                dims, shape = shapes[n]
                leaf = n.rpartition("/")[2]
                valueless = b"not a netCDF variable" in bytes(f[n].attrs.get("NAME", b""))
                if valueless:
                    check(leaf not in ds.variables and ds.sizes.get(leaf) == shape[0],
                          f"{where}: /{n}: a dimension without values, xarray has {dict(ds.sizes)}")
                    continue
                if not check(leaf in ds.variables, f"{where}: /{n} is not a variable"):
                    continue
                v = ds[leaf]
                check(v.dims == dims and v.shape == shape, f"{where}: /{n} has dims {v.dims} {v.shape}, want {dims} {shape}")
                if dims == (leaf,):
                    check(leaf in ds.coords, f"{where}: /{n} is not a coordinate")
                u = v.attrs.get("units")
                check(isinstance(u, str), f"{where}: /{n}.units is {type(u).__name__}, want str")
            for k, a in ds.attrs.items():
                h = f[g or "/"].attrs[k]
                if isinstance(h, (bytes, np.bytes_, str)):
                    check(isinstance(a, str), f"{where}: /{g} attribute {k} is {type(a).__name__}, want str")
        ctx.xarray_groups += 1


def read_csv(path):
    """(comments as [(name, value)], header, units, rows as lists of str,
    comments after the rows)."""
    lines = open(path, encoding="utf-8").read().splitlines()
    k = 0
    meta = []
    while k < len(lines) and lines[k].startswith("#"):
        name, _, value = lines[k][2:].partition(" = ")
        meta.append((name, value))
        k += 1
    header = lines[k].split(",") if k < len(lines) else []
    rows, tail = [], []
    for line in lines[k + 1:]:
        if line.startswith("#"):
            name, _, value = line[2:].partition(" = ")
            tail.append((name, value))
        else:
            rows.append(line.split(","))
    units = dict(meta).get("units", "").split(",")
    return meta, header, units, rows, tail


def check_csv(ctx, path, fmt, command, columns, nrows, reproducible=False):
    """A CSV file: provenance first, units one per column, the header, the
    number of rows.  columns: [(name, units)].  (header, rows, meta dict, tail)."""
    ctx.files += 1
    where = os.path.basename(path)
    meta, header, units, rows, tail = read_csv(path)
    names = [n for n, _ in meta]
    want_first = PROVENANCE[:3] + ([] if reproducible else ["created"])
    check(names[:len(want_first)] == want_first, f"{where}: first # lines {names[:4]}, want {want_first}")
    md = dict(meta)
    check_provenance(ctx, where, md.get, fmt, command, reproducible)
    check(header == [c for c, _ in columns], f"{where}: header {header[:12]}..., want {[c for c, _ in columns][:12]}...")
    check(units == [u for _, u in columns], f"{where}: # units = {units[:12]}..., want {[u for _, u in columns][:12]}...")
    check(len(rows) == nrows, f"{where}: {len(rows)} rows, want {nrows}")
    check(all(len(r) == len(header) for r in rows), f"{where}: a row's width differs from the header's")
    return header, rows, md, dict(tail)


def column(header, rows, name):
    return np.array([float(r[header.index(name)]) for r in rows])


def columns(ctx, fmt, yielding=False):
    """The datasets of a format that are CSV columns too (not the HDF5
    dimensions without values; a yielding run's only when yielding)."""
    return [d for d in ctx.doc[fmt]["datasets"]
            if not d["valueless"] and (yielding or not d["yielding"])]


def doc_units(ctx, fmt, name):
    for d in ctx.doc[fmt]["datasets"]:
        if pattern(d["name"]).match(name):
            return d["units"]
    return None


# ---- the file kinds ------------------------------------------------------------

def oscillator(ctx):
    fmt = "pound simulate oscillator 1"
    base = ["simulate", "--pulse", "sine", "--Tp", "0.3", "--T0", "3", "--ap", "4", "--gap", "0.004",
            "--eps", "0.6", "--tend", "2", "--method", "moreau"]
    for every, out in ((1, "osc.h5"), (7, "osc run.csv")):
        args = base + ["--every", str(every), "-o", out, "--json"]
        j = json.loads(run(ctx.pound, args, ctx.tmp))
        n = j["steps"] // every + 1
        path = os.path.join(ctx.tmp, out)
        if out.endswith(".h5"):
            f = check_h5(ctx, path, fmt, command_of(args), {"N": n})
            u = f["u"][:]
            check(close(np.abs(u).max(), j["umax"]), f"{out}: max |u| = {np.abs(u).max()!r}, umax = {j['umax']!r}")
            check(close(u.max(), j["u_toward"]) and close(-u.min(), j["u_away"]), f"{out}: max u, max -u != u_toward, u_away")
            for k in ("umax", "Pi1", "impacts", "steps", "gamma", "dt", "first_impact"):
                check(close(f.attrs[k], j[k]), f"{out}: attribute {k} = {f.attrs[k]!r}, --json {j[k]!r}")
            check(np.count_nonzero(f["impulse"][:]) == j["impacts"], f"{out}: nonzero impulses != impacts")
            check(close(f["impulse"][:].max(), j["max_impulse"]), f"{out}: max impulse != max_impulse")
            check(close(f["t"][-1], j["steps"] * j["dt"], 1e-9), f"{out}: last t {f['t'][-1]} != steps dt")
            f.close()
        else:
            cols = [(d["name"], d["units"]) for d in columns(ctx, fmt)]
            header, rows, md, _ = check_csv(ctx, path, fmt, command_of(args), cols, n)
            check(close(float(md["umax"].split(" [")[0]), j["umax"]), f"{out}: # umax differs from --json")
            check(md["umax"].endswith(" [m]"), f"{out}: # umax has no [m]")
            u = column(header, rows, "u")
            check(np.abs(u).max() <= j["umax"] * (1 + 1e-12), f"{out}: a sampled |u| exceeds umax")
            check(close(column(header, rows, "t")[1], 7 * j["dt"]), f"{out}: the second row is not t = 7 dt")
    # the event-driven reference: each sample's impulse sums the impacts since the previous one
    # ((1 + eps) v of each); these impacts fall in different samples
    args = base[:-1] + ["event", "-o", "osc-event.h5", "--json"]
    j = json.loads(run(ctx.pound, args, ctx.tmp))
    f = h5py.File(os.path.join(ctx.tmp, "osc-event.h5"), "r")
    p = f["impulse"][:]
    f.close()
    check(np.count_nonzero(p) == j["impacts"] > 0, f"osc-event.h5: {np.count_nonzero(p)} nonzero impulses, {j['impacts']} impacts")
    check(close(p.max(), j["max_impulse"]), f"osc-event.h5: max impulse {p.max()!r} != max_impulse {j['max_impulse']!r}")


def scene(ctx):
    fmt = "pound simulate scene 1"
    shutil.copy(SCENE, os.path.join(ctx.tmp, "two sdof's.json"))  # a name the shell must quote
    for every, out in ((1, "scene.h5"), (5, "scene.csv")):
        args = ["simulate", "--scene", "two sdof's.json", "--tend", "2", "--every", str(every), "-o", out]
        if out.endswith(".h5"):
            args += ["--dump-lcp", "dump.h5"]
        j = json.loads(run(ctx.pound, args + ["--json"], ctx.tmp))
        args += ["--json"]
        n = j["steps"] // every + 1
        storeys = {s["name"]: s["storeys"] for s in j["structures"]}
        path = os.path.join(ctx.tmp, out)
        if out.endswith(".h5"):
            env = lambda p: {"N": n, "storeys": storeys.get(p.split("/")[1], -1) if p.startswith("structures/") else -1}
            f = check_h5(ctx, path, fmt, command_of(args), env)
            check(sorted(f["structures"].keys()) == sorted(storeys), f"{out}: structures {list(f['structures'])}")
            check(len(f["contacts"]) == len(j["contacts"]), f"{out}: {len(f['contacts'])} contacts")
            for s in j["structures"]:
                g = f["structures"][s["name"]]
                x = g["x"][:]
                ok = all(close(a, b) for a, b in zip(np.abs(x).max(axis=0), s["umax"]))
                check(ok, f"{out}: {s['name']}: max |x| {np.abs(x).max(axis=0)} != umax {s['umax']}")
                check(all(close(a, b) for a, b in zip(g.attrs["gamma"], s["gamma"])), f"{out}: {s['name']}: gamma")
            for k, c in enumerate(j["contacts"]):
                g = f["contacts"][str(k)]
                check(g.attrs["impacts"] == c["impacts"], f"{out}: contact {k}: impacts {g.attrs['impacts']} != {c['impacts']}")
                check(np.count_nonzero(g["impulse"][:]) == c["impacts"], f"{out}: contact {k}: nonzero impulses != impacts")
                check(close(g["impulse"][:].max(), c["max_impulse"]), f"{out}: contact {k}: max impulse")
                check(text(g.attrs["a"]) == c["a"] and text(g.attrs["b"]) == c["b"], f"{out}: contact {k}: a, b")
            check(text(f.attrs["scene"]) == "two sdof's.json", f"{out}: scene {text(f.attrs['scene'])!r}")
            f.close()
            lcp_dump(ctx, os.path.join(ctx.tmp, "dump.h5"), command_of(args), j["lcp_solves"], "scene")
        else:
            unit = {p: doc_units(ctx, fmt, p) for p in ("t", "structures/A/x", "structures/A/v", "structures/A/a", "contacts/0/gap", "contacts/0/impulse")}
            cols = [("t", unit["t"])]
            for part, key in (("x", "structures/A/x"), ("v", "structures/A/v")):
                cols += [(f"{s['name']}.{part}{i}", unit[key]) for s in j["structures"] for i in range(1, s["storeys"] + 1)]
            for part, key in (("gap", "contacts/0/gap"), ("impulse", "contacts/0/impulse")):
                cols += [(f"c{k}.{part}", unit[key]) for k in range(len(j["contacts"]))]
            cols += [(f"{s['name']}.a{i}", unit["structures/A/a"]) for s in j["structures"] for i in range(1, s["storeys"] + 1)]
            header, rows, _, tail = check_csv(ctx, path, fmt, command_of(args), cols, n)
            check(close(float(tail.get("steps", "nan").split(" [")[0]), j["steps"]), f"{out}: # steps after the rows")
            s0 = j["structures"][1]
            want = f"[{s0['umax'][0]!r}] [m]"
            got = tail.get(f"{s0['name']}.umax", "")
            check(close(float(got.split("]")[0].strip("[")), s0["umax"][0]) and got.endswith("] [m]"),
                  f"{out}: # {s0['name']}.umax = {got!r}, want {want}")
            check(tail.get("c0.a") == j["contacts"][0]["a"], f"{out}: # c0.a")
    # the penalty methods: each contact's element force too, its peak force_max
    args = ["simulate", "--scene", "two sdof's.json", "--tend", "2", "--method", "newmark", "-o",
            "pscene.h5", "--json"]
    j = json.loads(run(ctx.pound, args, ctx.tmp))
    storeys = {s["name"]: s["storeys"] for s in j["structures"]}
    with h5py.File(os.path.join(ctx.tmp, "pscene.h5"), "r") as g:
        n = len(g["t"])
    env = lambda p: {"N": n, "storeys": storeys.get(p.split("/")[1], -1) if p.startswith("structures/") else -1}
    f = check_h5(ctx, os.path.join(ctx.tmp, "pscene.h5"), fmt, command_of(args), env, penalty=True)
    for k, c in enumerate(j["contacts"]):
        check(close(f["contacts"][str(k)]["force"][:].max(), c["force_max"]), f"pscene.h5: contact {k}: max force != force_max")
    for s in j["structures"]:
        a = np.abs(f["structures"][s["name"]]["a"][:]).max(axis=0)
        check(all(b <= m * (1 + 1e-12) and b >= 0.99 * m for b, m in zip(a, s["acc_max"])),
              f"pscene.h5: {s['name']}: max |a| {a} against acc_max {s['acc_max']}")
    f.close()


def lcp_dump(ctx, path, command, solves, model):
    fmt = "pound LCP dump 1"
    with h5py.File(path, "r") as g:
        n = g["n"][:]
        cp = g["colptr"][:]
        count = len(n)
        starts = np.concatenate([[0], np.cumsum(n + 1)])
        nnz = int(sum(cp[starts[k + 1] - 1] for k in range(count)))
        env = {"count": count, "sum_n": int(n.sum()), "nnz": nnz}
    f = check_h5(ctx, path, fmt, command, env, units_all="1" if model == "oscillator" else None)
    where = os.path.basename(path)
    check(text(f.attrs["model"]) == model, f"{where}: model {text(f.attrs['model'])!r}, want {model!r}")
    check(f.attrs["count"] == count, f"{where}: count {f.attrs['count']} != len(n) {count}")
    if solves is not None:
        check(count == solves, f"{where}: {count} LCPs, --json lcp_solves {solves}")
    check(count > 0, f"{where}: no LCP dumped")
    f.close()


def oscillator_dump(ctx):
    args = ["simulate", "--pulse", "sine", "--Tp", "0.3", "--T0", "3", "--ap", "4", "--gap", "0.004",
            "--eps", "0.6", "--tend", "2", "--kernel", "general", "--dump-lcp", "odump.h5"]
    run(ctx.pound, args, ctx.tmp)
    lcp_dump(ctx, os.path.join(ctx.tmp, "odump.h5"), command_of(args), None, "oscillator")


def converge(ctx):
    fmt = "pound converge 1"
    cases = [("oscillator", ["converge", "--pulse", "sine", "--Tp", "0.3", "--T0", "3", "--ap", "4", "--gap",
                             "0.004", "--eps", "0.6", "--dt", "1e-3:2.5e-4:3", "--methods", "moreau,moreau-rtol,penalty",
                             "--rtols", "1e-3,1e-5", "--kcs", "1e3,1e4"]),
             ("scene", ["converge", "--scene", "two sdof's.json", "--tend", "2", "--dt", "1e-3:5e-4:2",
                        "--methods", "moreau,event-general"])]
    for kind, base in cases:
        for out in ("conv-%s.h5" % kind, "conv-%s.csv" % kind):
            args = base + ["-o", out, "--json"]
            j = json.loads(run(ctx.pound, args, ctx.tmp))["rows"]
            path = os.path.join(ctx.tmp, out)
            if out.endswith(".h5"):
                f = check_h5(ctx, path, fmt, command_of(args), {"rows": len(j)}, root_qualifier=kind)
                for k in ("theta", "dt", "kc", "err_umax_rel", "err_hist_linf", "order", "impacts", "steps",
                          "rtol", "err_est"):
                    ok = all(close(a, r[k]) for a, r in zip(f[k][:], j))
                    check(ok, f"{out}: {k} differs from --json rows")
                codes = {0: "moreau", 1: "event", 2: "penalty", 3: "auto", 4: "event-general",
                         5: "newmark"}
                check([codes[int(m)] for m in f["method"][:]] == [r["method"] for r in j], f"{out}: method codes")
                check(text(f["method"].attrs["codes"]) ==
                      "0 = moreau, 1 = event, 2 = penalty, 3 = auto, 4 = event-general, 5 = newmark",
                      f"{out}: codes")
                f.close()
            else:
                cols = [(d["name"], d["units"]) for d in columns(ctx, fmt)]
                header, rows, md, _ = check_csv(ctx, path, fmt, command_of(args), cols, len(j))
                check([r[0] for r in rows] == [r["method"] for r in j], f"{out}: method column")
                check(all(close(a, r["err_hist_linf"]) for a, r in zip(column(header, rows, "err_hist_linf"), j)),
                      f"{out}: err_hist_linf differs from --json")


def spectrum(ctx):
    fmt = "pound spectrum 1"
    base = ["spectrum", "--Pi2", "0.1:3:5", "--Pi3", "0.1,1", "--eps", "0.5", "--pulse", "sine,cosine"]
    for out, extra in (("spec.h5", ["--threads", "2"]), ("spec.csv", [])):
        args = base + extra + ["-o", out, "--json"]
        j = json.loads(run(ctx.pound, args, ctx.tmp))
        pts = j["points"]
        npi2 = 5
        path = os.path.join(ctx.tmp, out)
        command = command_of(args, spectrum=True)
        check(command == command_of(base), f"{out}: the spectrum command {command!r} keeps an execution flag")
        if out.endswith(".h5"):
            f = check_h5(ctx, path, fmt, command, {"npi2": npi2}, reproducible=True)
            curves = sorted(k for k in f.keys() if k.startswith("curve_"))
            check(len(curves) == j["curves"] == f.attrs["curves"], f"{out}: {len(curves)} curve groups, --json {j['curves']}")
            check(f.attrs["points"] == len(pts) == j["curves"] * npi2, f"{out}: points")
            pi1 = np.concatenate([f[c]["Pi1"][:] for c in curves])
            check(all(close(a, p["Pi1"]) for a, p in zip(pi1, pts)), f"{out}: Pi1 differs from --json points")
            umax = np.concatenate([f[c]["umax"][:] for c in curves])
            check(all(close(a, p["umax"]) for a, p in zip(umax, pts)), f"{out}: umax differs from --json points")
            for c in curves:
                g = f[c]
                k = int(c[6:])
                check(text(g.attrs["pulse"]) == pts[k * npi2]["pulse"] and close(g.attrs["Pi3"], pts[k * npi2]["Pi3"]),
                      f"{out}: {c}: pulse, Pi3 differ from the --json point")
            f.close()
        else:
            curve_attrs = ctx.doc[fmt]["attrs"]["curve_NNNN"]
            cols = [(n, "1" if curve_attrs[n][0] == "text" else curve_attrs[n][1])
                    for n in ("pulse", "dir", "method", "ap", "Tp", "Pi3", "gap", "eps", "xi")]
            cols += [(d["name"].split("/", 1)[1], d["units"]) for d in columns(ctx, fmt)]
            header, rows, md, _ = check_csv(ctx, path, fmt, command, cols, len(pts), reproducible=True)
            check(all(close(a, p["Pi1"]) for a, p in zip(column(header, rows, "Pi1"), pts)), f"{out}: Pi1 differs from --json")
            check([r[0] for r in rows] == [p["pulse"] for p in pts], f"{out}: pulse column")


def spectrum_scene(ctx):
    fmt = "pound spectrum scene 1"
    base = ["spectrum", "--scene", "two sdof's.json", "--Pi2", "0.2:2:4", "--Pi3", "0.1,0.5"]
    for out in ("sspec.h5", "sspec.csv"):
        args = base + ["--threads", "1", "-o", out, "--json"]
        j = json.loads(run(ctx.pound, args, ctx.tmp))
        pts = j["points"]
        names = [s["name"] for s in pts[0]["structures"]]
        path = os.path.join(ctx.tmp, out)
        command = command_of(args, spectrum=True)
        if out.endswith(".h5"):
            f = check_h5(ctx, path, fmt, command, {"points": len(pts)}, reproducible=True)
            for i, n in enumerate(names):
                for q in ("Pi1", "gamma", "umax"):
                    ok = all(close(a, p["structures"][i][q]) for a, p in zip(f[f"{n}.{q}"][:], pts))
                    check(ok, f"{out}: {n}.{q} differs from --json")
            check(all(close(a, p["Pi2"]) for a, p in zip(f["Pi2"][:], pts)), f"{out}: Pi2 differs from --json")
            check(text(f.attrs["reference"]) == j["reference"], f"{out}: reference")
            f.close()
        else:
            cols = []
            for d in columns(ctx, fmt):
                if d["name"].startswith("NAME."):
                    continue
                cols.append((d["name"], d["units"]))
            for n in names:
                cols += [(d["name"].replace("NAME", n), d["units"]) for d in ctx.doc[fmt]["datasets"]
                         if d["name"].startswith("NAME.")]
            header, rows, md, _ = check_csv(ctx, path, fmt, command, cols, len(pts), reproducible=True)
            check(all(close(a, p["structures"][1]["Pi1"]) for a, p in zip(column(header, rows, names[1] + ".Pi1"), pts)),
                  f"{out}: {names[1]}.Pi1 differs from --json")


def journal(ctx):
    """F.partial: an interrupted sweep leaves it (magic, key, T lines with a
    checksum); --resume finishes the file and removes it."""
    base = ["spectrum", "--Pi2", "0.1:3:5", "--Pi3", "0.1", "--threads", "1", "-o", "j.h5"]
    run(ctx.pound, base + ["--stop-after", "3"], ctx.tmp, want=130)
    part = os.path.join(ctx.tmp, "j.h5.partial")
    lines = open(part).read().splitlines() if os.path.exists(part) else []
    ctx.files += 1
    check(lines[:1] == ["pound-spectrum-journal 1"], f"j.h5.partial: first line {lines[:1]}")
    check(len(lines) > 1 and lines[1].startswith("key v=1 ") and "tasks=" in lines[1], "j.h5.partial: no key line")
    recs = lines[2:]
    check(len(recs) >= 3 and all(re.fullmatch(r"T \d+( \S+){8} #[0-9a-f]{8}", r) for r in recs),
          f"j.h5.partial: records {recs[:2]}")
    run(ctx.pound, base + ["--resume"], ctx.tmp)
    check(not os.path.exists(part) and os.path.exists(os.path.join(ctx.tmp, "j.h5")),
          "j.h5.partial: --resume did not finish the file and remove the journal")



def yielding(ctx):
    """A yielding oscillator's and a yielding sweep's files: the rows the
    page marks as theirs present, with the figures of --json."""
    fmt = "pound simulate oscillator 1"
    args = ["simulate", "--Piy", "0.3", "--alpha", "0.05", "--tend", "2", "--method", "moreau",
            "-o", "yield.h5", "--json"]
    j = json.loads(run(ctx.pound, args, ctx.tmp))
    f = check_h5(ctx, os.path.join(ctx.tmp, "yield.h5"), fmt, command_of(args),
                 {"N": j["steps"] + 1}, yielding=True)
    for k in ("ductility", "residual", "n_yield", "hysteretic_energy", "energy_residual"):
        check(close(f.attrs[k], j[k]), f"yield.h5: attribute {k} = {f.attrs[k]!r}, --json {j[k]!r}")
    f.close()
    fmt = "pound simulate scene 1"  # a yielding scene: the storeys' offsets up, their residuals
    for every, out in ((1, "yscene.h5"), (3, "yscene.csv")):
        args = ["simulate", "--scene", YSCENE, "--tend", "2", "--every", str(every), "-o", out,
                "--json"]
        j = json.loads(run(ctx.pound, args, ctx.tmp))
        n = j["steps"] // every + 1
        st = {s["name"]: s for s in j["structures"]}
        path = os.path.join(ctx.tmp, out)
        if out.endswith(".h5"):
            env = lambda p: {"N": n, "storeys": st[p.split("/")[1]]["storeys"] if p.startswith("structures/") else -1}
            f = check_h5(ctx, path, fmt, command_of(args), env, yielding=True)
            for name, s in st.items():
                up = f["structures"][name]["up"][:]
                res = [(1 - a) * u for a, u in zip(s["yield_alpha"], up[-1])]
                check(all(close(a, b) for a, b in zip(res, s["residual"])),
                      f"{out}: {name}: (1 - alpha) up at the end {res} != residual {s['residual']}")
            f.close()
        else:
            unit = {p: doc_units(ctx, fmt, p) for p in ("t", "structures/A/x", "structures/A/v",
                                                        "structures/A/up", "structures/A/a",
                                                        "contacts/0/gap", "contacts/0/impulse")}
            cols = [("t", unit["t"])]
            for part in ("x", "v"):
                cols += [(f"{s}.{part}{i}", unit["structures/A/" + part]) for s in st
                         for i in range(1, st[s]["storeys"] + 1)]
            for part in ("gap", "impulse"):
                cols += [(f"c{k}.{part}", unit["contacts/0/" + part]) for k in range(len(j["contacts"]))]
            cols += [(f"{s}.up{i}", unit["structures/A/up"]) for s in st for i in range(1, st[s]["storeys"] + 1)]
            cols += [(f"{s}.a{i}", unit["structures/A/a"]) for s in st for i in range(1, st[s]["storeys"] + 1)]
            header, rows, _, _ = check_csv(ctx, path, fmt, command_of(args), cols, n)
            for name, s in st.items():  # the last row's offsets give the residuals
                res = [(1 - a) * column(header, rows, f"{name}.up{i + 1}")[-1] for i, a in enumerate(s["yield_alpha"])]
                check(all(close(a, b) for a, b in zip(res, s["residual"])), f"{out}: {name}: residuals {res}")
    fmt = "pound spectrum 1"
    base = ["spectrum", "--Pi2", "0.5:3:4", "--Pi3", "0.1,0.5", "--Piy", "0.4", "--alpha", "0.05"]
    for out in ("yspec.h5", "yspec.csv"):
        args = base + ["-o", out, "--json"]
        j = json.loads(run(ctx.pound, args, ctx.tmp))
        pts, path = j["points"], os.path.join(ctx.tmp, out)
        if out.endswith(".h5"):
            f = check_h5(ctx, path, fmt, command_of(args, spectrum=True), {"npi2": 4},
                         reproducible=True, yielding=True)
            mu = np.concatenate([f[c]["ductility"][:] for c in sorted(f.keys())])
            check(all(close(a, p["ductility"]) for a, p in zip(mu, pts)), f"{out}: ductility differs from --json")
            f.close()
        else:
            curve_attrs = ctx.doc[fmt]["attrs"]["curve_NNNN"]
            cols = [(n, "1" if curve_attrs[n][0] == "text" else curve_attrs[n][1])
                    for n in ("pulse", "dir", "method", "ap", "Tp", "Pi3", "gap", "eps", "xi")]
            cols += [(d["name"].split("/", 1)[1], d["units"]) for d in columns(ctx, fmt, yielding=True)]
            header, rows, _, _ = check_csv(ctx, path, fmt, command_of(args, spectrum=True), cols,
                                           len(pts), reproducible=True)
            check(all(close(a, p["residual_uy"]) for a, p in zip(column(header, rows, "residual_uy"), pts)),
                  f"{out}: residual_uy differs from --json")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: /usr/bin/python3 tests/formats_check.py PATH/TO/pound")
    pound = os.path.abspath(sys.argv[1])
    if not os.access(pound, os.X_OK):
        sys.exit(f"formats_check: {pound}: not an executable")
    t0 = time.monotonic()
    doc = parse_doc(DOC)
    want = ["Provenance", "pound simulate oscillator 1", "pound simulate scene 1", "pound LCP dump 1",
            "pound converge 1", "pound spectrum 1", "pound spectrum scene 1"]
    missing = [w for w in want if w not in doc or (w != "Provenance" and not doc[w]["datasets"])]
    if missing:
        sys.exit(f"formats_check: docs/formats.md has no dataset table for {missing}")
    version = version_of(pound)
    with tempfile.TemporaryDirectory(prefix="pound_formats_") as tmp:
        ctx = Ctx(pound, tmp, doc, version)
        for kind in (oscillator, scene, oscillator_dump, converge, spectrum, spectrum_scene, journal,
                     yielding):
            try:
                kind(ctx)
            except Exception as e:  # a missing dataset or attribute: one line, go on
                check(False, f"{kind.__name__}: {type(e).__name__}: {e}")
        nfiles = ctx.files
    for m in failures:
        print("FAIL", m)
    status = "ok" if not failures else f"FAILED {len(failures)} of"
    opened = (f"xarray skipped: python3-xarray or python3-h5netcdf not installed" if ctx.xarray_skipped
              else f"{ctx.xarray_groups} groups opened by xarray")
    opened += f", {ctx.ncdumped} files by ncdump" if NCDUMP else ", ncdump not installed"
    print(f"formats_check: {status} {checks} checks on {nfiles} files of 7 kinds, {opened} "
          f"(pound {version}) in {time.monotonic() - t0:.1f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
