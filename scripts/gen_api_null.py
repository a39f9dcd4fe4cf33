#!/usr/bin/env python3
"""gen_api_null.py -- the C API's NULL test, generated from the public headers.

    python3 scripts/gen_api_null.py HEADER... > tests/test_api_null.c

Reads every PD_API declaration of the headers (the installed ones in
`make install-check`, the source ones for the committed test) and writes one
case per (function, pointer argument): the function called with NULL in that
argument and live or zeroed objects in the others (tests/api_fixtures.c).
What a case expects follows from the return type (docs/api.md, "Pointers"):

  int          a negative status (functions returning a count, a flag or an
               index return 0 or a negative number: COUNTS below);
  pointer      NULL (a `const char *` name: any readable string);
  void, other  no crash, no sanitizer report: a documented no-op.

Arguments that the headers document as optional (NULL means defaults, zeros,
none) are listed in OPTIONAL; their NULL must work and is run too, expecting
only no crash.  `pd_err *` arguments (always optional), `void *` contexts and
callbacks are passed as NULL in every case and not counted.  The script
fails when a listed name is no longer declared, so the lists cannot drift.
"""
import re
import sys

# (function, argument): NULL documented as meaning defaults / zeros / none.
OPTIONAL = {
    ("pd_lcp_lemke", "opts"), ("pd_lcp_lemke", "info"),
    ("pd_lcp_solve", "opts"), ("pd_lcp_solve", "info"),
    ("pd_lcp_residual", "complementarity"), ("pd_lcp_residual", "infeasibility"),
    ("pd_lcp_residual", "residual"),
    ("pd_hermite5", "fd"),
    ("pd_mjb_init", "opts"), ("pd_edr_alloc", "opts"),
    ("pd_edr_run", "q0"), ("pd_edr_run", "v0"),
    ("pd_edg_run", "opts"), ("pd_edg_run", "q0"), ("pd_edg_run", "v0"),
    ("pd_penalty_run", "opts"), ("pd_penalty_run", "q0"), ("pd_penalty_run", "v0"),
    ("pd_ed_sdof_run", "opts"),
    ("pd_mj_reset", "q0"), ("pd_mj_reset", "v0"),
    ("pd_scene_new", "exc"), ("pd_scene_resolve_opts", "in"), ("pd_scene_run", "opts"),
    ("pd_scene_summarize", "opts"), ("pd_scene_trace_alloc", "o"),
    ("pd_osc_resolve_opts", "in"), ("pd_osc_run", "opts"), ("pd_osc_simulate", "opts"),
    ("pd_osc_reference", "opts"), ("pd_osc_penalty", "opts"), ("pd_osc_summarize", "opts"),
    ("pd_record_plausible", "msg"),
    ("pd_lcp_read_band", "band"), ("pd_lcp_read_band", "nnz"),
}

# int functions whose value is a count, a flag or an index: NULL gives <= 0.
COUNTS = {"pd_scene_as_oscillator", "pd_scene_result_fits", "pd_osc_batchable", "pd_osc_yield_exact",
          "pd_matrix_is_diagonal", "pd_lcp_nmax", "pd_lcp_solver_nmax", "pd_mjb_finite",
          "pd_record_plausible", "pd_osc_yields", "pd_scene_springs"}

# Scalars given to the other arguments, by name (default: 1 / 1.0).
ZERO_NAMES = {"i", "j", "k", "l", "lane", "task", "side", "seed", "index"}


def declarations(paths):
    """[(return type, name, [(type, arg name)])] of every PD_API function."""
    text = ""
    for p in paths:
        with open(p) as f:
            text += f.read() + "\n"
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    callbacks = set(re.findall(r"typedef[^;]*?\(\s*\*\s*(\w+)\s*\)", text))
    out = []
    for d in re.findall(r"PD_API\s+([^;{#]*?\))\s*(?:__attribute__\s*\(\(.*?\)\))?\s*;", text,
                        flags=re.S):
        d = " ".join(d.split())
        m = re.match(r"(.*?)\b(pd_\w+)\s*\((.*)\)$", d)
        if not m:
            sys.exit(f"gen_api_null: cannot read the declaration '{d}'")
        ret, name, args = m.group(1).strip(), m.group(2), m.group(3).strip()
        params = []
        if args not in ("void", ""):
            for k, a in enumerate(args.split(",")):
                a = a.strip()
                if a == "...":
                    continue
                am = re.match(r"(.*?)(\w+)\s*(\[[^\]]*\])?$", a)
                if not am or not am.group(1).strip():
                    sys.exit(f"gen_api_null: {name}: cannot read the argument '{a}'")
                t = am.group(1).strip()
                if am.group(3):
                    t += " *"
                t = re.sub(r"\s*\*", " *", t).replace("* *", "**")
                params.append((t, am.group(2)))
        out.append((ret, name, params))
    return out, callbacks


def is_pointer(t):
    return t.endswith("*")


def base_type(t):
    """'const pd_scene *' -> 'pd_scene'."""
    return re.sub(r"\bconst\b", "", t).replace("*", "").strip()


def value(t, name, callbacks, fn, k):
    """C expression for argument k of fn when it is not the NULL one."""
    if is_pointer(t):
        b = base_type(t)
        if t.replace(" ", "") in ("void*", "constvoid*") or b == "pd_err" and t.count("*") == 1:
            return "NULL" if b != "pd_err" else "&err"
        if t.count("*") == 2:
            return f"({t})fx_slot()"
        if b == "char":
            return f"({t})fx_string(\"{fn}\", \"{name}\")"
        return f"({t})fx_object(\"{b}\", \"{fn}\", {k})"
    if t in callbacks:
        return "NULL"
    if t in ("double", "float"):
        return "0.0" if name in ZERO_NAMES else "1.0"
    if name == "status":
        return "PD_EINVAL"
    if t in ("int", "long", "size_t", "unsigned", "uint64_t", "long long"):
        return "0" if name in ZERO_NAMES else ("64" if t == "size_t" else "1")
    # an enum or a struct passed by value
    return f"fx_zero_{t}()" if t in ("pd_matrix",) else f"({t})0"


def expectation(ret, fn):
    if ret == "void":
        return "EXPECT_NOCRASH"
    if is_pointer(ret):
        return "EXPECT_NAME" if ret.replace(" ", "") == "constchar*" else "EXPECT_NULL"
    if ret == "int":
        return "EXPECT_COUNT" if fn in COUNTS else "EXPECT_ERROR"
    return "EXPECT_NOCRASH"


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    decls, callbacks = declarations(argv[1:])
    names = {d[1]: d for d in decls}
    for fn, arg in sorted(OPTIONAL):
        if fn not in names or arg not in [p[1] for p in names[fn][2]]:
            sys.exit(f"gen_api_null: OPTIONAL lists {fn}({arg}), which the headers do not declare")
    for fn in sorted(COUNTS):
        if fn not in names:
            sys.exit(f"gen_api_null: COUNTS lists {fn}, which the headers do not declare")
    w = sys.stdout.write
    w("/* test_api_null.c -- GENERATED by scripts/gen_api_null.py from the public\n"
      " * headers; do not edit (make api-check regenerates it from the installed\n"
      " * headers and fails on a difference).\n"
      " *\n"
      " * Every exported function called with NULL in each pointer argument, the\n"
      " * others live (tests/api_fixtures.c), each call in its own child process:\n"
      " * an error status, a NULL pointer or a documented no-op, never a crash. */\n"
      "#include \"api_fixtures.h\"\n\n")
    cases = []
    for ret, fn, params in decls:
        for k, (t, name) in enumerate(params):
            if not is_pointer(t):
                continue
            b = base_type(t)
            if t.count("*") == 1 and (b == "pd_err" or b == "void"):
                continue
            idx = len(cases)
            args = ["NULL" if j == k else value(tj, nj, callbacks, fn, j)
                    for j, (tj, nj) in enumerate(params)]
            call = f"{fn}({', '.join(args)})"
            exp = "EXPECT_NOCRASH" if (fn, name) in OPTIONAL else expectation(ret, fn)
            w(f"static long api_case_{idx}(void)\n{{\n    pd_err err = {{0}};\n")
            if ret == "void":
                w(f"    {call};\n    (void)err;\n    return 0;\n}}\n\n")
            elif is_pointer(ret):
                if ret.replace(" ", "") == "constchar*":
                    w(f"    const char *s = {call};\n    (void)err;\n"
                      "    return s ? (long)strlen(s) + 1 : 0;\n}\n\n")
                else:
                    w(f"    {ret} p = {call};\n    (void)err;\n    return p != NULL;\n}}\n\n")
            elif ret in ("int", "long"):
                w(f"    long v = {call};\n    (void)err;\n    return v;\n}}\n\n")
            else:
                w(f"    {ret} v = {call};\n    (void)v;\n    (void)err;\n    return 0;\n}}\n\n")
            cases.append((fn, name, exp, idx))
    w("const api_null_case api_null_cases[] = {\n")
    for fn, name, exp, idx in cases:
        w(f"    {{.function = \"{fn}\", .argument = \"{name}\", .expect = {exp}, "
          f".call = api_case_{idx}}},\n")
    w("};\n")
    w(f"const int api_null_ncases = {len(cases)};\n")
    w(f"const int api_null_nfunctions = {len(decls)};\n")


if __name__ == "__main__":
    main(sys.argv)
