"""What a newcomer sees on the command line: a progress line on a terminal
for a run past two seconds (and nothing when stderr is not a terminal), and
`pound bench` saying what it skipped when the shared data are not there."""
import re
import shutil
import subprocess

import pytest

from conftest import pound_bin

LONG = "simulate --chain 1000 --pulse harmonic --json"  # about 3 s on this machine class


def test_progress_line_on_a_terminal(tmp_path):
    if not shutil.which("script"):
        pytest.skip("no script(1) to give the run a terminal")
    log = tmp_path / "tty.txt"
    cmd = "%s %s > %s" % (pound_bin(), LONG, tmp_path / "out.json")
    subprocess.run(["script", "-qc", cmd, str(log)], check=True, stdout=subprocess.DEVNULL)
    lines = log.read_text(errors="replace").replace("\r", "\n").splitlines()
    shown = [ln for ln in lines if re.match(r"pound: simulate: +\d+ % of a run", ln)]
    assert shown, lines[:5]
    # the run's percentage, then its contact-free twin's
    percents = [int(re.search(r"(\d+) %", ln).group(1)) for ln in shown]
    assert len(percents) >= 2 and all(0 <= p <= 100 for p in percents)
    assert (tmp_path / "out.json").read_text().startswith("{")  # stdout kept clean


def test_no_progress_line_off_a_terminal():
    out = subprocess.run([str(pound_bin())] + LONG.split(), stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, check=True)
    assert out.stderr == b""


def test_bench_says_what_it_skipped(tmp_path):
    """`pound bench --records --shared DIR` (make bench SHARED=DIR) without
    the records says so, naming the folder it looked in."""
    out = subprocess.run([str(pound_bin()), "bench", "--records", "--shared", str(tmp_path)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=True)
    assert ("Record study: skipped (no records in %s/data/records)" % tmp_path) in \
        out.stdout.decode()
    missing = subprocess.run([str(pound_bin()), "bench", "--records", "--shared",
                              str(tmp_path / "none")], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, check=False)
    assert missing.returncode == 2 and b"--shared" in missing.stderr
