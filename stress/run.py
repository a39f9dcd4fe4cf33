#!/usr/bin/env python3
"""stress/run.py — pound's adversarial test suite (`make stress`).

    python3 stress/run.py [--pound build/pound] [--stress build/stress]
                          [--report docs/reliability.md] [--only CAT[,CAT]]
                          [--jobs N] [--timeout S] [--fuzz-time S] [--keep]

Every case runs the binary (a private copy, so that a concurrent rebuild
cannot change it under the suite) in its own scratch folder, under a time
limit (a case still running then is a "hang") and an address-space limit,
and is judged by the same rules (docs/reliability.md):

  - never a signal: no exit by a signal, no exit status >= 128;
  - never a wrong success: exit 0 only where the table allows it;
  - exit 2 (bad input): exactly one line on stderr, matching the case's regex
    (the flag the user typed, or FILE:LINE);
  - exit 1 (runtime error): the reason on one line of stderr (pound lcp: a
    status other than "solved" on stdout);
  - no file left behind by a failed run (no F, F.tmp*, F.partial; a
    spectrum's F.partial is kept on purpose after an interrupted sweep), and
    no temporary file after a successful one;
  - --json on success prints exactly one JSON object (no NaN or Infinity);
  - bounded memory: peak RSS under 1 GB;
  plus the checks of each category (an LCP answered "solved" is recomputed in
  exact rational arithmetic; a resumed spectrum equals the uninterrupted one).

Categories: flags, lcp, scene, record, journal, faults, hangs, fuzz, tsan.
One line per category ("flags: 1234 inputs, 2 failures"), then the
failures, then "stress: N failures"; exit 1 when there is any.  With
--report, the table between the markers <!-- stress table --> and
<!-- end stress table --> of that file is rewritten."""
import argparse
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import mutate  # noqa: E402

SHARED = os.path.normpath(os.path.join(ROOT, "..", "shared"))
AS_LIMIT = 4 << 30          # address space of every run (bytes)
RSS_BOUND_MB = 1024         # "bounded memory"
CATEGORIES = ["flags", "lcp", "scene", "record", "journal", "faults", "hangs", "fuzz", "tsan"]
CAT_TEXT = {
    "flags": "every flag of every command: NaN, inf, 1e308, 0, -1, denormals, empty, '1e', "
             "'0x10', 100 kB strings, unknown words, missing values, unknown and conflicting flags",
    "lcp": "LCP files, plain and Siconos: truncations, extra tokens, NaN/inf, huge and tiny "
           "numbers, bad sizes, letters, binary junk, CRLF; extreme well-formed problems "
           "with every solver, answers recomputed exactly",
    "scene": "scene JSON: truncations, wrong types, negative/zero/1e308/1e999/NaN values, "
             "duplicate keys, control bytes in names, huge arrays, records that are not files",
    "record": "records (AT2, COSMOS V2, text): truncated, wrong NPTS/DT, NaN, non-uniform time, "
              "empty, no header, binary junk, CRLF; records as excitations",
    "journal": "spectrum journals (F.partial) corrupted, then `spectrum -o F --resume`",
    "faults": "full disk (RLIMIT_FSIZE), stdout on /dev/full or closed, missing or "
              "read-only target folders, SIGTERM/SIGINT during long runs, then --resume",
    "hangs": "inputs that could loop or run away: extreme periods, stiff penalties, "
             "Zeno accumulations, /dev/zero as an input",
    "fuzz": "libFuzzer + ASan + UBSan on the readers: LCP, scene, record, spectrum journal",
    "tsan": "ThreadSanitizer on parallel spectrum sweeps (2 OpenMP threads); "
            "2 threads = 1 thread byte for byte",
}


# ---- running one case ----------------------------------------------------------


class Result:
    def __init__(self, rc=None, out=b"", err=b"", secs=0.0, rss_mb=0.0, timed_out=False):
        self.rc, self.out, self.err = rc, out, err
        self.secs, self.rss_mb, self.timed_out = secs, rss_mb, timed_out


class Case:
    """One input and what is expected of pound on it."""
    _n = 0
    _lock = threading.Lock()

    def __init__(self, cat, argv, expect, regex=None, inputs=None, timeout=None,
                 partial_ok=False, stdout=None, prefix=None, setup=None, check=None, run=None,
                 rss_mb=RSS_BOUND_MB, env=None, why=None, display=None, rc1_reason=True,
                 outputs=None, stderr_lost=False):
        with Case._lock:
            Case._n += 1
            self.id = Case._n
        self.cat, self.argv, self.expect = cat, list(argv), expect
        self.regex = regex
        self.inputs = inputs or {}
        self.timeout = timeout
        self.partial_ok = partial_ok
        self.stdout = stdout          # None: captured; a path: stdout goes there
        self.prefix = prefix or []    # wrapper command before pound (prlimit, sh -c)
        self.setup, self.check, self.run = setup, check, run
        self.rss_mb = rss_mb
        self.env = env
        self.why = why                # what the regex stands for, in failure messages
        self.display = display
        self.rc1_reason = rc1_reason  # exit 1 needs one line on stderr
        self.outputs = outputs        # names a success may create (None: any)
        self.stderr_lost = stderr_lost  # stderr cannot be written (2>/dev/full, --fsize=0)

    def command(self):
        if self.display:
            return self.display
        return "pound " + " ".join(short_arg(a) for a in self.argv)


def short_arg(a):
    if len(a) > 48:
        return "<%d x %r>" % (len(a), a[:1]) if len(set(a)) == 1 else \
            "<%d chars %s...>" % (len(a), shlex.quote(a[:16]))
    if a == "":
        return "''"
    return shlex.quote(a) if re.search(r"[^\w@%+=:,./-]", a) else a


class Runner:
    def __init__(self, pound, scratch, timeout, keep):
        self.pound, self.scratch, self.timeout, self.keep = pound, scratch, timeout, keep

    def exec(self, argv, cwd, timeout, stdout=None, prefix=(), env=None, stdin=None,
             aslimit=True):
        """Run pound (or prefix + pound) in cwd, under an address-space limit
        (not for sanitizer builds, whose shadow memory needs more): a Result."""
        io = tempfile.mkdtemp(dir=self.scratch, prefix="io-")
        outp, errp = os.path.join(io, "out"), os.path.join(io, "err")
        full_env = dict(os.environ)
        full_env.update(env or {})
        cmd = list(prefix) + [self.pound] + list(argv)
        if aslimit:
            cmd = ["prlimit", "--as=%d" % AS_LIMIT, "--"] + cmd
        with open(outp if stdout is None else stdout, "wb") as fo, open(errp, "wb") as fe:
            t0 = time.monotonic()
            p = subprocess.Popen(cmd, cwd=cwd, stdin=stdin if stdin is not None else subprocess.DEVNULL,
                                 stdout=fo, stderr=fe, start_new_session=True, env=full_env)
            res = wait_pid(p, timeout, t0)
        if stdout is None:
            res.out = read_head(outp)
        res.err = read_head(errp)
        shutil.rmtree(io, ignore_errors=True)
        return res


def wait_pid(p, timeout, t0):
    """Reap p (its own session) with os.wait4 for its peak RSS; SIGKILL the
    group past timeout."""
    delay, timed_out = 0.001, False
    while True:
        pid, status, ru = os.wait4(p.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() - t0 > timeout:
            timed_out = True
            kill_group(p.pid)
            pid, status, ru = os.wait4(p.pid, 0)
            break
        time.sleep(delay)
        delay = min(delay * 1.5, 0.05)
    p.returncode = os.waitstatus_to_exitcode(status)
    kill_group(p.pid)  # anything it started (gnuplot) goes with it
    return Result(rc=p.returncode, secs=time.monotonic() - t0, rss_mb=ru.ru_maxrss / 1024.0,
                  timed_out=timed_out)


def kill_group(pgid):
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def read_head(path, cap=64 << 20):
    with open(path, "rb") as f:
        return f.read(cap)


def listing(d):
    out = set()
    for root, dirs, files in os.walk(d):
        for name in dirs + files:
            out.add(os.path.relpath(os.path.join(root, name), d))
    return out


def signame(n):
    try:
        return signal.Signals(n).name
    except ValueError:
        return "signal %d" % n


def strict_json(text):
    def bad(c):
        raise ValueError("non-finite number %s" % c)
    return json.loads(text, parse_constant=bad)


def judge(case, res, new):
    """The rules every case follows: a list of failure strings."""
    f = []
    expect = case.expect.replace("=", "")
    if res.timed_out:
        f.append("hang: still running after %g s (killed)" % case.timeout)
    elif res.rc is None:
        pass
    elif res.rc < 0:
        f.append("signal: killed by %s" % signame(-res.rc))
    elif res.rc >= 128:
        f.append("signal: exit status %d" % res.rc)
    elif str(res.rc) not in expect:
        if res.rc == 0:
            f.append("wrong success: exit 0 where exit %s was expected" % "/".join(expect))
        else:
            f.append("exit %d, expected %s" % (res.rc, "/".join(expect)))
    lines = res.err.decode("utf-8", "replace").splitlines()
    if not res.timed_out and res.rc == 2 and not case.stderr_lost:
        if len(lines) != 1:
            f.append("exit 2 with %d lines on stderr (exactly one expected)" % len(lines))
        if case.regex and lines and not re.search(case.regex, lines[0]):
            f.append("exit 2 without naming %s" % (case.why or "/%s/" % case.regex))
    if not res.timed_out and res.rc == 1 and case.rc1_reason and not case.stderr_lost:
        if len(lines) != 1:
            f.append("exit 1 with %d lines on stderr (the reason on one line expected)"
                     % len(lines))
    if res.rss_mb > case.rss_mb:
        f.append("memory: peak RSS %.0f MB (bound %d MB)" % (res.rss_mb, case.rss_mb))
    failed = res.timed_out or res.rc != 0
    if failed:
        left = sorted(p for p in new if not (case.partial_ok and p.endswith(".partial")))
        if left:
            f.append("left behind after a failed run: " + ", ".join(left[:6]))
    else:
        tmp = sorted(p for p in new if re.search(r"\.tmp|\.partial$", os.path.basename(p)))
        if tmp:
            f.append("temporary files left after success: " + ", ".join(tmp[:6]))
        if case.outputs is not None:
            extra = sorted(p for p in new if p not in case.outputs)
            if extra:
                f.append("unexpected files: " + ", ".join(extra[:6]))
    if (not failed and res.rc == 0 and "--json" in case.argv and case.stdout is None
            and "--help" not in case.argv):
        try:
            v = strict_json(res.out.decode("utf-8"))
            if not isinstance(v, dict):
                f.append("--json printed a %s, not one object" % type(v).__name__)
        except (ValueError, UnicodeDecodeError) as e:
            f.append("--json output is not one JSON object: %s" % str(e)[:120])
    return f


def run_case(runner, case):
    d = tempfile.mkdtemp(dir=runner.scratch, prefix="c%05d-" % case.id)
    case.timeout = case.timeout or runner.timeout
    failures, res = [], None
    try:
        for name, data in case.inputs.items():
            p = os.path.join(d, name)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            if isinstance(data, tuple) and data[0] == "copy":
                shutil.copyfile(data[1], p)
            elif isinstance(data, tuple) and data[0] == "mkdir":
                os.makedirs(p, exist_ok=True)
            elif isinstance(data, tuple) and data[0] == "symlink":
                os.symlink(data[1], p)
            else:
                with open(p, "wb") as fo:
                    fo.write(data)
        if case.setup:
            failures += case.setup(runner, case, d) or []
        before = listing(d)
        if failures:
            pass
        elif case.run:
            res, extra = case.run(runner, case, d)
            failures += extra
        else:
            res = runner.exec(case.argv, d, case.timeout, stdout=case.stdout, prefix=case.prefix,
                              env=case.env)
        if res is not None:
            failures = judge(case, res, listing(d) - before) + failures
            if case.check:
                failures += case.check(runner, case, d, res) or []
    except Exception as e:  # a bug of the suite is a failure too, never a crash of it
        failures.append("suite error: %s: %s" % (type(e).__name__, e))
    finally:
        if not (runner.keep and failures):
            shutil.rmtree(d, ignore_errors=True)
    return case, res, failures


# ---- category 1: flags ---------------------------------------------------------

HUGE = "9" * 100000
SPECIALS = ["nan", "inf", "-inf", "1e308", "-1e308", "0", "-1", "4.9e-324", "", "1e", "0x10", HUGE]


def flag_re(flag):
    if flag in ("-", "--"):
        return "'%s'" % re.escape(flag)
    return r"(?<![\w-])%s(?![\w-])" % re.escape(flag)


def classify(value, dom, is_int=False):
    """'2' (must be refused), or '012' (in the domain: any clean outcome)."""
    if value == "0x10":
        return "012"
    if value in ("", "1e", HUGE) or value.lower() in ("nan", "inf", "-inf"):
        return "2"
    if is_int:
        if not re.fullmatch(r"-?\d+", value):
            return "2"
        return "012" if dom(int(value)) else "2"
    x = float(value)
    return "012" if dom(x) else "2"


POS = lambda x: x > 0  # noqa: E731
NONNEG = lambda x: x >= 0  # noqa: E731
UNIT = lambda x: 0 <= x <= 1  # noqa: E731
XI = lambda x: 0 <= x < 1  # noqa: E731
THETA = lambda x: 0.5 <= x <= 1  # noqa: E731

CASE_NUMS = [("--ap", POS), ("--Tp", POS), ("--T0", POS), ("--Pi2", POS), ("--gap", NONNEG),
             ("--Pi3", NONNEG), ("--eps", UNIT), ("--xi", XI), ("--dt", POS), ("--theta", THETA),
             ("--gamma", UNIT), ("--tend", POS), ("--kc", POS), ("--kc-abs", NONNEG),
             ("--rtol", POS), ("--atol", POS), ("--chain-ratio", POS), ("--scale", POS)]
CONTEXT = {"--chain-ratio": ["--chain", "3"], "--scale": ["--record", "r.AT2"],
           "--kc": ["--method", "penalty"], "--kc-abs": ["--method", "penalty"],
           "--rtol": ["--method", "penalty"], "--atol": ["--method", "penalty"]}
ENUMS = {"--pulse": ["sine", "cosine", "harmonic"], "--dir": ["normal", "reverse"],
         "--method": ["moreau", "event", "penalty"], "--contact": ["kelvin", "hertz"],
         "--stepper": ["rk8pd", "rkf45", "rk4imp", "msbdf"], "--kernel": ["auto", "general"],
         "--factor": ["auto", "scalar", "dense", "cholmod"],
         "--lcp-solver": ["auto", "lemke", "structured", "pgs"],
         "--units": ["g", "m/s2", "cm/s2"], "--record-format": ["auto", "at2", "v2", "text"]}
CASE_ENUMS = list(ENUMS)
COMMANDS = {
    # command: (base argv, own numeric flags [(flag, domain, is_int, context)], own enums,
    #           file flags, case numeric flags used)
    "simulate": ([], [("--every", lambda k: k >= 1, True, ["-o", "x.csv"])], {},
                 ["-o", "--plot", "--dump-lcp"], [f for f, _ in CASE_NUMS]),
    "compare": ([], [], {"--methods": ["moreau", "moreau,penalty"]}, [],
                [f for f, _ in CASE_NUMS]),
    "converge": (["--dt", "1e-2:1e-3:2"], [], {"--methods": ["moreau", "moreau,penalty"],
                                               "--error": ["hist", "umax"]},
                 ["-o", "--plot"], [f for f, _ in CASE_NUMS if f not in ("--dt", "--theta")]),
    "spectrum": (["--Pi2", "0.5:1:2"],
                 [("--dt-per-Tp", POS, False, []), ("--threads", lambda k: 1 <= k <= 4096, True, []),
                  ("--stop-after", lambda k: k >= 1, True, ["-o", "s.csv"])],
                 {}, ["-o", "--plot"],
                 ["--Tp", "--dt", "--theta", "--gamma", "--tend", "--kc", "--kc-abs", "--rtol",
                  "--atol", "--scale"]),
}
INPUTS_FLAGS = None  # filled in main: the files the flag cases use


def cases_flags(env):
    cases = []
    inputs = env["flag_inputs"]

    def add(cmd, argv, expect, regex=None, why=None, timeout=None, outputs=None):
        cases.append(Case("flags", [cmd] + argv, expect, regex, inputs=inputs, why=why,
                          timeout=timeout, outputs=outputs))

    doms = dict(CASE_NUMS)
    for cmd, (base, own, own_enums, file_flags, nums) in COMMANDS.items():
        # numeric flags: every special value
        for flag in nums:
            for v in SPECIALS:
                ctx = CONTEXT.get(flag, [])
                if cmd == "spectrum" and flag == "--scale":
                    ctx = ["--record", "r.AT2"]
                add(cmd, base + ctx + [flag, v], classify(v, doms[flag]), flag_re(flag), flag)
        for flag, dom, is_int, ctx in own:
            for v in SPECIALS:
                add(cmd, base + ctx + [flag, v], classify(v, dom, is_int), flag_re(flag), flag)
        if cmd in ("simulate", "compare", "converge"):
            for v in SPECIALS + ["1", "10000001"]:
                exp = "2" if v in ("0", "-1", "10000001") else classify(v, lambda k: 1 <= k <= 10 ** 7, True)
                add(cmd, base + ["--chain", v, "--tend", "0.5"] if v not in ("0x10",) else
                    base + ["--chain", v], exp, flag_re("--chain"), "--chain")
        # enumerations
        enums = dict((f, ENUMS[f]) for f in CASE_ENUMS)
        enums.update(own_enums)
        for flag, good in enums.items():
            if cmd == "spectrum" and flag in ("--pulse", "--dir"):
                bad = [",%s" % good[0], "%s," % good[0], "%s,,%s" % (good[0], good[1]),
                       "%s,bogus" % good[0], ",".join(good + good[:1] + good[:1]), "bogus", ""]
                add(cmd, base + [flag, "%s,%s" % (good[0], good[0])], "012", flag_re(flag), flag)
            else:
                bad = ["bogus", "", good[0].upper(), good[0] + " ", good[0][:-1] or "x",
                       good[0] + "x", "\x01", HUGE]
                if flag not in ("--methods",):
                    bad.append("%s,%s" % (good[0], good[-1]))
                else:
                    bad += ["moreau,", ",moreau", "moreau,bogus"]
            for v in bad:
                add(cmd, base + [flag, v], "2", flag_re(flag), flag)
            ctx = ["--record", "r.AT2"] if flag in ("--units", "--record-format") else []
            for v in good:
                if flag == "--method" and v == "penalty" and cmd == "converge":
                    continue
                add(cmd, base + ctx + [flag, v], "012", flag_re(flag), flag)
        # a flag without its value (last on the line)
        valued = [f for f, _ in CASE_NUMS] + list(enums) + [f for f, _, _, _ in own] + file_flags + \
            ["--record", "--scene", "--chain"] + (["--Pi2", "--Pi3", "--gap", "--eps", "--xi", "--ap",
                                                   "--ref", "--ref-contact"] if cmd == "spectrum" else [])
        for flag in dict.fromkeys(valued):
            if cmd == "spectrum" and flag == "--T0":
                continue
            add(cmd, base + [flag], "2", flag_re(flag), flag)
        # unknown flags and stray words
        for tok in ["--bogus", "--Pi22", "--ap=1", "-", "--", "-x", "---ap", "--AP", "stray",
                    "--" + "z" * 5000]:
            add(cmd, base + [tok], "2", flag_re(tok) if len(tok) < 100 else re.escape(tok[:40]),
                "the unknown flag %s" % short_arg(tok))
        # output names
        for flag in file_flags:
            for v, exp in [("x.txt", "2"), ("", "2"), ("x.jpg" if flag == "--plot" else "x.png", "2"),
                           ("x", "2"), (".h5" if flag != "--plot" else ".png", "012")]:
                if flag == "--dump-lcp" and v in ("x.png",):
                    v = "x.csv"
                add(cmd, base + [flag, v], exp, flag_re(flag) + "|" + re.escape(v or "''"), flag)
        add(cmd, base + ["--help"], "0")
        add(cmd, base + ["--help", "--ap", "nan"], "0")
    # spectrum's own forms
    for v in SPECIALS + ["nan:1:2", "0.5:inf:2", "0:1:2", "-1:1:2", "1:0.5:2", "0.5:0.5:2",
                         "0.5:1:0", "0.5:1:-1", "0.5:1:1.5", "0.5:1:1e9", "0.5:1:1000001",
                         "0.5:1:", "0.5::2", "::", ":1:2", "0.5:1:2:3", "0.5,1,2", "1e-300:1e300:2",
                         "4.9e-324:1:2", "0.5:1e308:3", "0x1p-1:1:2"]:
        ok = v in ("1e-300:1e300:2", "4.9e-324:1:2", "0.5:1e308:3", "0x1p-1:1:2")
        add("spectrum", ["--Pi2", v], "012" if ok else "2", flag_re("--Pi2"), "--Pi2")
    add("spectrum", ["--Pi2", "1:1:1"], "0")
    for v in SPECIALS:
        add("spectrum", ["--Pi2", "0.5:1:2", "--T0", v], "2", flag_re("--T0"), "--T0")
    for flag, dom in [("--ap", POS), ("--gap", NONNEG), ("--Pi3", NONNEG), ("--eps", UNIT), ("--xi", XI)]:
        for v in SPECIALS:
            add("spectrum", ["--Pi2", "0.5:1:2", flag, v], classify(v, dom), flag_re(flag), flag)
        for v in ["0.1,", ",0.1", "0.1,,0.2", "0.1,nan", "0.1,-1", "0.1;0.2", ",".join(["0.1"] * 200),
                  "0.1,0.2"]:
            exp = "012" if v == "0.1,0.2" else "2"
            add("spectrum", ["--Pi2", "0.5:1:2", flag, v], exp, flag_re(flag), flag)
    for v in SPECIALS:
        add("spectrum", ["--Pi2", "0.5:1:2", "--scene", "s.json", "--ref-contact", v],
            classify(v, lambda k: 0 <= k < 1, True), flag_re("--ref-contact"), "--ref-contact")
    add("spectrum", ["--Pi2", "0.5:1:2", "--scene", "s.json", "--ref", "nosuch"], "2",
        flag_re("--ref") + "|nosuch", "--ref")
    # converge's ranges and lists
    for v in SPECIALS + ["1e-2:1e-3:1", "1e-3:1e-2:2", "0:0:2", "nan:1e-3:2", "1e-2:1e-3:0",
                         "1e-2:1e-3:-1", "1e-2:4.9e-324:2", "1e308:1e-3:2", "1e-2:1e-3:1e9",
                         "1e-2:1e-3:1000000000", "1e-2::2", "1e-2:1e-3", "1e-2:1e-3:2:4"]:
        ok = v in ("1e-2:1e-3:1", "1e-2:4.9e-324:2", "1e308:1e-3:2", "1e-2:1e-3:1000000000")
        add("converge", ["--dt", v], "012" if ok else "2", flag_re("--dt"), "--dt")
    for v in SPECIALS + ["0.5,", ",0.5", "0.5,,1", "0.5,2", "0.5,1"]:
        exp = classify(v, THETA) if "," not in v else ("012" if v == "0.5,1" else "2")
        add("converge", ["--dt", "1e-2:1e-3:2", "--theta", v], exp, flag_re("--theta"), "--theta")
    for v in SPECIALS + ["1e2,", "1e2,,1e3", "1e2,-1"]:
        exp = classify(v, POS) if "," not in v else "2"
        add("converge", ["--dt", "1e-2:1e-3:2", "--methods", "moreau,penalty", "--kcs", v], exp,
            flag_re("--kcs"), "--kcs", timeout=None)
    # lcp and record
    for flag, dom, is_int in [("--tol", lambda x: 0 < x < 1e-3, False), ("--cover", POS, False),
                              ("--max-pivots", lambda k: k > 0, True),
                              ("--max-iterations", lambda k: k > 0, True)]:
        for v in SPECIALS:
            add("lcp", ["a.lcp", flag, v], classify(v, dom, is_int), flag_re(flag), flag)
    for v in ["1,1", "1,", ",1", "1,,1", "1,0", "1,-1", "1,nan", "1,1,1"]:
        add("lcp", ["a.lcp", "--cover", v], "012" if v == "1,1" else "2", flag_re("--cover"), "--cover")
    if env.get("dump"):
        for v in SPECIALS + ["1", "999999"]:
            add("lcp", ["d.h5", "--index", v], classify(v, lambda k: 0 <= k < env["dump_count"], True),
                flag_re("--index"), "--index")
        add("lcp", ["d.h5", "--all", "--json"], "01")
        add("lcp", ["d.h5"], "2", r"--all|--index", "--all or --index")
        add("lcp", ["d.h5", "--all", "--index", "0"], "2", r"--all|--index", "--all or --index")
    for flag in ("--solver", "--format"):
        for v in ["bogus", "", "LEMKE", "lemke,pgs", HUGE]:
            add("lcp", ["a.lcp", flag, v], "2", flag_re(flag), flag)
        add("lcp", ["a.lcp", flag], "2", flag_re(flag), flag)
    for flag in ("--max-pivots", "--max-iterations", "--tol", "--cover", "--index"):
        add("lcp", ["a.lcp", flag], "2", flag_re(flag), flag)
    for tok in ["--bogus", "-", "--", "b.lcp"]:
        add("lcp", ["a.lcp", tok], "2", flag_re(tok) if tok != "b.lcp" else "b\\.lcp", tok)
    add("lcp", [], "2")
    add("lcp", ["a.lcp", "--all"], "2", flag_re("--all"), "--all")
    add("lcp", ["a.lcp", "--index", "0"], "2", flag_re("--index"), "--index")
    add("lcp", ["--help"], "0")
    for flag in ("--units", "--record-format"):
        for v in ["bogus", "", "G", "m/s", HUGE]:
            add("record", ["r.AT2", flag, v], "2", flag_re(flag), flag)
        add("record", ["r.AT2", flag], "2", flag_re(flag), flag)
    for tok in ["--bogus", "-", "--"]:
        add("record", ["r.AT2", tok], "2", flag_re(tok), tok)
    add("record", [], "2")
    add("record", ["r.AT2", "--plot"], "2", flag_re("--plot"), "--plot")
    add("record", ["r.AT2", "--plot", "x.jpg"], "2", flag_re("--plot") + "|x\\.jpg", "--plot")
    add("record", ["--help"], "0")
    add("bench", ["--help"], "0")
    add("bench", ["--bogus"], "2", flag_re("--bogus"), "--bogus")
    cases.append(Case("flags", [], "2", None, display="pound"))
    cases.append(Case("flags", ["bogus-command"], "2", "bogus-command", why="the command"))
    cases.append(Case("flags", ["--help"], "0"))
    # conflicting flags
    conflicts = [
        (["--gap", "0.1", "--Pi3", "0.1"], r"--gap|--Pi3"),
        (["--T0", "1", "--Pi2", "1"], r"--T0|--Pi2"),
        (["--record", "r.AT2", "--pulse", "sine"], r"--record|--pulse"),
        (["--record", "r.AT2", "--ap", "1"], r"--record|--ap"),
        (["--record", "r.AT2", "--Tp", "1"], r"--record|--Tp"),
        (["--scene", "s.json", "--chain", "3"], r"--scene|--chain"),
        (["--scene", "s.json", "--ap", "1"], r"--scene|--ap"),
        (["--scene", "s.json", "--record", "r.AT2"], r"--scene|--record"),
        (["--chain", "3", "--record", "r.AT2"], r"--chain|--record"),
        (["--scale", "2"], r"--scale"),
    ]
    for cmd in ("simulate", "compare", "converge"):
        base = COMMANDS[cmd][0]
        for argv, rx in conflicts:
            add(cmd, base + argv, "2", rx, "one of " + rx.replace("|", ", "))
    # (spectrum --record --ap is no conflict: --ap lists the pulse amplitudes the
    # record is scaled to, docs/records.md)
    for argv, rx in conflicts[:3] + conflicts[4:5] + [
            (["--dt", "0.001", "--dt-per-Tp", "100"], r"--dt"),
            (["--resume"], r"--resume"), (["--stop-after", "1"], r"--stop-after"),
            (["--ref", "A"], r"--ref"), (["--ref-contact", "0"], r"--ref-contact"),
            (["--scene", "s.json", "--chain", "3"], r"--scene|--chain"),
            (["--scene", "s.json", "--pulse", "sine"], r"--scene|--pulse"),
            (["--scene", "s.json", "--resume", "-o", "x.h5"], r"--resume"),
            (["--scene", "s.json", "--record", "r.AT2"], r"--scene|--record"),
            (["--chain", "3"], r"--chain"), (["--no-wall"], r"--no-wall")]:
        add("spectrum", ["--Pi2", "0.5:1:2"] + argv, "2", rx, "one of " + rx.replace("|", ", "))
    add("simulate", ["--dump-lcp", "d2.h5", "--method", "event"], "2", r"--dump-lcp|--method",
        "--dump-lcp or --method")
    add("simulate", ["--dump-lcp", "d2.h5", "-o", "d2.h5"], "2", r"--dump-lcp|-o|d2\.h5",
        "--dump-lcp or -o")
    add("simulate", ["-o", "x.h5", "-o", "x.csv"], "012", r"-o", "-o", outputs={"x.h5", "x.csv"})
    add("simulate", ["--ap", "1", "--ap", "2"], "012", r"--ap", "--ap")
    add("converge", [], "2", flag_re("--dt"), "--dt")
    add("spectrum", [], "2", flag_re("--Pi2"), "--Pi2")
    return cases


# ---- category 2: LCP files ------------------------------------------------------


def parse_lcp(data, fmt):
    """(M rows, q) as Fractions of the doubles pound reads, or None."""
    text = data.decode("latin-1")
    toks = []
    for line in text.replace("\r", "\n").split("\n"):
        line = line.split("#", 1)[0]  # both readers take '#' comments
        toks += line.split()

    def num(t):
        try:
            x = float(t)
        except ValueError:
            x = float.fromhex(t)
        if x != x or x in (float("inf"), float("-inf")):
            raise ValueError(t)
        return Fraction(x)
    try:
        n = int(toks[0])
        if fmt == "plain":
            vals = [num(t) for t in toks[1:1 + n * n + n]]
            if len(vals) != n * n + n:
                return None
            M = [vals[i * n:(i + 1) * n] for i in range(n)]
        else:
            vals = [num(t) for t in toks[6:6 + n * n + n]]
            if len(vals) != n * n + n:
                return None
            M = [[vals[j * n + i] for j in range(n)] for i in range(n)]
        return M, vals[n * n:]
    except (ValueError, IndexError, OverflowError):
        return None


def lcp_format(case, path):
    if "--format" in case.argv:
        f = case.argv[case.argv.index("--format") + 1]
        if f in ("plain", "siconos"):
            return f
    with open(path, "rb") as fo:
        head = fo.read(64 << 20).decode("latin-1")  # long comments push the header far
    t = " ".join(ln.split("#", 1)[0] for ln in head.replace("\r", "\n").split("\n")).split(None, 6)
    # Siconos: n, 0, rows, cols, rows cols: six integers (docs/lcp.md §8); "-0" is 0
    if len(t) >= 6 and all(re.fullmatch(r"-?\d+", x) for x in t[:6]) and int(t[1]) == 0:
        return "siconos"
    return "plain"


def check_lcp(runner, case, d, res, tol=Fraction(1, 10 ** 8)):
    """A "solved" answer is recomputed exactly: z >= 0, w = M z + q >= -tol r,
    min(|w_i| / r_i, z_i / max z) <= tol; the exit status follows the status."""
    if res is None or res.timed_out or res.rc not in (0, 1) or "--json" not in case.argv:
        return []
    path = os.path.join(d, case.argv[1])
    try:
        out = strict_json(res.out.decode("utf-8"))
    except (ValueError, UnicodeDecodeError) as e:
        return ["lcp --json output is not JSON: %s" % str(e)[:100]]
    status = out.get("status") if isinstance(out, dict) else None
    if res.rc == 0 and status != "solved":
        return ["exit 0 with status %r" % status]
    if res.rc == 1:
        return [] if status not in (None, "solved") else ["exit 1 with status %r" % status]
    with open(path, "rb") as fo:
        prob = parse_lcp(fo.read(), lcp_format(case, path))
    if prob is None:
        return []  # a form the reader accepts and this parser does not: not judged
    M, q = prob
    n = len(q)
    z = out.get("z")
    if not isinstance(z, list) or len(z) != n or not all(isinstance(x, (int, float)) for x in z):
        return ["solved, but z is not %d numbers: %s" % (n, str(z)[:80])]
    z = [Fraction(x) for x in z]
    if any(x < 0 for x in z):
        return ["wrong answer: solved with a negative z_i = %g" % float(min(z))]
    zs = max(z) if z else Fraction(0)
    worst, where = Fraction(0), None
    for i in range(n):
        w = q[i] + sum(M[i][j] * z[j] for j in range(n) if z[j])
        r = abs(q[i]) + sum(abs(M[i][j] * z[j]) for j in range(n) if z[j])
        if r == 0:
            continue
        neg = -w / r if w < 0 else Fraction(0)
        comp = min(abs(w) / r, z[i] / zs if zs else Fraction(0))
        bad = max(neg, comp)
        if bad > worst:
            worst, where = bad, i
    if worst > tol:
        return ["wrong answer: status solved but the exact relative residual is %.3g at row %d "
                "(w = Mz + q recomputed in rationals)" % (float(worst), where)]
    return []


def table_rows(kind):
    rows = []
    with open(os.path.join(HERE, "cases", kind + ".tsv")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            parts = line.rstrip("\n").split("\t")
            parts += [""] * (5 - len(parts))
            rows.append(parts[:5])
    return rows


def gen_input(spec):
    """gen:FAMILY:BASE:MUTANT -> (file name, bytes)."""
    _, fam, base, name = spec.split(":", 3)
    if fam == "lcp":
        with open(os.path.join(HERE, "corpus", "lcp", base)) as f:
            muts = mutate.lcp_mutants(f.read(), siconos=base.endswith(".dat"))
        stem, ext = os.path.splitext(base)
    elif fam == "scene":
        with open(os.path.join(ROOT, "examples", "scenes", base)) as f:
            muts = mutate.scene_mutants(f.read())
        stem, ext = base[:-5], ".json"
    else:
        with open(os.path.join(HERE, "corpus", "record", base)) as f:
            text = f.read()
        muts = mutate.record_mutants(text, "text" if base.endswith(".txt") else "at2")
        stem, ext = os.path.splitext(base)
    m = next(m for m in muts if m.name == name)
    return "%s--%s%s" % (stem, re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_")[:80], ext), m.data


def cases_table(kind):
    cases = []
    corpus = os.path.join(HERE, "corpus", kind)
    for inp, cmd, expect, regex, check in table_rows(kind):
        if inp.startswith("gen:"):
            fname, data = gen_input(inp)
            inputs = {fname: data}
        else:
            src = os.path.normpath(os.path.join(corpus, inp))
            fname = os.path.basename(src)
            inputs = {fname: ("copy", src)}
        argv = [a.replace("{F}", fname) for a in shlex.split(cmd)]
        cases.append(Case(kind, argv, expect, regex or None, inputs=inputs,
                          why="the file and line (%s)" % fname,
                          check=check_lcp if check == "verify-lcp" else None,
                          rc1_reason=argv[0] != "lcp"))
    return cases


def cases_lcp(env):
    cases = cases_table("lcp")
    sic = os.path.join(SHARED, "data", "lcp", "siconos")
    if not os.path.isdir(sic):
        env["skips"].append("lcp: ../shared/data/lcp/siconos absent: its mutants skipped")
        return cases
    for name in sorted(os.listdir(sic)):
        if not name.endswith(".dat"):
            continue
        src = os.path.join(sic, name)
        for solver in ("auto", "lemke", "structured", "pgs"):
            cases.append(Case("lcp", ["lcp", name, "--json", "--solver", solver], "01",
                              inputs={name: ("copy", src)}, check=check_lcp, rc1_reason=False))
        if name in ("lcp_CPS_1.dat", "lcp_mmc.dat", "lcp_trivial.dat"):
            with open(src, "rb") as f:
                text = f.read().decode("latin-1")
            for m in mutate.lcp_mutants(text, siconos=True):
                fname = "%s--%s.dat" % (name[:-4], re.sub(r"[^\w.-]+", "_", m.name))
                rx = re.escape(fname) + (r": line \d+" if m.where == "line" else "")
                cases.append(Case("lcp", ["lcp", fname, "--json"], m.expect, rx,
                                  inputs={fname: m.data}, why="the file and line (%s)" % fname,
                                  check=check_lcp, rc1_reason=False))
    return cases


def cases_scene(env):
    cases = cases_table("scene")
    for name in sorted(os.listdir(os.path.join(ROOT, "examples", "scenes"))):
        if name.endswith(".json"):
            path = os.path.join(ROOT, "examples", "scenes", name)
            if "rinaldi" in name and not os.path.isdir(os.path.join(SHARED, "data", "records")):
                continue
            for cmd in (["simulate", "--scene", path, "--json"],
                        ["simulate", "--scene", path, "--method", "event", "--json"],
                        ["compare", "--scene", path, "--dt", "1e-3", "--json"]):
                cases.append(Case("scene", cmd, "0", display="pound " + " ".join(
                    os.path.relpath(a, ROOT) if a.startswith("/") else a for a in cmd)))
    return cases


def cases_record(env):
    cases = cases_table("record")
    rdir = os.path.join(SHARED, "data", "records")
    if not os.path.isdir(rdir):
        env["skips"].append("record: ../shared/data/records absent: its mutants skipped")
        return cases
    for name in sorted(os.listdir(rdir)):
        if name.lower().endswith((".at2", ".v2")):
            cases.append(Case("record", ["record", name, "--json"], "0",
                              inputs={name: ("copy", os.path.join(rdir, name))}))
    for name, kind in (("NGA_no_1063_RRS228.AT2", "at2"), ("RSN1044_NORTHR_NWH360.AT2", "at2"),
                       ("ce36456p_CE36456.V2", "v2")):
        src = os.path.join(rdir, name)
        if not os.path.exists(src):
            continue
        with open(src, "rb") as f:
            text = f.read().decode("latin-1")
        for m in mutate.record_mutants(text, kind):
            stem, ext = os.path.splitext(name)
            fname = "%s--%s%s" % (stem, re.sub(r"[^\w.-]+", "_", m.name), ext)
            rx = re.escape(fname) + (r":\d+: " if m.where == "line" else r"(:\d+)?: ")
            cases.append(Case("record", ["record", fname, "--json"], m.expect, rx,
                              inputs={fname: m.data}, why="the file and line (%s)" % fname))
    return cases


# ---- category 5: spectrum journals ------------------------------------------------

SWEEP = ["spectrum", "--Pi2", "0.5:2:12", "--Pi3", "0.05,0.1", "--eps", "0.5"]


def prep_journal(runner, env):
    """A real interrupted sweep's journal, the key of another sweep, and the
    uninterrupted output to compare resumed ones with."""
    d = tempfile.mkdtemp(dir=runner.scratch, prefix="journal-prep-")
    r = runner.exec(SWEEP + ["-o", "out.h5", "--stop-after", "7"], d, 60)
    jp = os.path.join(d, "out.h5.partial")
    if r.rc != 130 or not os.path.exists(jp):
        return "spectrum --stop-after 7 gave exit %s and %s journal (stderr: %s)" % (
            r.rc, "a" if os.path.exists(jp) else "no", r.err.decode(errors="replace").strip()[:200])
    with open(jp, "rb") as f:
        env["journal"] = f.read()
    o = tempfile.mkdtemp(dir=runner.scratch, prefix="journal-other-")
    runner.exec(SWEEP[:-1] + ["0.6", "-o", "out.h5", "--stop-after", "1"], o, 60)
    with open(os.path.join(o, "out.h5.partial"), "rb") as f:
        env["other_key"] = f.read().split(b"\n")[1] + b"\n"
    r = runner.exec(SWEEP + ["-o", "ref.h5"], d, 60)
    if r.rc != 0:
        return "the uninterrupted sweep failed: exit %s" % r.rc
    env["journal_ref"] = os.path.join(d, "ref.h5")
    return None


def journal_check(equal):
    def check(runner, case, d, res):
        f = []
        jp, out = os.path.join(d, "out.h5.partial"), os.path.join(d, "out.h5")
        if res.timed_out or res.rc is None:
            return f
        if res.rc == 0:
            if os.path.lexists(jp):
                f.append("the journal is still there after a successful resume")
            if not os.path.exists(out):
                f.append("exit 0 but no out.h5")
            elif equal:
                with open(out, "rb") as a, open(case.ref, "rb") as b:
                    if a.read() != b.read():
                        f.append("the resumed out.h5 differs from the uninterrupted sweep's")
        else:
            data = case.inputs.get("out.h5.partial")
            if isinstance(data, bytes):
                if not os.path.exists(jp):
                    f.append("the journal was removed by a refused resume")
                else:
                    with open(jp, "rb") as fo:
                        if fo.read() != data:
                            f.append("a refused resume changed the journal")
        return f
    return check


def cases_journal(env):
    if "journal" not in env:
        return []
    cases = []
    argv = SWEEP + ["-o", "out.h5", "--resume", "--json"]
    rx = r"--resume|-o|out\.h5\.partial"
    for m in mutate.journal_mutants(env["journal"], env["other_key"]):
        c = Case("journal", argv, m.expect.replace("=", ""), rx, inputs={"out.h5.partial": m.data},
                 partial_ok=True, why="--resume or the journal", check=journal_check("=" in m.expect))
        c.ref = env["journal_ref"]
        c.display = "%s   (out.h5.partial: %s)" % (c.command(), m.name)
        cases.append(c)
    for label, inp, expect in [("a directory", ("mkdir",), "12"),
                               ("a symlink to /dev/null", ("symlink", "/dev/null"), "02"),
                               ("a dangling symlink", ("symlink", "nowhere/x.partial"), "012")]:
        c = Case("journal", argv, expect, rx, inputs={"out.h5.partial": inp}, partial_ok=True,
                 why="--resume or the journal", check=journal_check(True))
        c.ref = env["journal_ref"]
        c.display = "%s   (out.h5.partial: %s)" % (c.command(), label)
        cases.append(c)
    c = Case("journal", SWEEP + ["-o", "out.h5"], "2", r"-o.*exists|exists.*--resume",
             inputs={"out.h5.partial": env["journal"]}, partial_ok=True,
             why="that the journal exists", check=journal_check(False))
    c.display = "%s   (a journal exists, no --resume)" % c.command()
    cases.append(c)
    c = Case("journal", argv, "0", None, check=journal_check(True))
    c.ref = env["journal_ref"]
    c.display = "%s   (no journal yet)" % c.command()
    cases.append(c)
    c = Case("journal", argv, "0", None, inputs={"out.h5.partial": env["journal"], "out.h5": b"old"},
             check=journal_check(True))
    c.ref = env["journal_ref"]
    c.display = "%s   (an old out.h5 is replaced)" % c.command()
    cases.append(c)
    c = Case("journal", argv, "2", r"in use|--resume", run=run_locked, partial_ok=True,
             why="that the journal is in use")
    c.display = "%s   (while another sweep holds the journal)" % c.command()
    cases.append(c)
    return cases


def run_locked(runner, case, d):
    """A second sweep on a journal that a running sweep holds."""
    long_sweep = ["spectrum", "--Pi2", "0.05:5:4000", "--Pi3", "0.05,0.1", "--eps", "0.5"]
    p = subprocess.Popen([runner.pound] + long_sweep + ["-o", "out.h5"], cwd=d,
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        t0 = time.monotonic()
        while not os.path.exists(os.path.join(d, "out.h5.partial")) and time.monotonic() - t0 < 5:
            time.sleep(0.01)
        time.sleep(0.2)
        if p.poll() is not None:
            return None, ["the long sweep ended before the test (exit %s)" % p.returncode]
        case.argv = long_sweep + ["-o", "out.h5", "--resume"]
        res = runner.exec(case.argv, d, case.timeout)
        return res, []
    finally:
        kill_group(p.pid)
        p.wait()
        for name in os.listdir(d):  # what the killed holder leaves is not this case's
            if name.startswith("out.h5"):
                os.unlink(os.path.join(d, name))


# ---- category 6: faults -----------------------------------------------------------


def fsize_prefix(nbytes):
    # RLIMIT_FSIZE as a full disk: SIGXFSZ ignored (inherited through exec), so
    # that write(2) fails with EFBIG as it would with ENOSPC
    return ["prlimit", "--fsize=%d" % nbytes, "--", "sh", "-c", 'trap "" XFSZ; exec "$0" "$@"']


def signal_run(sig, after, resume_argv=None):
    def run(runner, case, d):
        p = subprocess.Popen([runner.pound] + case.argv, cwd=d, stdin=subprocess.DEVNULL,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             start_new_session=True)
        t0 = time.monotonic()
        time.sleep(after)
        f = []
        if p.poll() is not None:
            err = p.stderr.read()
            return Result(rc=p.returncode, err=err), \
                ["finished (exit %d) before the signal: make the run longer" % p.returncode]
        os.kill(p.pid, sig)
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            kill_group(p.pid)
            p.wait()
            f.append("hang: still running 10 s after %s" % signame(sig))
        err = p.stderr.read()
        kill_group(p.pid)
        res = Result(rc=p.returncode, err=err, secs=time.monotonic() - t0)
        files = sorted(listing(d))
        out = case.target
        left = [x for x in files if x == out or x.startswith(out + ".tmp") or
                (x == out + ".partial" and not resume_argv)]
        if left:
            f.append("left behind after %s: %s" % (signame(sig), ", ".join(left)))
        if resume_argv:
            if out + ".partial" not in files:
                f.append("no journal %s.partial after %s: the sweep cannot resume" % (out, signame(sig)))
            r2 = runner.exec(resume_argv, d, 60)
            if r2.rc != 0:
                f.append("--resume after %s: exit %s: %s" % (signame(sig), r2.rc,
                                                            r2.err.decode(errors="replace").strip()[:200]))
            else:
                r3 = runner.exec([a if a != out else "ref-" + out for a in case.argv], d, 60)
                if r3.rc == 0:
                    with open(os.path.join(d, out), "rb") as a, open(os.path.join(d, "ref-" + out), "rb") as b:
                        if a.read() != b.read():
                            f.append("the resumed %s differs from an uninterrupted run's" % out)
                left = [x for x in listing(d) if ".tmp" in x or x.endswith(".partial")]
                if left:
                    f.append("left after the resume: " + ", ".join(sorted(left)))
        # the signal itself is expected here: judge only what it leaves
        res.rc = 0 if not f else None
        return None, f
    return run


def cases_faults(env):
    cases = []
    inputs = env["flag_inputs"]
    full_disk = [
        (["simulate", "-o", "x.h5"], "x.h5"), (["simulate", "-o", "x.csv"], "x.csv"),
        (["simulate", "--chain", "20", "--tend", "2", "-o", "x.h5"], "x.h5"),
        (["simulate", "--chain", "20", "--tend", "2", "-o", "x.csv"], "x.csv"),
        (["simulate", "--chain", "5", "--tend", "1", "--dump-lcp", "dump.h5"], "dump.h5"),
        (["converge", "--dt", "1e-2:1e-3:3", "-o", "c.csv"], "c.csv"),
        (["converge", "--dt", "1e-2:1e-3:3", "-o", "c.h5"], "c.h5"),
        (["spectrum", "--Pi2", "0.5:2:40", "-o", "s.h5"], "s.h5"),
        (["spectrum", "--Pi2", "0.5:2:40", "-o", "s.csv"], "s.csv"),
        (["spectrum", "--scene", "s.json", "--Pi2", "0.5:2:6", "-o", "s.h5"], "s.h5"),
    ]
    for argv, out in full_disk:
        for n in (0, 700, 8192, 65536):
            c = Case("faults", argv, "01" if n else "1", None, inputs=inputs, prefix=fsize_prefix(n),
                     partial_ok=argv[0] == "spectrum", stderr_lost=n == 0,
                     display="prlimit --fsize=%d (full disk) pound %s" % (n, " ".join(argv)))
            c.check = no_output_check(out, n)
            cases.append(c)
    for argv in (["lcp", "a.lcp", "--json"], ["lcp", "a.lcp"], ["record", "r.AT2", "--json"],
                 ["record", "r.AT2"], ["simulate", "--json"], ["simulate"],
                 ["spectrum", "--Pi2", "0.5:1:4", "--json"], ["compare", "--json"],
                 ["converge", "--dt", "1e-2:1e-3:2", "--json"], ["simulate", "--scene", "s.json"],
                 ["simulate", "--help"], ["lcp", "--help"]):
        cases.append(Case("faults", argv, "1", None, inputs=inputs, stdout="/dev/full",
                          display="pound %s > /dev/full" % " ".join(argv)))
        cases.append(Case("faults", argv, "1", None, inputs=inputs,
                          prefix=["sh", "-c", 'exec "$0" "$@" >&-'],
                          display="pound %s >&- (stdout closed)" % " ".join(argv)))
    cases.append(Case("faults", ["simulate", "--ap", "nan"], "2", None,
                      prefix=["sh", "-c", 'exec "$0" "$@" 2>/dev/full'], stderr_lost=True,
                      display="pound simulate --ap nan 2>/dev/full"))
    for argv, flag in [(["simulate", "-o", "nodir/x.h5"], "-o"), (["simulate", "-o", "nodir/x.csv"], "-o"),
                       (["simulate", "--chain", "3", "-o", "nodir/x.h5"], "-o"),
                       (["simulate", "--plot", "nodir/p.png"], "--plot"),
                       (["simulate", "--chain", "3", "--dump-lcp", "nodir/d.h5"], "--dump-lcp"),
                       (["spectrum", "--Pi2", "0.5:1:4", "-o", "nodir/s.h5"], "-o"),
                       (["spectrum", "--Pi2", "0.5:1:4", "-o", "nodir/s.h5", "--resume"], "-o"),
                       (["converge", "--dt", "1e-2:1e-3:2", "-o", "nodir/c.csv"], "-o"),
                       (["record", "r.AT2", "--plot", "nodir/p.png"], "--plot"),
                       (["simulate", "-o", "adir.h5"], "-o"), (["simulate", "-o", "adir.csv"], "-o"),
                       (["spectrum", "--Pi2", "0.5:1:4", "-o", "adir.h5"], "-o")]:
        ins = dict(inputs)
        ins["adir.h5/keep"] = b"a folder with a file"
        ins["adir.csv/keep"] = b"a folder with a file"
        cases.append(Case("faults", argv, "12", flag_re(flag) + "|nodir|adir", inputs=ins,
                          why=flag + " or the path", partial_ok=False))
    if os.geteuid() == 0:
        env["skips"].append("faults: read-only target folder: skip (root ignores modes)")
    else:
        for argv in (["simulate", "-o", "ro/x.h5"], ["spectrum", "--Pi2", "0.5:1:4", "-o", "ro/s.h5"]):
            c = Case("faults", argv, "12", r"-o|ro/", inputs=inputs, why="-o or the path",
                     setup=lambda r, c, d: (os.makedirs(os.path.join(d, "ro")),
                                            os.chmod(os.path.join(d, "ro"), 0o555), [])[2])
            cases.append(c)
    long_runs = [
        (["simulate", "--dt", "1e-7", "--tend", "40", "--every", "100000", "-o", "x.h5"], "x.h5", False),
        (["simulate", "--chain", "200", "--tend", "1000", "--every", "1000", "-o", "x.h5"], "x.h5", False),
        (["simulate", "--chain", "200", "--tend", "1000", "--every", "1000", "-o", "x.csv"], "x.csv", False),
        (["simulate", "--chain", "100", "--tend", "2000", "--dump-lcp", "d.h5"], "d.h5", False),
        (["spectrum", "--Pi2", "0.05:5:5000", "--Pi3", "0.01,0.1", "--dt-per-Tp", "20000", "-o",
          "s.h5"], "s.h5", True),
    ]
    for sig in (signal.SIGTERM, signal.SIGINT):
        for argv, out, resumable in long_runs:
            c = Case("faults", argv, "0", None, partial_ok=resumable, timeout=90,
                     run=signal_run(sig, 1.0, argv + ["--resume"] if resumable else None),
                     display="pound %s   (%s after 1 s%s)" % (" ".join(argv), signame(sig),
                                                             ", then --resume" if resumable else ""))
            c.target = out
            cases.append(c)
    return cases


def no_output_check(out, limit=None):
    """Nothing of out after a failure; after a success under a file-size
    limit, an output that really fits it (then exit 0 is right)."""
    def check(runner, case, d, res):
        names = listing(d)
        left = [x for x in names if x == out or x.startswith(out + ".tmp")]
        if left and res.rc != 0:
            return ["left behind: " + ", ".join(sorted(left))]
        p = os.path.join(d, out)
        if res.rc == 0 and limit is not None:
            if not os.path.exists(p):
                return ["exit 0 but no %s" % out]
            if os.path.getsize(p) >= limit:  # a cut file stops exactly there
                return ["exit 0 with %s of %d bytes at the %d-byte limit"
                        % (out, os.path.getsize(p), limit)]
        return []
    return check


# ---- category 7: hangs --------------------------------------------------------------


def cases_hangs(env):
    inputs = env["flag_inputs"]
    runs = [
        "simulate --Pi2 1e308 --dt 0.01 --method event",
        "converge --dt 1e-2:1e-3:2 --Pi2 1e308",
        "simulate --Pi2 1e6 --method event",
        "simulate --Pi2 1e6 --method event --dt 0.01",
        "simulate --Pi2 1e6 --method penalty",
        "simulate --Pi2 1e-6 --method event",
        "simulate --Pi2 1e-6",
        "simulate --T0 1e-9",
        "simulate --T0 1e9 --method event",
        "simulate --Pi2 1e4 --method event --tend 1",
        "simulate --method event --pulse harmonic --xi 0 --eps 1",
        "simulate --method event --pulse harmonic --xi 1e-300",
        "simulate --pulse harmonic --xi 1e-300",
        "simulate --method event --Pi3 0 --eps 0.999999",
        "simulate --method event --Pi3 0 --eps 0.5 --no-accumulation",
        "simulate --method event --Pi3 1e-300 --eps 0.9",
        "simulate --method event --ap 1e300",
        "simulate --method event --ap 1e-300",
        "simulate --ap 1e308 --method event",
        "simulate --method penalty --kc 1e308",
        "simulate --method penalty --kc 1e12",
        "simulate --method penalty --kc-abs 1e300",
        "simulate --method penalty --contact hertz --kc 1e15",
        "simulate --method penalty --rtol 1e-300 --atol 1e-300",
        "simulate --method penalty --stepper rk4imp --kc 1e10",
        "simulate --method penalty --stepper msbdf --kc 1e10",
        "simulate --method penalty --stepper rkf45 --rtol 1e308",
        "simulate --theta 0 --allow-unstable --dt 0.1",
        "simulate --theta 2 --allow-unstable --dt 0.1",
        "simulate --dt 0.5 --Pi2 100",
        "simulate --gamma 0 --Pi3 0 --eps 1",
        "simulate --chain 50 --method event",
        "simulate --chain 50 --method event --Pi3 0 --eps 0.9",
        "simulate --chain 20 --method penalty --kc 1e8",
        "simulate --chain 300 --lcp-solver pgs --Pi3 0",
        "simulate --chain 3000 --lcp-solver lemke --Pi3 0 --tend 0.2",
        "simulate --chain 200 --factor dense --tend 0.5",
        "simulate --chain 3 --factor scalar",
        "compare --Pi2 1e6",
        "compare --Pi2 1e-6",
        "compare --Pi3 0 --eps 0.999",
        "converge --dt 1:1e-9:3",
        "converge --dt 1e-2:1e-3:2 --methods moreau,penalty --kcs 1e300",
        "spectrum --Pi2 1e-6:1e6:3",
        "spectrum --Pi2 0.5:1:2 --method penalty --kc 1e308",
        "spectrum --Pi2 0.5:1:2 --Pi3 0 --eps 0.999999 --method event",
        "spectrum --Pi2 0.05:5:4 --pulse harmonic --xi 0",
        "simulate --scene s.json --method penalty --kc 1e300",
        "simulate --scene s.json --tend 1e6",
        "compare --scene s.json --dt 1e-9",
        "lcp murty20.lcp --max-pivots 2147483647",
        "lcp murty20.lcp --solver pgs --max-iterations 2147483647",
        "lcp murty20.lcp --solver structured --max-iterations 2147483647",
        "record /dev/zero",
        "record /dev/zero --record-format text",
        "lcp /dev/zero",
        "simulate --record /dev/zero",
        "simulate --scene /dev/zero",
        "simulate --scene dev-zero-record.json",
        "record /dev/urandom",
    ]
    cases = []
    for r in runs:
        argv = shlex.split(r)
        is_dev = "/dev/" in r or "dev-zero" in r
        # 60 s: a runaway never ends, while legitimate heavy cases take up
        # to about 10 s alone and twice that on a loaded 2-core machine
        cases.append(Case("hangs", argv, "2" if is_dev else "012",
                          r"/dev/(zero|urandom)|dev-zero" if is_dev else None, inputs=inputs,
                          why="the file" if is_dev else None, timeout=60,
                          rc1_reason=argv[0] != "lcp"))  # lcp: its status is on stdout
    return cases


# ---- category 8: libFuzzer ------------------------------------------------------------


def run_fuzz(runner, env, fuzz_time):
    fdir = os.path.join(env["stress"], "fuzz")
    skip = os.path.join(env["stress"], "fuzz.skip")
    targets = ["fuzz_lcp", "fuzz_scene", "fuzz_record", "fuzz_journal"]
    if os.path.exists(skip) or not all(os.path.exists(os.path.join(fdir, t)) for t in targets):
        msg = open(skip).read().strip() if os.path.exists(skip) else "fuzz: skip (harnesses not built)"
        return None, msg
    seeds = {
        "fuzz_lcp": [os.path.join(HERE, "corpus", "lcp")] + [os.path.join(SHARED, "data", "lcp", "siconos")],
        "fuzz_scene": [os.path.join(ROOT, "examples", "scenes"), os.path.join(HERE, "corpus", "scene")],
        "fuzz_record": [os.path.join(HERE, "corpus", "record"), os.path.join(SHARED, "data", "records")],
        "fuzz_journal": [],
    }

    def one(t):
        work = os.path.join(fdir, t + ".work")
        art = os.path.join(fdir, t + ".crashes")
        seed_dir = tempfile.mkdtemp(dir=runner.scratch, prefix=t + "-seeds-")
        os.makedirs(work, exist_ok=True)
        os.makedirs(art, exist_ok=True)
        k = 0
        for src in seeds[t]:
            for root, _, files in os.walk(src) if os.path.isdir(src) else []:
                for name in sorted(files):
                    p = os.path.join(root, name)
                    if os.path.getsize(p) <= 16384 and not name.startswith(("COPYING", "README")):
                        shutil.copyfile(p, os.path.join(seed_dir, "s%04d" % k))
                        k += 1
        if t == "fuzz_journal" and "journal" in env:
            for m in mutate.journal_mutants(env["journal"], env["other_key"]):
                if len(m.data) <= 16384:
                    with open(os.path.join(seed_dir, "s%04d" % k), "wb") as f:
                        f.write(m.data)
                    k += 1
        # a fixed seed: a CI run repeats the local one as far as time allows
        cmd = [os.path.join(fdir, t), "-seed=1", "-max_total_time=%d" % fuzz_time, "-timeout=10",
               "-rss_limit_mb=2048", "-max_len=16384", "-print_final_stats=1",
               "-artifact_prefix=" + art + "/", work, seed_dir]
        envv = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0",
                    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1", TMPDIR=runner.scratch)
        t0 = time.monotonic()
        p = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, env=envv, timeout=fuzz_time + 120)
        log = p.stdout.decode("utf-8", "replace")
        with open(os.path.join(fdir, t + ".log"), "w") as f:
            f.write(log)
        m = re.search(r"stat::number_of_executed_units:\s*(\d+)", log)
        execs = int(m.group(1)) if m else 0
        fails = []
        if p.returncode != 0:
            summary = [ln for ln in log.splitlines()
                       if re.search(r"SUMMARY:|ERROR: libFuzzer|==ERROR|runtime error:|deadly signal|"
                                    r"out-of-memory|Test unit written", ln)]
            fails.append("%s: exit %d after %.0f s: %s (log: %s)" % (
                t, p.returncode, time.monotonic() - t0, " | ".join(summary[:4])[:600],
                os.path.relpath(os.path.join(fdir, t + ".log"), ROOT)))
        return t, execs, fails

    with ThreadPoolExecutor(max_workers=2) as ex:
        results = list(ex.map(one, targets))
    return results, None


# ---- category 9: ThreadSanitizer -------------------------------------------------------


def run_tsan(runner, env):
    results, skips = [], []
    tsan = os.path.join(env["stress"], "tsan", "pound")
    skip = os.path.join(env["stress"], "tsan.skip")
    inputs = env["flag_inputs"]
    sweeps = [
        ["spectrum", "--Pi2", "0.2:3:24", "--Pi3", "0.01,0.1", "--pulse", "sine,cosine", "-o", "t.h5"],
        ["spectrum", "--Pi2", "0.2:3:24", "--Pi3", "0.01,0.1", "--method", "event", "-o", "t.csv"],
        ["spectrum", "--Pi2", "0.5:2:6", "--method", "penalty", "--json"],
        ["spectrum", "--scene", "s.json", "--Pi2", "0.5:2:8", "-o", "t.h5"],
        ["spectrum", "--Pi2", "0.5:2:16", "-o", "r.h5", "--stop-after", "5"],
    ]
    # determinism on the plain build: 2 threads = 1 thread, byte for byte
    for argv in sweeps[:2] + sweeps[3:4]:
        d = tempfile.mkdtemp(dir=runner.scratch, prefix="threads-")
        for name, data in inputs.items():
            shutil.copyfile(data[1], os.path.join(d, name)) if isinstance(data, tuple) else None
        out = argv[argv.index("-o") + 1]
        r1 = runner.exec(argv[:-1] + ["one-" + out, "--threads", "1"], d, 60)
        r2 = runner.exec(argv[:-1] + ["two-" + out, "--threads", "2"], d, 60)
        f = []
        if r1.rc != 0 or r2.rc != 0:
            f.append("exit %s / %s" % (r1.rc, r2.rc))
        else:
            with open(os.path.join(d, "one-" + out), "rb") as a, open(os.path.join(d, "two-" + out), "rb") as b:
                if a.read() != b.read():
                    f.append("the file of 2 threads differs from that of 1 thread")
        results.append(("pound %s --threads 1 vs 2" % " ".join(argv), f))
    if os.path.exists(skip) or not os.path.exists(tsan):
        skips.append(open(skip).read().strip() if os.path.exists(skip) else "tsan: skip (not built)")
        return results, skips
    archer = ""
    ap = os.path.join(env["stress"], "archer.path")
    if os.path.exists(ap):
        archer = open(ap).read().strip()
    supp = os.path.join(HERE, "tsan.supp")
    tenv = {"OMP_NUM_THREADS": "2", "TSAN_OPTIONS": "halt_on_error=0 exitcode=66 "
            "ignore_noninstrumented_modules=1 suppressions=%s" % supp}
    if archer:
        tenv["OMP_TOOL_LIBRARIES"] = archer
    else:
        skips.append("tsan: libarcher.so not found: OpenMP synchronisation is invisible to TSan "
                     "(reports inside libomp may be false positives)")
    old = runner.pound
    runner.pound = tsan
    try:
        for argv in sweeps:
            d = tempfile.mkdtemp(dir=runner.scratch, prefix="tsan-")
            for name, data in inputs.items():
                shutil.copyfile(data[1], os.path.join(d, name)) if isinstance(data, tuple) else None
            r = runner.exec(argv + ["--threads", "2"], d, 180, env=tenv, aslimit=False)
            err = r.err.decode("utf-8", "replace")
            f = []
            races = err.count("WARNING: ThreadSanitizer")
            want = 130 if "--stop-after" in argv else 0
            if races:
                first = re.search(r"WARNING: ThreadSanitizer: ([^\n]*)((?:\n[^\n]*){0,12})", err)
                f.append("%d ThreadSanitizer report(s): %s%s" % (
                    races, first.group(1) if first else "", (first.group(2) if first else "")[:700]))
            if r.rc != want and not races:
                f.append("exit %s (expected %d): %s" % (r.rc, want, err.strip()[-300:]))
            if r.timed_out:
                f.append("hang under TSan")
            results.append(("[tsan] pound %s --threads 2" % " ".join(argv), f))
    finally:
        runner.pound = old
    return results, skips


# ---- the report ------------------------------------------------------------------------


def write_report(path, summary, failures, skips, wall):
    begin, end = "<!-- stress table -->", "<!-- end stress table -->"
    lines = [begin, "",
             "Last run: %s, %d failures, %.0f s on %d cores (`make stress`)." % (
                 time.strftime("%Y-%m-%d"), sum(n for _, _, n in summary), wall, os.cpu_count() or 1),
             "", "| category | inputs tried | failures | what |", "| --- | ---: | ---: | --- |"]
    for cat, tried, nf in summary:
        lines.append("| %s | %s | %s | %s |" % (cat, tried, nf, CAT_TEXT.get(cat, "")))
    if skips:
        lines += [""] + ["- " + s for s in skips]
    if failures:
        lines += ["", "Failures of the last run (command → what went wrong; stderr):", ""]
        for cat, cmd, fs, res in failures[:400]:
            err = res.err.decode("utf-8", "replace").strip().replace("\n", " | ")[:300] if res else ""
            rc = ("exit %s" % res.rc) if res and res.rc is not None and not res.timed_out else \
                ("timeout" if res and res.timed_out else "")
            lines.append("- [%s] `%s` — %s%s%s" % (
                cat, cmd.replace("`", "'"), "; ".join(fs).replace("`", "'"),
                (" (%s)" % rc) if rc else "", ("; stderr: `%s`" % err.replace("`", "'")) if err else ""))
        if len(failures) > 400:
            lines.append("- ... and %d more" % (len(failures) - 400))
    lines += ["", end]
    block = "\n".join(lines)
    text = open(path).read() if os.path.exists(path) else "# Reliability\n\n%s\n%s\n" % (begin, end)
    if begin in text and end in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(text)


# ---- main ---------------------------------------------------------------------------------


def make_inputs(runner, env):
    """The files the flag, fault and hang cases use, made once."""
    d = tempfile.mkdtemp(dir=runner.scratch, prefix="inputs-")
    files = {
        "a.lcp": open(os.path.join(HERE, "corpus", "lcp", "base2.lcp"), "rb").read(),
        "r.AT2": open(os.path.join(HERE, "corpus", "record", "synth.AT2"), "rb").read(),
        "s.json": open(os.path.join(ROOT, "examples", "scenes", "two-sdof.json"), "rb").read(),
        "murty20.lcp": mutate.lcp_plain([[1.0 if i == j else (2.0 if j < i else 0.0) for j in range(20)]
                                         for i in range(20)], [-1.0] * 20).encode(),
        "dev-zero-record.json": json.dumps({
            "excitation": {"record": "/dev/zero", "dir": "+x"},
            "structures": [{"name": "A", "T0": 0.5}],
            "contacts": [{"a": "A", "b": "wall", "gap": 0.01, "eps": 0.5}]}).encode(),
    }
    for name, data in files.items():
        with open(os.path.join(d, name), "wb") as f:
            f.write(data)
    r = runner.exec(["simulate", "--chain", "3", "--tend", "0.5", "--dump-lcp", "d.h5"], d, 60)
    if r.rc == 0 and os.path.exists(os.path.join(d, "d.h5")):
        files["d.h5"] = None
        r2 = runner.exec(["lcp", "d.h5", "--all", "--json"], d, 60)
        try:
            env["dump_count"] = int(json.loads(r2.out)["count"])
            env["dump"] = True
        except (ValueError, KeyError, TypeError):
            env["skips"].append("flags: the LCP dump could not be read back: --index cases skipped")
    else:
        env["skips"].append("flags: simulate --dump-lcp failed (exit %s): --index cases skipped" % r.rc)
    env["flag_inputs"] = {name: ("copy", os.path.join(d, name)) for name in files}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default=os.path.join(ROOT, "build", "pound"))
    ap.add_argument("--stress", default=os.path.join(ROOT, "build", "stress"),
                    help="where `make stress` built the fuzzers and the TSan binary")
    ap.add_argument("--report", default=None, help="rewrite the stress table of this file")
    ap.add_argument("--only", default=None, help="comma-separated categories")
    ap.add_argument("--jobs", type=int, default=max(2, (os.cpu_count() or 2) + 1))
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--fuzz-time", type=int, default=20)
    ap.add_argument("--keep", action="store_true", help="keep the scratch folders of failures")
    args = ap.parse_args()
    cats = args.only.split(",") if args.only else CATEGORIES
    for c in cats:
        if c not in CATEGORIES:
            ap.error("unknown category %r (one of %s)" % (c, ", ".join(CATEGORIES)))
    t_start = time.monotonic()
    os.makedirs(args.stress, exist_ok=True)
    scratch = tempfile.mkdtemp(prefix="pound-stress-")
    pound = os.path.join(scratch, "pound")
    shutil.copy2(args.pound, pound)  # a rebuild during the run cannot swap it
    runner = Runner(pound, scratch, args.timeout, args.keep)
    env = {"skips": [], "stress": os.path.abspath(args.stress)}
    make_inputs(runner, env)
    if "journal" in cats or "fuzz" in cats:
        msg = prep_journal(runner, env)
        if msg:
            env["skips"].append("journal: cannot make a journal: " + msg)
    gens = {"flags": cases_flags, "lcp": cases_lcp, "scene": cases_scene, "record": cases_record,
            "journal": cases_journal, "faults": cases_faults, "hangs": cases_hangs}
    all_cases = []
    for c in cats:
        if c in gens:
            all_cases += gens[c](env)
    # the long ones first, so that they overlap the many short ones
    all_cases.sort(key=lambda c: 0 if c.cat in ("hangs", "faults", "journal") else 1)
    per_cat = {c: [0, []] for c in cats}
    done = [0]

    def progress(fut_result):
        done[0] += 1
    with ThreadPoolExecutor(max_workers=args.jobs) as ex:
        for case, res, fails in ex.map(lambda c: run_case(runner, c), all_cases):
            per_cat[case.cat][0] += 1
            if fails:
                per_cat[case.cat][1].append((case, res, fails))
    fuzz_results = None
    if "fuzz" in cats:
        fuzz_results, msg = run_fuzz(runner, env, args.fuzz_time)
        if msg:
            env["skips"].append(msg)
        else:
            per_cat["fuzz"][0] = sum(n for _, n, _ in fuzz_results)
            for t, n, fs in fuzz_results:
                for f in fs:
                    per_cat["fuzz"][1].append((Case("fuzz", [t], "0", display=t), None, [f]))
    if "tsan" in cats:
        results, skips = run_tsan(runner, env)
        env["skips"] += skips
        per_cat["tsan"][0] = len(results)
        for cmd, fs in results:
            if fs:
                per_cat["tsan"][1].append((Case("tsan", [], "0", display=cmd), None, fs))
    wall = time.monotonic() - t_start
    summary, failures = [], []
    print("stress: %s (a copy of %s), %d jobs, %.0f s" % (os.path.relpath(args.pound, ROOT), args.pound,
                                                        args.jobs, wall))
    for c in cats:
        tried, fl = per_cat[c]
        if c == "fuzz" and fuzz_results:
            tried_s = "%d executions of %d harnesses" % (tried, len(fuzz_results))
        elif c == "fuzz" or (c == "tsan" and any(s.startswith("tsan: skip") for s in env["skips"])):
            tried_s = str(tried) + (" (skipped)" if c == "fuzz" else " (plain build only)")
        else:
            tried_s = str(tried)
        summary.append((c, tried_s, len(fl)))
        print("%s, %s inputs tried, %d failures" % (c, tried_s, len(fl)))
        for case, res, fs in fl:
            failures.append((c, case.command(), fs, res))
    for s in env["skips"]:
        print(s)
    if failures:
        print("\nfailures:")
    for cat, cmd, fs, res in failures:
        print("[%s] %s" % (cat, cmd))
        for f in fs:
            print("    " + f)
        if res is not None:
            print("    exit: %s%s" % ("timeout" if res.timed_out else res.rc,
                                      "  (%.1f s, %.0f MB)" % (res.secs, res.rss_mb)))
            err = res.err.decode("utf-8", "replace").rstrip()
            if err:
                print("    stderr: " + err[:600].replace("\n", "\n            "))
    if args.report:
        write_report(args.report, summary, failures, env["skips"], wall)
    if not args.keep:
        shutil.rmtree(scratch, ignore_errors=True)
    else:
        print("scratch kept in " + scratch)
    print("stress: %d failures (%.0f s)" % (len(failures), time.monotonic() - t_start))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
