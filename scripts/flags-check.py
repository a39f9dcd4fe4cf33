#!/usr/bin/python3
"""flags-check.py: every command's flags, as `pound CMD --help` lists them,
checked against the man page, the bash completion and the parser.

    python3 scripts/flags-check.py build/pound

The help text is the table: for every command (simulate, compare,
converge, spectrum, record, lcp, bench) the flags are the words `--name`
and `-o` of `pound CMD --help` (text between backquotes is an example of
another command and is left out).  The lines from "model flags (defaults in
brackets):" on are the flags every case-driven command shares
(cli/case.c, pd_cli_case_help); the lines before are the command's own.
It asserts:

1. the man page (docs/pound.1) names each of the command's own flags in the
   command's entry of COMMANDS, or, for a case-driven command, in MODEL
   FLAGS or SCHEME FLAGS; each shared flag in MODEL FLAGS or SCHEME FLAGS;
2. the bash completion (scripts/pound.bash-completion, its _pound_flags CMD)
   offers each flag;
3. the parser takes each: `pound CMD FLAG [VALUE] --zz-sentinel` stops at
   the sentinel ("unknown flag '--zz-sentinel'"), so FLAG (and a plausible
   VALUE: the first of a|b|c, a number, a range, a file) was read;
   and where the help names a flag's values (--kernel auto|general), the
   completion offers those values, the man page names the same (where it
   names any) and the parser takes each;
4. the reverse: the flags a command's man entry or completion names that
   its --help does not list (and those of MODEL/SCHEME FLAGS that no
   case-driven command's help lists).

--help, which every command takes, is checked as if each help listed it.
`pound --help` is checked too: its commands are the completion's and the
man page's COMMANDS, its flags (--version, --help) completed first and in
the SYNOPSIS.

It exits 1 with one line per discrepancy, and prints one summary line.
Standard library only (and bash for the completion).
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAN = os.path.join(ROOT, "docs", "pound.1")
COMPLETION = os.path.join(ROOT, "scripts", "pound.bash-completion")
COMMANDS = ["simulate", "compare", "converge", "spectrum", "record", "lcp", "bench"]
CASE_MARK = "model flags (defaults in brackets):"
SENTINEL = "--zz-sentinel"
FLAG_RX = re.compile(r"(?<![\w-])(--[A-Za-z0-9][A-Za-z0-9-]*|-o)(?![\w-])")

failures = []
checks = 0


def check(ok, msg):
    global checks
    checks += 1
    if not ok:
        failures.append(msg)
    return ok


def flags_of_text(text):
    """The flags a help text names, in order, once each (not in `...`)."""
    text = re.sub(r"`[^`\n]*`", "", text)
    seen = []
    for m in FLAG_RX.finditer(text):
        f = m.group(1).rstrip("-")
        if f not in seen:
            seen.append(f)
    return seen


def help_of(pound, cmd):
    """(own flags, shared flags, {flag: the words after it in the help})."""
    p = subprocess.run([pound, cmd, "--help"], capture_output=True, text=True, timeout=30)
    check(p.returncode == 0, f"pound {cmd} --help: exit {p.returncode}")
    text = p.stdout
    own, _, shared = text.partition(CASE_MARK)
    follow = {}  # every word that follows the flag somewhere in the help
    plain = re.sub(r"`[^`\n]*`", "", text)
    for m in FLAG_RX.finditer(plain):
        words = plain[m.end():m.end() + 40].split("\n")[0].split()
        if words:
            follow.setdefault(m.group(1), []).append(words[0])
    choices = {}  # --flag a|b|c: the values it names
    for m in re.finditer(r"(?<![\w-])(--[A-Za-z0-9][\w-]*) ([a-z0-9/]+(?:\|[a-z0-9/-]+)+)(?![\w.])", plain):
        choices.setdefault(m.group(1), set()).update(m.group(2).split("|"))
    return flags_of_text(own), flags_of_text(shared), follow, choices


# ---- the man page ------------------------------------------------------------------

def roff_flags(text):
    """The flags a piece of roff names (\\-\\-name, \\-o)."""
    found = []
    for m in re.finditer(r"\\-\\-((?:[A-Za-z0-9]|\\-)+)", text):
        f = "--" + m.group(1).replace("\\-", "-").rstrip("-")
        if f not in found:
            found.append(f)
    if re.search(r"(?<![\w\\-])\\-o(?![\w\\])", text.replace("\\-\\-", "  ")):
        found.append("-o")
    return found


def roff_choices(text):
    """{flag: values} of the roff's "\\-\\-flag a|b|c"."""
    out = {}
    rx = r"\\-\\-((?:[A-Za-z0-9]|\\-)+)\s+((?:[a-z0-9/]|\\-)+(?:\|(?:[a-z0-9/]|\\-)+)+)"
    for m in re.finditer(rx, text):
        vals = m.group(2).replace("\\-", "-").split("|")
        out.setdefault("--" + m.group(1).replace("\\-", "-"), set()).update(vals)
    return out


def man_sections():
    """{command: roff of its COMMANDS entry}, and the roff of MODEL FLAGS
    and SCHEME FLAGS together."""
    lines = open(MAN, encoding="utf-8").read().splitlines()
    section, entries, shared, cmd, depth, prev = None, {}, [], None, 0, ""
    for line in lines:
        if line.startswith(".SH "):
            section, cmd = line[4:].strip().strip('"'), None
            continue
        if section == "COMMANDS":
            if line.startswith(".RS"):
                depth += 1
            elif line.startswith(".RE"):
                depth -= 1
            m = re.match(r"\.BI? (\w+)", line)
            if prev == ".TP" and depth == 0 and m and m.group(1) in COMMANDS + ["help"]:
                cmd = m.group(1)
                entries[cmd] = []
            elif cmd:
                entries[cmd].append(line)
        elif section in ("MODEL FLAGS", "SCHEME FLAGS"):
            shared.append(line)
        prev = line.strip()
    return {c: "\n".join(v) for c, v in entries.items()}, "\n".join(shared)


# ---- the completion ------------------------------------------------------------------

def completion_flags(cmd):
    script = f'source "{COMPLETION}"; _pound_flags {cmd}'
    p = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=30)
    check(p.returncode == 0, f"completion: _pound_flags {cmd}: exit {p.returncode} {p.stderr.strip()}")
    return p.stdout.split()


# ---- the parser ------------------------------------------------------------------------

def completion_values(cmd, flag):
    """The words the completion offers after cmd's flag (not its file markers)."""
    script = f'source "{COMPLETION}"; _pound_values {flag} {cmd}'
    p = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=30)
    return [w for w in p.stdout.split() if not w.startswith("_")], bool(p.stdout.strip())


def values_for(cmd, flag, follow):
    """Plausible values for a flag: the completion's words for it, then a
    number, ranges, files; [] when it takes none (in the help, the word
    after it is text, not a placeholder H, LIST, F.json or a choice a|b)."""
    words = [w.strip("[](),") for w in follow.get(flag, [])]
    words = [w for w in words if w and w != "|"]
    choices = [w.split("|")[0] for w in words if "|" in w and re.match(r"^[a-z0-9]", w)]
    offered, some = completion_values(cmd, flag)
    if not choices and not some and not any(re.match(r"^[A-Z]", w) for w in words):
        return []
    return offered[:1] + choices + ["1", "2:1:3", "1:2:3", os.path.join(ROOT, "examples", "scenes", "two-sdof.json"),
                      os.path.join(ROOT, "examples", "records", "NGA_no_1063_RRS228.AT2"),
                      "x.h5", "x.png", tempfile.gettempdir()]


def parser_takes(pound, cmd, flag, follow, cwd):
    """Does `pound cmd flag [value] --zz-sentinel` stop at the sentinel?"""
    if flag == "--help":
        return True, ""
    last = ""
    values = values_for(cmd, flag, follow)
    for args in [[flag, v] for v in values] if values else [[flag]]:
        try:
            p = subprocess.run([pound, cmd] + args + [SENTINEL], capture_output=True, text=True,
                               timeout=20, cwd=cwd)
        except subprocess.TimeoutExpired:  # it ran: the sentinel was taken for a value
            last = f"pound {cmd} {' '.join(args)} {SENTINEL} ran for 20 s"
            continue
        last = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"
        if f"unknown flag '{SENTINEL}'" in p.stderr:
            return True, ""
        if f"unknown flag '{flag}'" in p.stderr:
            return False, last
    # no value got past the flag; taken all the same if it refused the value
    # in its own name ("pound: --T0: spectrum sweeps Pi2 ...")
    return last.startswith(f"pound: {flag}:"), last


def top_level(pound, entries):
    """`pound --help`: its commands against the completion's and the man
    page's, its flags (with --help) offered first and in the SYNOPSIS."""
    p = subprocess.run([pound, "--help"], capture_output=True, text=True, timeout=30)
    check(p.returncode == 0, f"pound --help: exit {p.returncode}")
    listed, _, rest = p.stdout.partition("commands:")
    cmds = re.findall(r"^  ([a-z]+) ", rest, re.M)
    flags = re.findall(r"^  (--[\w-]+)", rest, re.M) + ["--help"]  # its own lines, not a command's
    script = f'source "{COMPLETION}"; echo "$_pound_commands"'
    comp = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=30).stdout.split()
    check(sorted(cmds) == sorted(comp), f"completion: commands {comp}, pound --help lists {cmds}")
    check(sorted(cmds) == sorted(entries), f"pound.1: COMMANDS has {sorted(entries)}, pound --help lists {cmds}")
    check(sorted(set(cmds) - {"help"}) == sorted(COMMANDS), f"flags-check knows {COMMANDS}, pound --help lists {cmds}")
    src = open(COMPLETION, encoding="utf-8").read()
    first = re.search(r'compgen -W "\$_pound_commands ([^"]*)"', src)
    man = open(MAN, encoding="utf-8").read()
    synopsis = man.partition(".SH SYNOPSIS")[2].partition(".SH ")[0]
    for f in flags:
        check(first is not None and f in first.group(1).split(), f"completion: {f} is not offered as the first word")
        check(f in roff_flags(synopsis), f"pound.1: {f} is not in the SYNOPSIS")
    return len(flags)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: python3 scripts/flags-check.py PATH/TO/pound")
    pound = os.path.abspath(sys.argv[1])
    entries, shared_roff = man_sections()
    man_shared = roff_flags(shared_roff)
    all_shared, all_listed, all_choices = set(), set(), {}
    nflags = 0
    with tempfile.TemporaryDirectory(prefix="pound_flags_") as tmp:
        for cmd in COMMANDS:
            own, shared, follow, choices = help_of(pound, cmd)
            for f, vals in choices.items():
                all_choices.setdefault(f, set()).update(vals)
            takes_case = bool(shared)
            listed = own + [f for f in shared if f not in own]
            if "--help" not in listed:  # every command's, which its help need not list
                listed.append("--help")
            all_shared |= set(shared)
            all_listed |= set(listed)
            nflags += len(listed)
            man_own = roff_flags(entries.get(cmd, ""))
            check(cmd in entries, f"pound.1: no entry for {cmd} in COMMANDS")
            comp = completion_flags(cmd)
            for f in listed:
                if f == "--help":  # the man page says it once for every command
                    pass
                elif f in shared:
                    check(f in man_shared or f in man_own,
                          f"pound.1: {cmd}: {f} (a model/scheme flag) is not in MODEL FLAGS or SCHEME FLAGS")
                else:
                    check(f in man_own or (takes_case and f in man_shared),
                          f"pound.1: {cmd}: {f} is not in the entry of {cmd}")
                check(f in comp, f"completion: {cmd}: {f} is not offered")
                ok, why = parser_takes(pound, cmd, f, follow, tmp)
                check(ok, f"parser: pound {cmd} {f}: not taken ({why})")
            for f, vals in sorted(choices.items()):  # the values: completion, parser
                offered, _ = completion_values(cmd, f)
                check(set(offered) == vals, f"completion: {cmd} {f}: offers {sorted(offered)}, "
                      f"the help names {sorted(vals)}")
                for v in sorted(vals):
                    p = subprocess.run([pound, cmd, f, v, SENTINEL], capture_output=True, text=True,
                                       timeout=20, cwd=tmp)
                    check(f"unknown flag '{SENTINEL}'" in p.stderr,
                          f"parser: pound {cmd} {f} {v}: {p.stderr.strip()[:200]}")
            for f in man_own:
                check(f in listed, f"pound.1: {cmd}: the entry names {f}, which pound {cmd} --help does not list")
            for f in comp:
                check(f in listed, f"completion: {cmd}: offers {f}, which pound {cmd} --help does not list")
    nflags += top_level(pound, entries)
    man_choices = roff_choices(open(MAN, encoding="utf-8").read())
    for f, vals in sorted(man_choices.items()):
        check(vals == all_choices.get(f), f"pound.1: {f} {'|'.join(sorted(vals))}, the help names "
              f"{'|'.join(sorted(all_choices.get(f, [])))}")
    for f in man_shared:
        check(f in all_shared or f in all_listed,
              f"pound.1: MODEL/SCHEME FLAGS name {f}, which no command's --help lists")
    for m in failures:
        print("FAIL", m)
    status = "ok" if not failures else f"FAILED {len(failures)} of"
    print(f"flags-check: {status} {checks} checks, {nflags} flags of {len(COMMANDS)} commands "
          f"(help, docs/pound.1, bash completion, parser)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
