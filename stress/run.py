#!/usr/bin/env python3
"""stress/run.py — pound's adversarial test suite (`make stress`).

    python3 stress/run.py [--pound build/pound] [--stress build/stress]
                          [--report docs/reliability.md] [--only CAT[,CAT]]
                          [--jobs N] [--timeout S] [--fuzz-time S] [--keep]

Every case runs the binary (a private copy, so that a concurrent rebuild
cannot change it under the suite) in its own scratch folder, under a limit
of CPU time (a case still computing then is a "hang"; CPU time, so that a
loaded machine slows a case without failing it), a wall-clock backstop for
runs that block without computing (5 times the CPU limit; 10 s where a FIFO
could block pound), and an address-space limit, and is judged by the same
rules (docs/reliability.md):

  - never a signal: no exit by a signal, no exit status >= 128;
  - never a wrong success: exit 0 only where the table allows it;
  - exit 2 (bad input): exactly one line on stderr, matching the case's regex
    (the flag the user typed, or FILE:LINE, or FILE:LINE:COL and the field);
  - exit 1 (runtime error): the reason on one line of stderr (pound lcp: a
    status other than "solved" on stdout);
  - no file left behind by a failed run (no F, F.tmp*, F.partial; a
    spectrum's F.partial is kept on purpose after an interrupted sweep), and
    no temporary file after a successful one; an output reported written is
    whole (scene outputs: every CSV row as wide as the header, the header and
    the HDF5 groups naming the scene's structures);
  - --json on success prints exactly one JSON object (no NaN or Infinity);
  - bounded memory: peak RSS under 1 GB;
  plus the checks of each category (an LCP answered "solved" is recomputed in
  exact rational arithmetic; a resumed spectrum equals the uninterrupted one,
  and an uninterrupted run that fails is a failure, not a skipped check).

Categories: corpus, flags, lcp, scene, record, journal, faults, hangs,
nonregular, names, bounds, derived, capi, python, fuzz, tsan.  The in-repo
corpus is always expected (category corpus rebuilds it in memory with
stress/gen_corpus.py and compares); ../shared (or $POUND_SHARED) is expected
when it exists or when POUND_SHARED is set: then a missing part is a
failure.  POUND_STRESS_STRICT=1 (.ci/run) turns a skipped capi or python
category (no clang, NumPy or pytest) into a failure.
One line per category ("flags: 1234 inputs, 2 failures"), then the
failures, then "stress: N failures"; exit 1 when there is any.  With
--report, the table between the markers <!-- stress table --> and
<!-- end stress table --> of that file is rewritten.  STRESS_PROFILE=1 lists
the runs that took the most CPU and wall time."""
import argparse
import concurrent.futures
import csv
import json
import os
import re
import resource
import shlex
import shutil
import signal
import stat
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

# the shared test data (Siconos LCPs, PEER/COSMOS records): ../shared, or $POUND_SHARED
SHARED = os.path.normpath(os.environ.get("POUND_SHARED") or os.path.join(ROOT, "..", "shared"))
AS_LIMIT = 4 << 30          # address space of every run (bytes)
RSS_BOUND_MB = 1024         # "bounded memory"
CATEGORIES = ["corpus", "flags", "lcp", "scene", "record", "journal", "faults", "hangs",
              "nonregular", "names", "bounds", "derived", "hostile", "physics", "capi", "python",
              "fuzz", "tsan"]
CAT_TEXT = {
    "corpus": "the in-repo corpus and tables (stress/corpus, stress/cases) equal what "
              "stress/gen_corpus.py makes; ../shared's LCPs and records present when expected",
    "flags": "every flag of every command: NaN, inf, 1e308, 0, -1, denormals, empty, '1e', "
             "'0x10', 100 kB strings, unknown words, missing values, unknown and conflicting flags",
    "lcp": "LCP files, plain and Siconos: truncations, extra tokens, NaN/inf, huge and tiny "
           "numbers, bad sizes, letters, binary junk, CRLF; extreme well-formed problems "
           "with every solver, answers recomputed exactly",
    "scene": "scene JSON, each run with -o (CSV or HDF5) and one expected status: truncations, "
             "wrong types, negative/zero/1e308/1e999/NaN values, duplicate keys, control bytes "
             "in names, huge arrays, records that are not files; refused with FILE:LINE:COL and "
             "the field, nothing left; accepted with a whole output",
    "record": "records (AT2, COSMOS V2, text): truncated, wrong NPTS/DT, NaN, non-uniform time, "
              "empty, no header, binary junk, CRLF; records as excitations",
    "journal": "spectrum journals (F.partial) corrupted, then `spectrum -o F --resume`",
    "faults": "full disk (RLIMIT_FSIZE), stdout on /dev/full or closed, missing or "
              "read-only target folders, SIGTERM/SIGINT/SIGXCPU during long runs, then --resume",
    "hangs": "inputs that could loop or run away: extreme periods, stiff penalties, "
             "Zeno accumulations, /dev/zero as an input",
    "nonregular": "FIFOs (with and without a reader or writer), device nodes, folders and links "
                  "to FIFOs as --record, --scene, a scene's record, an LCP, a journal, -o, "
                  "--dump-lcp, --plot: refused at once, the node left as it was",
    "names": "structure names the writers cannot carry (comma, '.', empty, quote, control "
             "characters, 300 characters, '/', 'wall'): refused naming structures[i].name; "
             "spaces, UTF-8, 63 characters, the file's own names (t, storey, x): written as "
             "given (CSV header, HDF5 groups)",
    "bounds": "work and memory refused up front: 20000 or 5e6 contact levels, 20000 pairs or "
              "entries, a 160 kHz mode for the event-driven and penalty methods; penalty "
              "chains whose elements switch at one instant stopped within the 10 s (exit 1, "
              "Moreau-Jean named)",
    "derived": "derived quantities out of range (T0 = Tp / Pi2, steps over tend, gap / Le): "
               "the flag the user typed is named first",
    "hostile": "the fourth round's inputs: rows at gaps within the closing tolerance (1e-300, "
               "5e-324) and touching buildings run in seconds by the row reference; masses "
               "beyond double precision refused naming moreau; derived demands that overflow "
               "(contact-duration, storey_heights) and newmark's budgets refused naming the "
               "field; another method's flags refused; 1000 bodies to HDF5 under an "
               "address-space limit: out of memory, no signal, nothing left",
    "physics": "the row reference's physics at every impact over generated hostile rows (2 to "
               "30 SDOFs between walls, masses over 12 decades, gaps 0, 1e-300, 1e-13 m, 1e-6 "
               "m, 1 cm, restitutions in [0, 1]; 6 seeds of 200 rows): "
               "momentum balances, kinetic energy never rises, every row answers or ends with "
               "its chatter named (tests/test_rows.c test_rows_hostile_physics)",
    "capi": "the C API misused under ASan + UBSan: every exported function with NULL in each "
            "pointer argument (generated from the headers), results of another shape, zeroed, "
            "or for an unfinished scene",
    "python": "the Python package misused: NaN/inf and wrong types in LCPs, options and "
              "scenes, paths with NUL bytes or as bytes, fractional counts, booleans as "
              "numbers (python/tests/test_misuse.py); to_pandas of sweeps, plot indices, "
              "record= arrays of every dtype (test_harden4.py)",
    "fuzz": "libFuzzer + ASan + UBSan on the readers: LCP, scene, record, spectrum and suite "
            "journals",
    "tsan": "ThreadSanitizer on parallel spectrum sweeps (2 OpenMP threads); "
            "2 threads = 1 thread byte for byte",
}


# ---- running one case ----------------------------------------------------------


class Result:
    def __init__(self, rc=None, out=b"", err=b"", secs=0.0, rss_mb=0.0, timed_out=False):
        self.rc, self.out, self.err = rc, out, err
        self.secs, self.rss_mb, self.timed_out = secs, rss_mb, timed_out
        self.cpu, self.why = 0.0, ""


class Case:
    """One input and what is expected of pound on it.  timeout is in CPU
    seconds of the run (a loaded machine slows it without failing it); wall
    is the backstop for a run that blocks without computing (default: 5
    times timeout, at least 60 s)."""
    _n = 0
    _lock = threading.Lock()

    def __init__(self, cat, argv, expect, regex=None, inputs=None, timeout=None,
                 partial_ok=False, stdout=None, prefix=None, setup=None, check=None, run=None,
                 rss_mb=RSS_BOUND_MB, env=None, why=None, display=None, rc1_reason=True,
                 outputs=None, stderr_lost=False, wall=None, pipes=False, rc1_regex=None,
                 heavy=False, as_limit=AS_LIMIT):
        with Case._lock:
            Case._n += 1
            self.id = Case._n
        self.cat, self.argv, self.expect = cat, list(argv), expect
        self.regex = regex
        self.inputs = inputs or {}
        self.timeout = timeout
        self.wall = wall
        self.partial_ok = partial_ok
        self.stdout = stdout          # None: captured; a path: stdout goes there
        self.prefix = prefix or []    # wrapper command before pound (prlimit, sh -c)
        self.setup, self.check, self.run = setup, check, run
        self.rss_mb = rss_mb
        self.env = env
        self.why = why                # what the regex stands for, in failure messages
        self.display = display
        self.rc1_reason = rc1_reason  # exit 1 needs one line on stderr
        self.rc1_regex = rc1_regex    # and that line must match this
        self.outputs = outputs        # names a success may create (None: any)
        self.stderr_lost = stderr_lost  # stderr cannot be written (2>/dev/full)
        self.pipes = pipes            # stdout and stderr through pipes (a file-size limit)
        self.heavy = heavy            # started first (a large input)
        self.as_limit = as_limit      # address-space limit of the run

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


def wall_limit(cpu, wall=None):
    return wall if wall else max(5.0 * cpu, 60.0)


class Runner:
    def __init__(self, pound, scratch, timeout, keep):
        self.pound, self.scratch, self.timeout, self.keep = pound, scratch, timeout, keep

    def exec(self, argv, cwd, timeout, stdout=None, prefix=(), env=None, stdin=None,
             aslimit=AS_LIMIT, wall=None, pipes=False):
        """Run pound (or prefix + pound) in cwd, under an address-space limit
        (not for sanitizer builds, whose shadow memory needs more), at most
        `timeout` CPU seconds (and `wall` seconds): a Result.  With pipes,
        stdout and stderr reach their files through pipes, so that a
        file-size limit on pound does not apply to them."""
        io = tempfile.mkdtemp(dir=self.scratch, prefix="io-")
        outp, errp = os.path.join(io, "out"), os.path.join(io, "err")
        full_env = dict(os.environ)
        full_env.update(env or {})
        cmd = list(prefix) + [self.pound] + list(argv)
        if aslimit:
            cmd = ["prlimit", "--as=%d" % aslimit, "--"] + cmd
        with open(outp if stdout is None else stdout, "wb") as fo, open(errp, "wb") as fe:
            t0 = time.monotonic()
            stdin = stdin if stdin is not None else subprocess.DEVNULL
            if pipes:
                p = subprocess.Popen(cmd, cwd=cwd, stdin=stdin, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, start_new_session=True, env=full_env)
                pumps = [threading.Thread(target=pump, args=(p.stdout, fo), daemon=True),
                         threading.Thread(target=pump, args=(p.stderr, fe), daemon=True)]
                for t in pumps:
                    t.start()
            else:
                p = subprocess.Popen(cmd, cwd=cwd, stdin=stdin, stdout=fo, stderr=fe,
                                     start_new_session=True, env=full_env)
            res = wait_pid(p, timeout, t0, wall_limit(timeout, wall))
            if pipes:
                for t in pumps:
                    t.join(10)
        if stdout is None:
            res.out = read_head(outp)
        res.err = read_head(errp)
        shutil.rmtree(io, ignore_errors=True)
        return res


def pump(src, dst):
    while True:
        b = src.read(65536)
        if not b:
            break
        dst.write(b)
    src.close()


CLK_TCK = os.sysconf("SC_CLK_TCK")


def proc_cpu(pid):
    """CPU seconds used so far by process pid (all its threads, and the
    children it has reaped), from /proc; 0 when it cannot be read."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            st = f.read()
        v = st[st.rindex(")") + 2:].split()
        return sum(int(x) for x in v[11:15]) / CLK_TCK
    except (OSError, ValueError, IndexError):
        return 0.0


def wait_pid(p, cpu_limit, t0, wall):
    """Reap p (its own session) with os.wait4 for its peak RSS and CPU time;
    SIGKILL the group past cpu_limit CPU seconds or wall seconds."""
    delay, timed_out, why = 0.001, False, ""
    while True:
        pid, status, ru = os.wait4(p.pid, os.WNOHANG)
        if pid:
            break
        el = time.monotonic() - t0
        cpu = proc_cpu(p.pid)
        if cpu > cpu_limit or el > wall:
            timed_out = True
            why = ("still computing after %.0f s of CPU (limit %g s)" % (cpu, cpu_limit)
                   if cpu > cpu_limit else
                   "still running after %.0f s (wall limit) having used %.1f s of CPU%s"
                   % (el, cpu, ": blocked" if cpu < 0.2 * el else ""))
            kill_group(p.pid)
            pid, status, ru = os.wait4(p.pid, 0)
            break
        time.sleep(delay)
        delay = min(delay * 1.5, 0.05)
    p.returncode = os.waitstatus_to_exitcode(status)
    kill_group(p.pid)  # anything it started (gnuplot) goes with it
    res = Result(rc=p.returncode, secs=time.monotonic() - t0, rss_mb=ru.ru_maxrss / 1024.0,
                 timed_out=timed_out)
    res.cpu = ru.ru_utime + ru.ru_stime
    res.why = why
    return res


def suite_rss_mb():
    """The suite's own peak RSS: a child's ru_maxrss includes its parent's
    at fork and exec (Linux keeps the larger across execve), so a child's
    figure at or below this one says nothing about the child."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


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
        f.append("hang: %s (killed)" % (res.why or "still running after %g s" % case.timeout))
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
        if case.rc1_regex and lines and not re.search(case.rc1_regex, lines[0]):
            f.append("exit 1 without the reason /%s/" % case.rc1_regex)
    # (a child's ru_maxrss is at least the suite's peak RSS at its start:
    # only a figure above that one is the child's own)
    if res.rss_mb > case.rss_mb and res.rss_mb > suite_rss_mb() + 1:
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
            elif callable(data):  # a large input, written when its case runs
                with open(p, "wb") as fo:
                    data(fo)
            else:
                with open(p, "wb") as fo:
                    fo.write(data)
        if case.setup:
            failures += case.setup(runner, case, d) or []
        if getattr(case, "skip", None):
            with Case._lock:
                SKIPS.append("%s: %s: skip (%s)" % (case.cat, case.command(), case.skip))
            return case, None, []
        before = listing(d)
        if failures:
            pass
        elif case.run:
            res, extra = case.run(runner, case, d)
            failures += extra
        else:
            res = runner.exec(case.argv, d, case.timeout, stdout=case.stdout, prefix=case.prefix,
                              env=case.env, wall=case.wall, pipes=case.pipes,
                              aslimit=case.as_limit)
        if res is not None:
            failures = judge(case, res, listing(d) - before) + failures
            if case.check:
                failures += case.check(runner, case, d, res) or []
    except Exception as e:  # a bug of the suite is a failure too, never a crash of it
        failures.append("suite error: %s: %s" % (type(e).__name__, e))
    finally:
        for _, _, fd in getattr(case, "fds", []):
            os.close(fd)
        case.fds = []
        if not (runner.keep and failures):
            shutil.rmtree(d, ignore_errors=True)
    return case, res, failures


SKIPS = []  # cases that could not be set up here (a device node without the right)


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
        for tok in ["--bogus", "--Pi22", "-", "--", "-x", "---ap", "--AP", "stray",
                    "--" + "z" * 5000]:
            add(cmd, base + [tok], "2", flag_re(tok) if len(tok) < 100 else re.escape(tok[:40]),
                "the unknown flag %s" % short_arg(tok))
        # --flag=value is --flag value: an unknown flag, a bad value, an empty one, named
        for tok, flag in [("--bogus=1", "--bogus"), ("--ap=0", "--ap"), ("--ap=", "--ap")]:
            add(cmd, base + [tok], "2", flag_re(flag), "%s as --flag=value" % tok)
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
        (["--chain", "3", "--record", "r.AT2"], r"--chain|--record"),
        (["--scale", "2"], r"--scale"),
    ]
    for cmd in ("simulate", "compare", "converge"):
        base = COMMANDS[cmd][0]
        for argv, rx in conflicts:
            add(cmd, base + argv, "2", rx, "one of " + rx.replace("|", ", "))
        # a record on a scene replaces its excitation (suites of records run so)
        add(cmd, base + ["--scene", "s.json", "--record", "r.AT2"], "0")
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
        stem, ext = os.path.splitext(os.path.basename(base))
    elif fam == "scene":
        with open(os.path.join(ROOT, "examples", "scenes", base)) as f:
            muts = mutate.scene_mutants(f.read())
        stem, ext = base[:-5], ".json"
    else:
        with open(os.path.join(HERE, "corpus", "record", base), encoding="latin-1") as f:
            text = f.read()
        kind = "text" if base.endswith(".txt") else "v2" if base.endswith(".V2") else "at2"
        muts = mutate.record_mutants(text, kind)
        stem, ext = os.path.splitext(base)
    m = next(m for m in muts if m.name == name)
    return "%s--%s%s" % (stem, re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_")[:80], ext), m.data


def fail_case(cat, display, msg):
    """A case that is a failure by itself (a missing corpus)."""
    return Case(cat, [], "0", display=display, run=lambda runner, case, d: (None, [msg]))


def cases_table(kind):
    cases = []
    corpus = os.path.join(HERE, "corpus", kind)
    for inp, cmd, expect, regex, check in table_rows(kind):
        if inp.startswith("gen:"):
            try:
                fname, data = gen_input(inp)
            except (OSError, StopIteration) as e:
                cases.append(fail_case(kind, inp, "corpus: cannot make %s: %s" % (inp, e)))
                continue
            inputs = {fname: data}
        else:
            src = os.path.normpath(os.path.join(corpus, inp))
            fname = os.path.basename(src)
            if not os.path.exists(src):
                cases.append(fail_case(kind, inp, "corpus: %s is missing (run stress/gen_corpus.py)"
                                       % os.path.relpath(src, ROOT)))
                continue
            inputs = {fname: ("copy", src)}
        argv = [a.replace("{F}", fname) for a in shlex.split(cmd)]
        cases.append(Case(kind, argv, expect, regex or None, inputs=inputs,
                          heavy=inp.startswith("gen:"),
                          why="the file, line and field (%s)" % fname if kind == "scene"
                          else "the file and line (%s)" % fname,
                          check=check_lcp if check == "verify-lcp" else
                          check_output if check == "output" else None,
                          rc1_reason=argv[0] != "lcp"))
    return cases


# ---- outputs: whole after a success, absent after a failure --------------------------


def out_name(argv):
    for flag in ("-o", "--dump-lcp"):
        if flag in argv and argv.index(flag) + 1 < len(argv):
            return argv[argv.index(flag) + 1]
    return None


def scene_layout(path):
    """(names, storeys per structure, number of contacts, storeys of the
    yielding structures: their up columns) of a scene file, or None when
    Python's JSON reader does not take it (a BOM, ...)."""
    try:
        with open(path, "rb") as f:
            doc = json.loads(f.read().decode("utf-8"))
        names, storeys, yielding = [], [], 0
        for st in doc["structures"]:
            names.append(st["name"])
            storeys.append(len(st["masses"]) if "masses" in st else int(st.get("storeys", 1)))
            yielding += storeys[-1] if "uy" in st else 0
        nc = 0
        for c in doc.get("contacts") or []:
            nc += len(c["pairs"]) if "pairs" in c else len(c.get("levels", [1]))
        return names, storeys, nc, yielding
    except (ValueError, KeyError, TypeError, UnicodeDecodeError, OSError):
        return None


def h5_names(path, group):
    """The names of the members of group in an HDF5 file (h5ls), or an error string."""
    if not shutil.which("h5ls"):
        return None
    p = subprocess.run(["h5ls", "%s/%s" % (path, group)], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, timeout=120)
    if p.returncode != 0:
        return "h5ls %s/%s: exit %d: %s" % (os.path.basename(path), group, p.returncode,
                                           p.stderr.decode(errors="replace").strip()[:200])
    names = []
    for ln in p.stdout.splitlines():
        m = re.match(rb"((?:\\[0-7]{3}|\\.|\S)+)\s+(Group|Dataset)", ln)
        if m:  # h5ls escapes blanks as "\ " and bytes beyond ASCII as "\ooo"
            raw = re.sub(rb"\\([0-7]{3})|\\(.)", lambda x: bytes([int(x.group(1), 8)]) if x.group(1)
                         else x.group(2), m.group(1))
            names.append(raw.decode("utf-8", "replace"))
    return names


def verify_output(path, layout):
    """Failures of an output that exit 0 reported: it must be whole, and a
    scene's outputs must name its structures (CSV columns NAME.x1 ...,
    HDF5 groups /structures/NAME)."""
    f = []
    if not os.path.exists(path):
        return ["exit 0 but no %s" % os.path.basename(path)]
    if path.endswith(".csv"):
        # streamed: outputs of tens of MB must not swell the suite (whose RSS
        # every child's ru_maxrss includes, see suite_rss_mb)
        with open(path, "rb") as fo:
            if os.path.getsize(path):
                fo.seek(-1, os.SEEK_END)
                if fo.read(1) != b"\n":
                    f.append("%s does not end with a newline (cut?)" % os.path.basename(path))
        with open(path, newline="", encoding="utf-8", errors="replace") as fo:
            rows = csv.reader(ln for ln in fo if not ln.startswith("#"))
            head = next(rows, None)
            if head is None:
                return f + ["%s has no header row" % os.path.basename(path)]
            for i, r in enumerate(rows, 2):
                if len(r) != len(head):
                    f.append("%s: row %d has %d fields, the header %d" % (
                        os.path.basename(path), i, len(r), len(head)))
                    break
        if layout:
            names, storeys, nc, yielding = layout
            # the penalty methods add each contact's element force
            forces = sum(1 for h in head if h.endswith(".force"))
            want = 1 + 3 * sum(storeys) + 2 * nc + yielding + (nc if forces else 0)
            if len(head) != want or forces not in (0, nc):
                f.append("%s: the header has %d columns, the scene needs %d (t, x, v and a of %d "
                         "storeys, gap and impulse of %d contacts, up of %d yielding storeys, "
                         "%d forces)" % (os.path.basename(path), len(head), want, sum(storeys),
                                         nc, yielding, forces))
            cols = set(head)
            missing = [n for n in names if n + ".x1" not in cols]
            if missing:
                f.append("%s: the header names no column %r" % (os.path.basename(path),
                                                               missing[0] + ".x1"))
    elif path.endswith((".h5", ".hdf5")):
        with open(path, "rb") as fo:
            if fo.read(8) != b"\x89HDF\r\n\x1a\n":
                return ["%s is not an HDF5 file" % os.path.basename(path)]
        if layout:
            got = h5_names(path, "structures")
            if isinstance(got, str):
                f.append(got)
            elif got is not None:
                have = set(got)
                missing = [n for n in layout[0] if n not in have]
                if missing or len(got) != len(layout[0]):
                    f.append("%s: /structures holds %s, the scene names %s" % (
                        os.path.basename(path), short_list(got), short_list(layout[0])))
    return f


def short_list(xs):
    return "[%s%s]" % (", ".join(repr(x) for x in xs[:4]), ", ..." if len(xs) > 4 else "")


def check_output(runner, case, d, res):
    """A scene run with -o: after exit 0 the output is whole and names the
    structures; after a failure nothing of it is left (judge() sees any new
    file, out.csv.tmpPID included)."""
    out = out_name(case.argv)
    if res is None or res.timed_out or res.rc != 0 or not out:
        return []
    layout = None
    if "--scene" in case.argv and case.argv[0] == "simulate":
        layout = scene_layout(os.path.join(d, case.argv[case.argv.index("--scene") + 1]))
    return verify_output(os.path.join(d, out), layout)


# ---- the corpora: in the repository always; ../shared when it is expected ---------------


def shared_expected():
    """(expected, why): the shared corpus (../shared or $POUND_SHARED) is
    expected when that folder exists or when POUND_SHARED names it; then a
    missing part is a failure."""
    if os.environ.get("POUND_SHARED"):
        return True, "POUND_SHARED=%s" % os.environ["POUND_SHARED"]
    if os.path.isdir(SHARED):
        return True, "%s exists" % SHARED
    return False, "%s absent" % SHARED


SHARED_NEEDS = {
    "lcp": ("data/lcp/siconos", ["lcp_CPS_1.dat", "lcp_mmc.dat", "lcp_trivial.dat"], ".dat"),
    "record": ("data/records", ["NGA_no_1063_RRS228.AT2", "RSN1044_NORTHR_NWH360.AT2",
                                "ce36456p_CE36456.V2"], (".at2", ".v2")),
}


def shared_dir(kind, env):
    """The shared folder of kind, or None; a failure case when it is expected
    and missing or incomplete, a skip note when it is not expected."""
    sub, needed, ext = SHARED_NEEDS[kind]
    d = os.path.join(SHARED, sub)
    expected, why = shared_expected()
    present = os.path.isdir(d) and any(n.lower().endswith(ext) for n in os.listdir(d))
    missing = [n for n in needed if not os.path.exists(os.path.join(d, n))] if present else needed
    if present and not missing:
        return d, []
    if not expected:
        env["skips"].append("%s: %s: its cases skipped (set POUND_SHARED to require it)"
                            % (kind, why))
        return (d if present else None), []
    msg = ("corpus: %s is expected (%s) but %s" % (
        os.path.relpath(d, ROOT) if d.startswith(ROOT) else d, why,
        "absent" if not present else "lacks " + ", ".join(missing)))
    return (d if present else None), [fail_case(kind, os.path.join("../shared", sub), msg)]


def cases_corpus(env):
    """The in-repo corpus (stress/corpus, stress/cases) equals what
    stress/gen_corpus.py makes now: a missing or stale file is a failure."""
    import gen_corpus
    try:
        files, counts = gen_corpus.build()
    except Exception as e:  # the generator itself is broken
        return [fail_case("corpus", "stress/gen_corpus.py", "corpus: build() failed: %s: %s"
                          % (type(e).__name__, e))]
    env["corpus_counts"] = counts
    problems = []
    for rel, data in sorted(files.items()):
        p = os.path.join(HERE, rel)
        if not os.path.exists(p):
            problems.append((rel, "missing"))
            continue
        with open(p, "rb") as f:
            if f.read() != data:
                problems.append((rel, "differs from what stress/gen_corpus.py makes"))
    for kind in gen_corpus.KINDS:
        top = os.path.join(HERE, "corpus", kind)
        for root, _, names in os.walk(top):
            for n in names:
                rel = os.path.relpath(os.path.join(root, n), HERE)
                if rel not in files:
                    problems.append((rel, "not made by stress/gen_corpus.py (stray)"))
    env["corpus_files"] = len(files)
    cases = []
    for rel, what in problems[:20]:
        cases.append(fail_case("corpus", "stress/" + rel, "corpus: stress/%s %s (run "
                               "python3 stress/gen_corpus.py)" % (rel, what)))
    if len(problems) > 20:
        cases.append(fail_case("corpus", "stress/corpus", "corpus: %d more files missing or "
                               "stale" % (len(problems) - 20)))
    return cases


def cases_lcp(env):
    cases = cases_table("lcp")
    sic, fails = shared_dir("lcp", env)
    cases += fails
    if not sic:
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
    rec, _ = shared_dir("record", {"skips": []})  # its failure is the record category's
    for name in sorted(os.listdir(os.path.join(ROOT, "examples", "scenes"))):
        if name.endswith(".json"):
            path = os.path.join(ROOT, "examples", "scenes", name)
            if "rinaldi" in name and not rec:
                continue
            # a yielding scene: newmark as well (the exact reference and compare, whose
            # judge it is, run yielding structures too)
            runs = [(["simulate", "--scene", path, "--json", "-o", "out.h5"], "0", None),
                    (["simulate", "--scene", path, "--method", "event", "--json", "-o",
                      "out.csv"], "0", None),
                    (["compare", "--scene", path, "--dt", "1e-3", "--json"], "0", None)]
            if "yielding" in name:
                runs.append((["simulate", "--scene", path, "--method", "newmark", "--json"], "0",
                             None))
            for cmd, expect, rx in runs:
                cases.append(Case("scene", cmd, expect, rx, check=check_output,
                                  display="pound " + " ".join(
                                      os.path.relpath(a, ROOT) if a.startswith("/") else a
                                      for a in cmd)))
    return cases


def cases_record(env):
    cases = cases_table("record")
    rdir, fails = shared_dir("record", env)
    cases += fails
    if not rdir:
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
    r = runner.exec(SWEEP[:-1] + ["0.6", "-o", "out.h5", "--stop-after", "1"], o, 60)
    try:
        with open(os.path.join(o, "out.h5.partial"), "rb") as f:
            env["other_key"] = f.read().split(b"\n")[1] + b"\n"
    except (OSError, IndexError):
        env.pop("journal", None)
        return "spectrum --eps 0.6 --stop-after 1 gave exit %s and no journal" % r.rc
    # the uninterrupted sweep the resumed ones must equal: if it fails or
    # runs out of time, that is a failure (the byte-for-byte check is not
    # skipped)
    r = runner.exec(SWEEP + ["-o", "ref.h5"], d, 60)
    if r.rc != 0 or r.timed_out:
        env.pop("journal", None)
        return "the uninterrupted sweep (the reference of --resume) failed: %s: %s" % (
            r.why if r.timed_out else "exit %s" % r.rc, r.err.decode(errors="replace").strip()[:200])
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
        return [fail_case("journal", "spectrum %s -o out.h5 --stop-after 7, then the whole sweep"
                          % " ".join(SWEEP[1:]),
                          "journal: cannot make the journal or the reference: %s"
                          % env.get("journal_error", "?"))]
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
    # about 20 s of work on 2 cores (8000 points took 0.3 s and ended first)
    long_sweep = ["spectrum", "--Pi2", "0.05:5:100000", "--Pi3", "0.05,0.1,0.2,0.4,0.8,1.6", "--eps", "0.5"]
    p = subprocess.Popen([runner.pound] + long_sweep + ["-o", "out.h5"], cwd=d,
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        t0 = time.monotonic()
        # (a loaded machine may take a while to start it: up to 30 s)
        while not os.path.exists(os.path.join(d, "out.h5.partial")) and time.monotonic() - t0 < 30:
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
    # RLIMIT_FSIZE as a full disk, as users meet it: SIGXFSZ keeps its default
    # action (the process is killed) unless pound itself handles it; pound's
    # stdout and stderr go through pipes (Case.pipes), out of the limit's reach
    return ["prlimit", "--fsize=%d" % nbytes, "--"]


# what an exit 1 under a file-size limit must say (docs/reliability.md, promise 4)
FSIZE_REASON = r"File too large|No space left on device"


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
        # the cleanup after the signal: at most 10 s of CPU (60 s of wall)
        t1, cpu0 = time.monotonic(), proc_cpu(p.pid)
        while p.poll() is None:
            if proc_cpu(p.pid) - cpu0 > 10 or time.monotonic() - t1 > 60:
                kill_group(p.pid)
                p.wait()
                f.append("hang: still running %.0f s after %s" % (time.monotonic() - t1,
                                                                  signame(sig)))
                break
            time.sleep(0.02)
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
            r2 = runner.exec(resume_argv, d, 120)
            if r2.rc != 0 or r2.timed_out:
                f.append("--resume after %s: %s: %s" % (
                    signame(sig), r2.why if r2.timed_out else "exit %s" % r2.rc,
                    r2.err.decode(errors="replace").strip()[:200]))
            else:
                # the uninterrupted run to compare with: its failure is a
                # failure of the case, never a skipped comparison
                r3 = runner.exec([a if a != out else "ref-" + out for a in case.argv], d, 120)
                if r3.rc != 0 or r3.timed_out:
                    f.append("the uninterrupted run (to compare the resumed %s with) failed: %s: %s"
                             % (out, r3.why if r3.timed_out else "exit %s" % r3.rc,
                                r3.err.decode(errors="replace").strip()[:200]))
                else:
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
                     partial_ok=argv[0] == "spectrum", pipes=True, rc1_regex=FSIZE_REASON,
                     display="prlimit --fsize=%d (full disk) pound %s" % (n, " ".join(argv)))
            c.check = no_output_check(out, n)
            cases.append(c)
    # outputs surely larger than the limit (issue 19): exit 1 with the reason,
    # nothing left (not killed by SIGXFSZ with F.tmpPID behind)
    for argv, out in [(["simulate", "-o", "x.csv"], "x.csv"),    # about 490 kB
                      (["simulate", "-o", "x.h5"], "x.h5"),      # about 340 kB
                      (["simulate", "--chain", "5", "--tend", "1", "--dump-lcp", "dump.h5"],
                       "dump.h5"),                                # about 570 kB
                      (["spectrum", "--Pi2", "0.5:2:400", "-o", "s.csv"], "s.csv")]:  # 145 kB
        c = Case("faults", argv, "1", None, inputs=inputs, prefix=fsize_prefix(100000),
                 partial_ok=argv[0] == "spectrum", pipes=True, rc1_regex=FSIZE_REASON,
                 display="prlimit --fsize=100000 (full disk) pound %s" % " ".join(argv))
        c.check = no_output_check(out, 100000)
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
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGXCPU):
        for argv, out, resumable in long_runs[:2] if sig == signal.SIGXCPU else long_runs:
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
        # (what a failure leaves is judge()'s: any new file)
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
        # 60 s of CPU: a runaway never ends, while legitimate heavy cases
        # take up to about 10 s (CPU time: a loaded machine does not matter)
        cases.append(Case("hangs", argv, "2" if is_dev else "012",
                          r"/dev/(zero|urandom)|dev-zero" if is_dev else None, inputs=inputs,
                          why="the file" if is_dev else None, timeout=60,
                          rc1_reason=argv[0] != "lcp"))  # lcp: its status is on stdout
    return cases


# ---- category: files that are not regular files ------------------------------------------


def scene_doc(name="A", record=None, structures=None, contacts=None, tend=None):
    """A small scene: one SDOF named `name` against a wall, under a sine
    pulse (or the record file `record`)."""
    d = {"excitation": {"record": record, "dir": "+x"} if record else
         {"pulse": "sine", "dir": "+x", "ap": 3.0, "Tp": 0.5},
         "structures": structures or [{"name": name, "T0": 0.5, "xi": 0.05}],
         "contacts": contacts if contacts is not None else
         [{"a": name, "b": "wall", "gap": 0.01, "eps": 0.5}]}
    if tend:
        d["tend"] = tend
    return json.dumps(d).encode("utf-8")


def node_id(path):
    st = os.lstat(path)
    return stat.S_IFMT(st.st_mode), st.st_ino, os.readlink(path) if os.path.islink(path) else None


def nonregular_setup(nodes, reader=None, writer=None):
    """Make the non-regular files of a case: nodes {name: "fifo" | "chardev"
    | "dir" | ("symlink", target)}; reader: a FIFO the suite holds open for
    reading (what pound would write into it is read back); writer: a FIFO
    the suite holds open for writing (pound's open succeeds, its read would
    wait forever)."""
    def setup(runner, case, d):
        for name, kind in nodes.items():
            p = os.path.join(d, name)
            if kind == "fifo":
                os.mkfifo(p)
            elif kind == "chardev":
                try:
                    os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # as /dev/null
                except OSError as e:
                    case.skip = "cannot make a device node (%s)" % e.strerror
                    return []
            elif kind == "dir":
                os.makedirs(p)
            else:
                os.symlink(kind[1], p)
        case.fds = []
        if reader:
            case.fds.append(("reader", reader, os.open(os.path.join(d, reader),
                                                       os.O_RDONLY | os.O_NONBLOCK)))
        if writer:
            case.fds.append(("writer", writer, os.open(os.path.join(d, writer), os.O_RDWR)))
        case.nodes = {name: node_id(os.path.join(d, name)) for name in nodes}
        return []
    return setup


def nonregular_check(runner, case, d, res):
    """The nodes are left as they were (a FIFO is not replaced by a regular
    file, nor written into)."""
    f = []
    for name, ident in getattr(case, "nodes", {}).items():
        p = os.path.join(d, name)
        if not os.path.lexists(p):
            f.append("%s was removed" % name)
        elif node_id(p) != ident:
            f.append("%s was replaced (now %s)" % (name, stat.filemode(os.lstat(p).st_mode)))
    for role, name, fd in getattr(case, "fds", []):
        if role == "reader":
            try:
                data = os.read(fd, 65536)
            except BlockingIOError:
                data = b""
            if data:
                f.append("%d bytes were written into the FIFO %s" % (len(data), name))
    return f


def cases_nonregular(env):
    cases = []
    inputs = env["flag_inputs"]
    rx_flag = lambda flag, name: flag_re(flag) + "|" + re.escape(name)  # noqa: E731

    def add(argv, nodes, regex, why, reader=None, writer=None, extra=None, label=""):
        ins = dict(inputs)
        ins.update(extra or {})
        c = Case("nonregular", argv, "2", regex, inputs=ins, why=why, timeout=10, wall=10,
                 setup=nonregular_setup(nodes, reader, writer), check=nonregular_check)
        c.display = "pound %s   (%s)" % (" ".join(short_arg(a) for a in argv), label)
        cases.append(c)
    # inputs: refused at once (a FIFO's open or read would wait for ever)
    for argv, name, flag in [
            (["simulate", "--record", "fifo.AT2", "-o", "out.csv"], "fifo.AT2", "--record"),
            (["record", "fifo.AT2"], "fifo.AT2", "--record"),
            (["spectrum", "--Pi2", "0.5:1:2", "--record", "fifo.AT2", "-o", "out.h5"], "fifo.AT2",
             "--record"),
            (["simulate", "--scene", "fifo.json", "-o", "out.csv"], "fifo.json", "--scene"),
            (["spectrum", "--scene", "fifo.json", "--Pi2", "0.5:1:2", "-o", "out.h5"], "fifo.json",
             "--scene"),
            (["compare", "--scene", "fifo.json"], "fifo.json", "--scene"),
            (["lcp", "fifo.lcp", "--json"], "fifo.lcp", "lcp")]:
        add(argv, {name: "fifo"}, rx_flag(flag, name), "%s or %s" % (flag, name),
            label="%s is a FIFO" % name)
        if argv[0] in ("simulate", "lcp"):
            add(argv, {name: "fifo"}, rx_flag(flag, name), "%s or %s" % (flag, name), writer=name,
                label="%s is a FIFO held open by a writer" % name)
    for argv in (["simulate", "--scene", "rec.json", "-o", "out.h5"],
                 ["spectrum", "--scene", "rec.json", "--Pi2", "0.5:1:2", "-o", "out.csv"]):
        add(argv, {"fifo.AT2": "fifo"}, r"fifo\.AT2|excitation\.record", "the record file",
            extra={"rec.json": scene_doc(record="fifo.AT2")}, label="its record fifo.AT2 is a FIFO")
    add(["simulate", "--scene", "rec.json", "-o", "out.h5"], {"fifo.AT2": "fifo"},
        r"fifo\.AT2|excitation\.record", "the record file", writer="fifo.AT2",
        extra={"rec.json": scene_doc(record="fifo.AT2")},
        label="its record fifo.AT2 is a FIFO held open by a writer")
    add(SWEEP + ["-o", "out.h5", "--resume"], {"out.h5.partial": "fifo"},
        r"--resume|-o|out\.h5\.partial", "--resume or the journal", label="the journal is a FIFO")
    # outputs: an existing FIFO, device or folder is refused and left as it was
    for argv, name, flag in [
            (["simulate", "-o", "fifo.csv"], "fifo.csv", "-o"),
            (["simulate", "-o", "fifo.h5"], "fifo.h5", "-o"),
            (["simulate", "--chain", "3", "--tend", "0.5", "--dump-lcp", "fifo.h5"], "fifo.h5",
             "--dump-lcp"),
            (["simulate", "--plot", "fifo.png"], "fifo.png", "--plot"),
            (["spectrum", "--Pi2", "0.5:1:4", "-o", "fifo.h5"], "fifo.h5", "-o"),
            (["converge", "--dt", "1e-2:1e-3:2", "-o", "fifo.csv"], "fifo.csv", "-o")]:
        add(argv, {name: "fifo"}, rx_flag(flag, name), "%s or %s" % (flag, name), reader=name,
            label="%s is a FIFO with a reader" % name)
    add(["simulate", "-o", "fifo.csv"], {"fifo.csv": "fifo"}, rx_flag("-o", "fifo.csv"),
        "-o or fifo.csv", label="fifo.csv is a FIFO without a reader")
    add(["simulate", "-o", "link.csv"], {"fifo.csv": "fifo", "link.csv": ("symlink", "fifo.csv")},
        rx_flag("-o", "link.csv") + r"|fifo\.csv", "-o or link.csv", reader="fifo.csv",
        label="link.csv is a symbolic link to a FIFO")
    for argv, name, flag in [(["simulate", "-o", "null.csv"], "null.csv", "-o"),
                             (["simulate", "-o", "null.h5"], "null.h5", "-o"),
                             (["simulate", "--plot", "null.png"], "null.png", "--plot")]:
        add(argv, {name: "chardev"}, rx_flag(flag, name), "%s or %s" % (flag, name),
            label="%s is a character device (1,3: what /dev/null is)" % name)
    for argv, name, flag in [(["simulate", "-o", "dir.csv"], "dir.csv", "-o"),
                             (["simulate", "-o", "dir.h5"], "dir.h5", "-o"),
                             (["simulate", "--chain", "3", "--dump-lcp", "dir.h5"], "dir.h5",
                              "--dump-lcp"),
                             (["simulate", "--plot", "dir.png"], "dir.png", "--plot"),
                             (["spectrum", "--Pi2", "0.5:1:4", "-o", "dir.h5"], "dir.h5", "-o")]:
        add(argv, {name: "dir"}, rx_flag(flag, name), "%s or %s" % (flag, name),
            label="%s is an empty folder" % name)
    return cases


# ---- category: structure names --------------------------------------------------------


# names the writers cannot carry (a CSV column NAME.x1, an HDF5 group
# /structures/NAME): refused at load, structures[0].name named
BAD_NAMES = [("comma", "a,b"), ("dot", "."), ("empty", ""), ("double-quote", 'a"b'),
             ("newline", "a\nb"), ("control", "a\x01b"), ("tab", "a\tb"), ("DEL", "a\x7fb"),
             ("slash", "a/b"), ("300-chars", "y" * 300), ("wall", "wall")]
# names that must work, and be written as given
GOOD_NAMES = [("space", "Building A"), ("utf8", "\u00e9t\u00e9"), ("63-chars", "y" * 63),
              ("digits", "2"), ("dimension-t", "t"), ("dimension-storey", "storey"),
              ("dataset-x", "x")]


def cases_names(env):
    cases = []
    rx = r"n\.json:\d+:\d+: structures\[0\]\.name: "
    for label, name in BAD_NAMES:
        for argv in (["simulate", "--scene", "n.json", "--json", "-o", "out.csv"],
                     ["simulate", "--scene", "n.json", "--json", "-o", "out.h5"],
                     ["spectrum", "--scene", "n.json", "--Pi2", "0.5:1:2", "-o", "out.csv"]):
            if argv[0] == "spectrum" and label not in ("comma", "dot", "double-quote"):
                continue
            c = Case("names", argv, "2", rx, inputs={"n.json": scene_doc(name)},
                     why="n.json:LINE:COL and structures[0].name", check=check_output)
            c.display = "pound %s   (structures[0].name = %s)" % (" ".join(argv), short_arg(
                json.dumps(name)))
            cases.append(c)
    # a second structure, in a row: the same for structures[1]
    for label, name in BAD_NAMES[:4]:
        doc = scene_doc(structures=[{"name": "B", "T0": 0.8}, {"name": name, "T0": 0.5}],
                        contacts=[{"a": "B", "b": name, "gap": 0.01, "eps": 0.5}])
        c = Case("names", ["simulate", "--scene", "n.json", "-o", "out.h5"], "2",
                 r"n\.json:\d+:\d+: structures\[1\]\.name: ", inputs={"n.json": doc},
                 why="n.json:LINE:COL and structures[1].name", check=check_output)
        c.display = "pound simulate --scene n.json -o out.h5   (structures[1].name = %s)" % \
            short_arg(json.dumps(name))
        cases.append(c)
    for label, name in GOOD_NAMES:
        for argv in (["simulate", "--scene", "n.json", "--json", "-o", "out.csv"],
                     ["simulate", "--scene", "n.json", "--json", "-o", "out.h5"]):
            c = Case("names", argv, "0", None, inputs={"n.json": scene_doc(name)},
                     check=check_output)
            c.display = "pound %s   (structures[0].name = %s)" % (" ".join(argv), short_arg(
                json.dumps(name)))
            cases.append(c)
    return cases


# ---- category: resource bounds --------------------------------------------------------


# a 2-storey building whose second mode is about 160 kHz (a 1 ug top storey
# on a 1e6 N/m spring), against a wall at storey 2: Moreau-Jean runs it in
# milliseconds; the event-driven and penalty methods would follow that mode
STIFF = {"name": "A", "masses": [1.0, 1e-6], "stiffnesses": [40.0, 1e6]}


def levels_5e6(fo):
    """Write a scene whose one contact entry lists 5e6 levels (1..100000, 50
    times): about 30 MB of JSON, written in pieces."""
    block = ",".join(str(k) for k in range(1, 100001)).encode()
    doc = scene_doc(structures=[{"name": "A", "storeys": 100000, "mass": 1e5, "T0": 0.9}],
                    contacts=[{"a": "A", "b": "wall", "levels": "@LEVELS@", "gap": 0.01, "eps": 0.5}])
    head, tail = doc.split(b'"@LEVELS@"')
    fo.write(head + b"[")
    for k in range(50):
        fo.write((b"," if k else b"") + block)
    fo.write(b"]" + tail)


def cases_bounds(env):
    cases = []
    inputs = env["flag_inputs"]

    # refused up front: 10 s of CPU and 1.5 GiB of address space are plenty
    # (before issue 19 these ran for minutes, or took 3.8 GB and ran out)
    def add(argv, expect, regex, why, extra=None, rss_mb=512, timeout=10, label=None):
        ins = dict(inputs)
        ins.update(extra or {})
        c = Case("bounds", argv, expect, regex, inputs=ins, why=why, timeout=timeout,
                 rss_mb=rss_mb, check=check_output if out_name(argv) else None,
                 as_limit=3 << 29)
        if label:
            c.display = "pound %s   (%s)" % (" ".join(short_arg(a) for a in argv), label)
        cases.append(c)
    n = 20000
    tall = [{"name": "A", "storeys": n, "mass": 1e5, "T0": 0.9}]
    rx_c = r"b\.json:\d+:\d+: contacts(\[\d+\])?(\.(levels|pairs))?: "
    why_c = "b.json:LINE:COL and the contacts' field"
    for label, doc, rss in [
            ("one contact entry, levels 1..20000", scene_doc(structures=tall, contacts=[
                {"a": "A", "b": "wall", "levels": list(range(1, n + 1)), "gap": 0.01, "eps": 0.5}]), 512),
            ("one contact entry, 5e6 levels", levels_5e6, 1024),
            ("one contact entry, 20000 pairs", scene_doc(
                structures=tall + [{"name": "B", "storeys": n, "mass": 1e5, "T0": 0.7}],
                contacts=[{"a": "A", "b": "B", "pairs": [[k, k] for k in range(1, n + 1)],
                           "gap": 0.01, "eps": 0.5}]), 512),
            ("20000 contact entries of one level", scene_doc(structures=tall, contacts=[
                {"a": "A", "b": "wall", "levels": [k], "gap": 0.01, "eps": 0.5}
                for k in range(1, n + 1)]), 512)]:
        add(["simulate", "--scene", "b.json", "-o", "out.h5"], "2", rx_c, why_c,
            extra={"b.json": doc}, rss_mb=rss, label=label)
    stiff = scene_doc(structures=[STIFF], contacts=[
        {"a": "A", "b": "wall", "levels": [2], "gap": 0.01, "eps": 0.5}])
    # (the budget is the method's, so FILE:LINE:COL is not required: the
    # structure and the method that runs it are)
    rx_s = r"structures\[0\](\.\w+)?(?![\w\[]).*(?i:moreau)"
    why_s = "structures[0] and Moreau-Jean (the method that runs it)"
    for argv in (["simulate", "--scene", "s2.json", "--method", "event", "-o", "out.csv"],
                 ["simulate", "--scene", "s2.json", "--method", "penalty", "-o", "out.h5"],
                 ["spectrum", "--scene", "s2.json", "--Pi2", "0.5:1:2", "--method", "event",
                  "-o", "out.h5"],
                 ["spectrum", "--scene", "s2.json", "--Pi2", "0.5:1:2", "--method", "penalty"]):
        add(argv, "2", rx_s, why_s, extra={"s2.json": stiff},
            label="a second mode of 160 kHz")
    # compare's reference is the event-driven method: refused, the field named
    add(["compare", "--scene", "s2.json"], "2", r"structures\[0\]",
        "structures[0]", extra={"s2.json": stiff}, label="a second mode of 160 kHz")
    add(["simulate", "--scene", "s2.json", "-o", "out.csv", "--json"], "0", None, None,
        extra={"s2.json": stiff}, label="a second mode of 160 kHz, Moreau-Jean")
    # a penalty chain whose elements switched at one instant (681 s of CPU before
    # issue 19, then stopped by the stall guard): issue 20 removed the chatter,
    # the row runs to the end within the category's 10 s (1.1 s), outputs whole
    for extra_argv in ([], ["-o", "out.h5"]):
        add(["simulate", "--chain", "30", "--method", "penalty", "--kc", "1e8"] + extra_argv,
            "0", None, None, label="a stiff row, no longer a stall")
    return cases


# ---- category: the flag the user typed -----------------------------------------------------


def cases_derived(env):
    """Derived quantities (T0 = Tp / Pi2, the step count over tend = Tp + 2 T0,
    gap / Le) overflow or leave their range: the message names the flag that
    made them do so, first ("pound: --Tp: ..."), not one whose derived value
    is out of range."""
    cases = []
    base = {"--pulse": "sine", "--ap": "4", "--Tp": "0.5", "--T0": "0.5", "--gap": "0.004"}
    for cmd in ("simulate", "compare"):
        for flag, values in [("--Tp", ["1e308", "1e30", "1e-30"]), ("--T0", ["1e308", "1e30", "1e-30"]),
                             ("--gap", ["1e308"])]:
            for v in values:
                args = dict(base)
                args[flag] = v
                argv = [cmd] + [x for kv in args.items() for x in kv]
                cases.append(Case("derived", argv, "2", r"^pound: %s:" % re.escape(flag),
                                  why=flag + " first", timeout=20))
    return cases


# ---- category: the fourth round's hostile inputs ----------------------------------------


def row_doc(n, gap, eps=0.7, storeys=1, walls=True, masses=None, tend=3.0):
    """n structures in a row (SDOFs, or buildings of `storeys` touching at
    every floor), every gap `gap`, between two walls when `walls`."""
    st = [{"name": "S%d" % i, "T0": 1.0, "xi": 0.05, "mass": (masses[i] if masses else 1e5)}
          if storeys == 1 else {"name": "S%d" % i, "storeys": storeys, "T0": 0.5 + 0.05 * i,
                                "xi": 0.05, "mass": 1e5} for i in range(n)]
    lv = {} if storeys == 1 else {"levels": list(range(1, storeys + 1))}
    ct = [dict({"a": "S%d" % i, "b": "S%d" % (i + 1), "gap": gap, "eps": eps}, **lv)
          for i in range(n - 1)]
    if walls:
        ct = [{"a": "wall", "b": "S0", "gap": gap, "eps": eps}] + ct + \
             [{"a": "S%d" % (n - 1), "b": "wall", "gap": gap, "eps": eps}]
    return json.dumps({"excitation": {"pulse": "sine", "dir": "+x", "ap": 3.0, "Tp": 1.0},
                       "structures": st, "contacts": ct, "tend": tend}).encode("utf-8")


def cases_hostile(env):
    cases = []
    # gaps within the closing tolerance are closed: seconds, not the event budget
    for gap in ("1e-300", "5e-324", "1e-12", "0"):
        doc = row_doc(10, 0.0).replace(b'"gap": 0.0', b'"gap": ' + gap.encode())
        cases.append(Case("hostile", ["simulate", "--scene", "r.json", "--method", "event",
                                      "--json"], "0", None, inputs={"r.json": doc}, timeout=20,
                          display="pound simulate --scene r.json --method event   (10 SDOFs "
                          "between walls, gaps %s)" % gap))
    cases.append(Case("hostile", ["simulate", "--scene", "b.json", "--method", "event", "--json"],
                      "0", None, inputs={"b.json": row_doc(10, 0.0, eps=0.5, storeys=5,
                                                           walls=False)}, timeout=60,
                      display="pound simulate --scene b.json --method event   (ten 5-storey "
                      "buildings touching at every floor)"))
    # masses beyond double precision: refused for the references, moreau named
    doc = row_doc(2, 1e-300, eps=1.0, masses=[1e-6, 1e12])
    for m in ("event", "event-general"):
        cases.append(Case("hostile", ["simulate", "--scene", "m.json", "--method", m], "2",
                          r"mass: .*moreau", inputs={"m.json": doc}, timeout=20))
    # derived demands that overflow, newmark's budgets, another method's flags
    heights = json.loads(scene_doc("A"))
    heights["structures"][0]["storey_heights"] = 5e-324
    for argv, ins, rx in [
            (["simulate", "--scene", "n.json", "--contact-duration", "1e-307", "-o", "o.h5"],
             {"n.json": row_doc(2, 0.02)}, r"contact-duration"),
            (["simulate", "--scene", "n.json", "-o", "o.csv"],
             {"n.json": json.dumps(heights).encode()}, r"storey_heights"),
            (["simulate", "--method", "newmark", "--kc", "1e300"], None, r"kc:"),
            (["simulate", "--method", "newmark", "--dt", "1e-8"], None, r"dt:"),
            (["simulate", "--chain", "3", "--method", "newmark", "--kc", "1e300"], None, r"kc:"),
            (["simulate", "--method", "moreau", "--close-tol", "1e-9"], None, r"--close-tol"),
            (["simulate", "--method", "newmark", "--theta", "0.6"], None, r"--theta"),
            (["simulate", "--method", "event", "--kc", "10"], None, r"--kc"),
            (["bench", "--lcp", "--shared", "/nonexistent"], None, r"--shared")]:
        cases.append(Case("hostile", argv, "2", rx, inputs=ins, timeout=20, check=check_output))
    cases.append(Case("hostile", ["simulate", "--json"], "2", r"POUND_ISA",
                      env={"POUND_ISA": "avx3"}, timeout=20))
    # 1000 bodies to HDF5 under address-space limits: written whole, or out of
    # memory with nothing left (never a signal, never a corrupted heap)
    cradle = row_doc(1000, 0.0, eps=0.9, walls=False, tend=2.0)
    for limit in (300 << 20, 150 << 20, 50 << 20):
        cases.append(Case("hostile", ["simulate", "--scene", "c.json", "--every", "10", "-o",
                                      "o.h5"], "01", None,
                          inputs={"c.json": cradle}, timeout=60, as_limit=limit,
                          rc1_regex=r"memory", check=check_output,
                          display="pound simulate --scene c.json --every 10 -o o.h5   (1000 bodies, "
                          "address space %d MB)" % (limit >> 20)))
    return cases


# ---- category 8: libFuzzer ------------------------------------------------------------


def run_fuzz(runner, env, fuzz_time):
    fdir = os.path.join(env["stress"], "fuzz")
    skip = os.path.join(env["stress"], "fuzz.skip")
    targets = ["fuzz_lcp", "fuzz_scene", "fuzz_record", "fuzz_journal", "fuzz_suite"]
    if os.path.exists(skip) or not all(os.path.exists(os.path.join(fdir, t)) for t in targets):
        msg = open(skip).read().strip() if os.path.exists(skip) else "fuzz: skip (harnesses not built)"
        return None, msg
    seeds = {
        "fuzz_lcp": [os.path.join(HERE, "corpus", "lcp")] + [os.path.join(SHARED, "data", "lcp", "siconos")],
        "fuzz_scene": [os.path.join(ROOT, "examples", "scenes"), os.path.join(HERE, "corpus", "scene")],
        "fuzz_record": [os.path.join(HERE, "corpus", "record"), os.path.join(SHARED, "data", "records")],
        "fuzz_journal": [],
        "fuzz_suite": [],
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
        if t == "fuzz_suite":  # two real interrupted suites' journals: a scene's, an oscillator's
            for flags in (["--scene", os.path.join(ROOT, "examples", "scenes", "two-sdof.json")],
                          ["--T0", "0.8", "--gap", "0.01", "--eps", "0.6"]):
                jpath = os.path.join(seed_dir, "s%04d" % k)
                subprocess.run([runner.pound, "simulate", "--records",
                                os.path.join(ROOT, "examples", "records", "suite", "suite.txt"),
                                *flags, "--journal", jpath, "--stop-after", "3"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
                if not os.path.exists(jpath):
                    continue
                k += 1
                with open(jpath, "rb") as f:  # and each record's line, its checksum cut
                    for line in f.read().split(b"\n"):
                        if line.startswith(b"R "):
                            with open(os.path.join(seed_dir, "s%04d" % k), "wb") as g:
                                g.write(line.rsplit(b" #", 1)[0])
                            k += 1
        if t == "fuzz_journal" and "journal" in env:
            for m in mutate.journal_mutants(env["journal"], env["other_key"]):
                if len(m.data) <= 16384:
                    with open(os.path.join(seed_dir, "s%04d" % k), "wb") as f:
                        f.write(m.data)
                    k += 1
        # a fixed seed: a CI run repeats the local one as far as time allows
        cmd = [os.path.join(fdir, t), "-seed=1", "-max_total_time=%d" % fuzz_time, "-timeout=60",
               "-rss_limit_mb=2048", "-max_len=16384", "-print_final_stats=1",
               "-artifact_prefix=" + art + "/", work, seed_dir]
        envv = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0",
                    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1", TMPDIR=runner.scratch,
                    POUND_FUZZ_SCENE=os.path.join(ROOT, "examples", "scenes", "two-sdof.json"))
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


PHYSICS_SEEDS = (1, 2, 3, 4, 5, 6)
PHYSICS_ROWS = 200


def run_physics(runner, env):
    """tests/test_rows.c's impact observer over PHYSICS_ROWS generated hostile
    rows per seed (the build's pound_tests, two seeds at a time): one input
    per row, a failure per seed whose run failed, with its messages."""
    tests = os.path.join(os.path.dirname(os.path.abspath(env["pound_built"])), "pound_tests")
    if not os.path.exists(tests):
        return [("physics", 0, ["%s missing (make all)" % tests])], []

    def one(seed):
        penv = dict(os.environ, POUND_STRESS_ROWS=str(PHYSICS_ROWS), POUND_STRESS_SEED=str(seed))
        p = subprocess.run([tests, "test_rows_hostile_physics"], cwd=runner.scratch, env=penv,
                           stdin=subprocess.DEVNULL, capture_output=True, timeout=600)
        out = p.stdout.decode("utf-8", "replace")
        if p.returncode == 0 and "1 passed, 0 failed" in out:
            return None
        msgs = [l.strip() for l in out.splitlines() if "test_rows.c:" in l]
        return "seed %d: exit %d: %s" % (seed, p.returncode, "; ".join(msgs[:5]) or out[-400:])

    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        fails = [f for f in pool.map(one, PHYSICS_SEEDS) if f]
    return [("physics", PHYSICS_ROWS * len(PHYSICS_SEEDS), fails)], []


def run_capi(runner, env):
    """The C API misuse binary (scripts/stress.sh builds it): one result per
    case it runs, a failure per FAIL line or for a sanitizer's abort."""
    capi = os.path.join(env["stress"], "capi", "capi")
    skip = os.path.join(env["stress"], "capi.skip")
    if os.path.exists(skip) or not os.path.exists(capi):
        return [], [open(skip).read().strip() if os.path.exists(skip) else "capi: skip (not built)"]
    p = subprocess.run([capi], cwd=ROOT, stdin=subprocess.DEVNULL, capture_output=True,
                       timeout=600)
    out = p.stdout.decode("utf-8", "replace")
    m = re.search(r"capi: (\d+) cases passed, (\d+) failed", out)
    fails = [l[5:] for l in out.splitlines() if l.startswith("FAIL ")]
    if not m:
        err = p.stderr.decode("utf-8", "replace")
        fails.append("capi exited %d without its summary: %s" % (p.returncode, err[-600:]))
    calls = re.search(r"capi: (\d+) NULL calls", out)
    return [("capi", int(calls.group(1)) + 4 if calls else 0, fails)], []


def run_python(runner, env):
    """python/tests/test_misuse.py and test_harden4.py (to_pandas, plot indices,
    record= dtypes) against this build's libpound.so, from python/."""
    lib = os.path.join(os.path.dirname(os.path.abspath(env["pound_built"])), "libpound.so")
    # Debian's Python, with NumPy and pytest (as python/check.sh), not a
    # python3 that PATH may find first
    py = os.environ.get("PYTHON") or ("/usr/bin/python3" if os.path.exists("/usr/bin/python3")
                                      else sys.executable)
    probe = subprocess.run([py, "-c", "import numpy, pytest"], capture_output=True)
    if probe.returncode != 0:
        return [], ["python: skip (%s: %s)" % (py, probe.stderr.decode("utf-8", "replace")
                                                .strip().splitlines()[-1:])]
    if not os.path.exists(lib):
        return [("python", 0, ["%s missing (make shared)" % lib])], []
    penv = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"), POUND_LIBRARY=lib,
                POUND_BIN=env["pound_built"], MPLBACKEND="Agg")
    p = subprocess.run([py, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        os.path.join(ROOT, "python", "tests", "test_misuse.py"),
                        os.path.join(ROOT, "python", "tests", "test_harden4.py")],
                       cwd=runner.scratch, env=penv, stdin=subprocess.DEVNULL,
                       capture_output=True, timeout=600)
    out = p.stdout.decode("utf-8", "replace")
    m = re.search(r"(\d+) passed", out)
    passed = int(m.group(1)) if m else 0
    fails = ["%s" % l for l in out.splitlines() if l.startswith("FAILED") or l.startswith("ERROR")]
    if p.returncode != 0 and not fails:
        fails.append("pytest exited %d: %s" % (p.returncode, out[-600:]))
    nfail = re.search(r"(\d+) failed", out)
    return [("python", passed + (int(nfail.group(1)) if nfail else 0), fails)], []


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


def signals_delivered():
    """The fault cases send SIGINT, SIGTERM, SIGHUP and SIGQUIT: a suite
    started in the background (`cmd &` without job control, nohup) would
    pass them on ignored, and pound rightly keeps an ignored signal
    ignored.  The runner's children get them as a terminal's would."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT):
        if signal.getsignal(s) == signal.SIG_IGN:
            signal.signal(s, signal.SIG_DFL)


def main():
    signals_delivered()
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pound", default=os.path.join(ROOT, "build", "pound"))
    ap.add_argument("--stress", default=os.path.join(ROOT, "build", "stress"),
                    help="where `make stress` built the fuzzers and the TSan binary")
    ap.add_argument("--report", default=None, help="rewrite the stress table of this file")
    ap.add_argument("--only", default=None, help="comma-separated categories")
    ap.add_argument("--jobs", type=int, default=max(2, (os.cpu_count() or 2) + 1))
    ap.add_argument("--timeout", type=float, default=30.0, help="CPU seconds per case")
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
    env = {"skips": [], "stress": os.path.abspath(args.stress), "pound_built": args.pound}
    make_inputs(runner, env)
    if "journal" in cats or "fuzz" in cats:
        msg = prep_journal(runner, env)
        if msg:
            env["journal_error"] = msg  # a failure of the journal category (cases_journal)
    gens = {"corpus": cases_corpus, "flags": cases_flags, "lcp": cases_lcp, "scene": cases_scene,
            "record": cases_record, "journal": cases_journal, "faults": cases_faults,
            "hangs": cases_hangs, "nonregular": cases_nonregular, "names": cases_names,
            "bounds": cases_bounds, "derived": cases_derived, "hostile": cases_hostile}
    all_cases = []
    for c in cats:
        if c in gens:
            all_cases += gens[c](env)
    # the long ones first, so that they overlap the many short ones
    all_cases.sort(key=lambda c: 0 if c.cat in ("hangs", "faults", "journal", "bounds") or
                   getattr(c, "heavy", False) else 1)
    per_cat = {c: [0, []] for c in cats}
    done = [0]

    def progress(fut_result):
        done[0] += 1
    cpu = []
    with ThreadPoolExecutor(max_workers=args.jobs) as ex:
        for case, res, fails in ex.map(lambda c: run_case(runner, c), all_cases):
            per_cat[case.cat][0] += 1
            if res is not None:
                cpu.append((res.cpu, res.secs, case.cat, case.command()))
            if fails:
                per_cat[case.cat][1].append((case, res, fails))
    if "corpus" in cats:
        per_cat["corpus"][0] = env.get("corpus_files", 0)
    env["skips"] += SKIPS
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
    for c, fn in (("physics", run_physics), ("capi", run_capi), ("python", run_python)):
        if c in cats:
            results, skips = fn(runner, env)
            if skips and os.environ.get("POUND_STRESS_STRICT"):  # .ci/run: nothing skipped
                results = [(c, 0, ["skipped under POUND_STRESS_STRICT: " + "; ".join(skips)])]
                skips = []
            env["skips"] += skips
            for _, n, fs in results:
                per_cat[c][0] = n
                for f in fs:
                    per_cat[c][1].append((Case(c, [], "0", display=c), None, [f]))
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
    if cpu and os.environ.get("STRESS_PROFILE"):
        cpu.sort(reverse=True)
        print("CPU: %.0f s in %d runs (%.0f s of wall), the suite's own peak RSS %.0f MB; "
              "the longest:" % (sum(c for c, _, _, _ in cpu), len(cpu), sum(w for _, w, _, _ in cpu),
                                suite_rss_mb()))
        for c, w, cat, cmd in cpu[:8]:
            print("  %6.1f s CPU %6.1f s wall  [%s] %s" % (c, w, cat, cmd[:100]))
        cpu.sort(key=lambda x: -x[1])
        print("the longest in wall time:")
        for c, w, cat, cmd in cpu[:8]:
            print("  %6.1f s CPU %6.1f s wall  [%s] %s" % (c, w, cat, cmd[:100]))
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
