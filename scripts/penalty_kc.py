#!/usr/bin/env python3
"""penalty_kc.py — the penalty elements' error against kc on a row (docs/methods.md).

Usage: scripts/penalty_kc.py [path/to/pound] [N]   (from the project root; N = 10)

Runs `pound simulate --chain N` (sine pulse Tp = 1 s, T0 = 1 s, Pi3 = 0.05,
e = 0.6, tend 4 s: the rows of the work-precision charts) with the exact row
reference (--method event) and, for kc = 1e6 ... 1e10 times the largest
storey stiffness, both penalty methods: the adaptive GSL integration
(--method penalty, rk8pd, rtol 1e-10) and Newmark's fixed steps (--method
newmark, 10 steps per element period).  Prints per row: kc, the relative
error of the peak displacement of the worst structure, accepted steps and
the run's CPU seconds, and the relative error of each contact's sampled
impulses summed over the run (the force integral plus the impacts:
docs/formats.md, "The sampled impulse"), the worst contact.  (Impulses per
impact are not compared: an element engaged while the row rests compressed
integrates its force over the whole resting phase where the reference
counts impacts.)
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

POUND = sys.argv[1] if len(sys.argv) > 1 else "build/pound"
N = sys.argv[2] if len(sys.argv) > 2 else "10"
ROW = ["--chain", N, "--pulse", "sine", "--Tp", "1", "--T0", "1", "--Pi3", "0.05",
       "--eps", "0.6", "--tend", "4"]


def run(extra):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "run.csv")
        out = subprocess.run([POUND, "simulate", *ROW, *extra, "--json", "-o", path], check=True,
                             capture_output=True, text=True).stdout
        with open(path) as f:
            rows = list(csv.reader(line for line in f if not line.startswith("#")))
    d = json.loads(out)
    cols = [i for i, h in enumerate(rows[0]) if h.endswith(".impulse")]
    imp = [sum(float(r[i]) for r in rows[1:]) for i in cols]
    return [s["umax"][0] for s in d["structures"]], d["steps"], d["cpu_s_run"], imp


def main():
    ru, _, rcpu, rimp = run(["--method", "event"])
    print(f"chain {N}: exact row reference (--method event) in {rcpu:.3g} s; summed "
          f"impulses per contact {min(rimp):.3g} ... {max(rimp):.3g} N s")
    print(f"{'method':8} {'kc':>7} {'err_umax':>10} {'err_imp':>10} {'steps':>9} {'cpu [s]':>8}")
    for kc in ["1e6", "1e7", "1e8", "1e9", "1e10"]:
        for method in ["penalty", "newmark"]:
            u, steps, cpu, imp = run(["--method", method, "--kc", kc])
            eu = max(abs(a / b - 1.0) for a, b in zip(u, ru))
            ei = max(abs(a / b - 1.0) for a, b in zip(imp, rimp) if b > 0.0)
            print(f"{method:8} {kc:>7} {eu:10.3g} {ei:10.3g} {steps:9d} {cpu:8.3g}")


if __name__ == "__main__":
    main()
