#!/bin/sh
# api-check.sh — pound as an installed library (make install-check; make check).
#
#   sh scripts/api-check.sh [BUILD]      (BUILD: the build folder, default build)
#
# Installs into a staging folder (make install DESTDIR=$tmp PREFIX=/usr) and
# checks what a user gets: the files, the soname and its links, the exports
# of libpound.so (pd_* only, no HDF5 needed), the examples/api/ programs
# compiled with the installed pound.pc against the installed headers and
# shared library (and one linked statically with pkg-config --static), each
# run for its own sanity check; the installed pound --version, man page and
# bash completion; then make uninstall leaves nothing.  One summary line;
# exit 1 on any failure, with what failed above it.
set -u
BUILD=${1:-build}
MAKE=${MAKE:-make}
CC=${CC:-cc}
# make -n (the single-letter flags come first in MAKEFLAGS): run nothing
first=${MAKEFLAGS:-}
first=${first%% *}
case $first in -* | '') ;; *n*)
    echo "sh scripts/api-check.sh $BUILD"
    exit 0 ;;
esac
tmp=$(mktemp -d "${TMPDIR:-/tmp}/pound-api.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
stage=$tmp/stage
root=$stage/usr
start=$(date +%s)
checks=0
failed=0

# check NAME COMMAND...: run it quietly; on failure say so with its output.
check() {
    name=$1
    shift
    checks=$((checks + 1))
    if "$@" >"$tmp/out" 2>&1; then
        return 0
    fi
    failed=$((failed + 1))
    echo "api-check: FAIL $name"
    sed 's/^/    /' "$tmp/out" | head -20
    return 1
}

# The library's version, from the header the install copied.
version=$(sed -n 's/^#define PD_VERSION "\(.*\)"/\1/p' core/pd_core.h)

# ---- install -----------------------------------------------------------
if ! check "make install" $MAKE --no-print-directory BUILD="$BUILD" install \
    DESTDIR="$stage" PREFIX=/usr; then
    echo "api-check: 0 of 1 checks passed (make install failed)"
    exit 1
fi

files="bin/pound lib/libpound.a lib/libpound.so.$version lib/libpound.so.0 lib/libpound.so
include/pound/pound.h include/pound/pd_core.h include/pound/pd_lcp.h
include/pound/pd_engine.h include/pound/pd_problems.h lib/pkgconfig/pound.pc
share/man/man1/pound.1 share/bash-completion/completions/pound"

# Every file there, the links pointing at the real library, nothing else.
installed() {
    for f in $files; do
        [ -e "$root/$f" ] || { echo "missing $f"; return 1; }
    done
    [ "$(readlink "$root/lib/libpound.so.0")" = "libpound.so.$version" ] &&
        [ "$(readlink "$root/lib/libpound.so")" = "libpound.so.0" ] ||
        { echo "symlinks: $(ls -l "$root/lib")"; return 1; }
    extra=$(cd "$root" && find . \( -type f -o -type l \) | sed 's|^\./||' | sort |
        while read -r f; do case " $(echo $files) " in *" $f "*) ;; *) echo "$f" ;; esac; done)
    [ -z "$extra" ] || { echo "not expected: $extra"; return 1; }
}
check "installed files" installed

# The soname, the exports (pd_* functions only) and the libraries it needs.
exports() {
    so=$root/lib/libpound.so.$version
    readelf -d "$so" | grep -q 'SONAME.*\[libpound\.so\.0\]' || { echo "soname"; return 1; }
    nm -D --defined-only "$so" | awk '{print $NF}' >"$tmp/syms"
    n=$(wc -l <"$tmp/syms")
    bad=$(grep -v '^pd_' "$tmp/syms")
    [ "$n" -gt 100 ] && [ -z "$bad" ] || { echo "$n exports; not pd_*: $bad"; return 1; }
    ! readelf -d "$so" | grep -qi 'NEEDED.*hdf5' || { echo "libpound.so needs HDF5"; return 1; }
    echo "$n" >"$tmp/nsyms"
}
check "exports of libpound.so" exports

# docs/api.md's lists: per installed header, the PD_API names and their
# count in "- `pd_x.h` (N): ..."; the total "**N functions" equal to the
# exports.  The README gives no count (it points at the list).
documented() {
    awk '/^## The public API and what libpound.so exports/ { f = 1; next } /^## / { f = 0 } f' \
        docs/api.md >"$tmp/apidoc"
    total=$(sed -n 's/.*\*\*\([0-9][0-9]*\) functions.*/\1/p' "$tmp/apidoc" | head -1)
    [ "$total" = "$(wc -l <"$tmp/syms")" ] ||
        { echo "docs/api.md says $total functions; libpound.so exports $(wc -l <"$tmp/syms")"; return 1; }
    ok=0
    for h in pd_core.h pd_lcp.h pd_engine.h pd_problems.h; do
        # the header's bullet: from its line to the next bullet
        awk -v h="$h" 'index($0, "- `" h "` (") == 1 { f = 1 } f && /^- `/ && index($0, h) == 0 { f = 0 } f' \
            "$tmp/apidoc" >"$tmp/bullet"
        said=$(sed -n 's/^- `[a-z_.]*` (\([0-9]*\)).*/\1/p' "$tmp/bullet")
        grep -o '`pd_[A-Za-z0-9_]*`' "$tmp/bullet" | tr -d '`' | sort >"$tmp/listed"
        { tr '\n' ' ' <"$root/include/pound/$h"; echo; } | sed 's/PD_API/\n&/g' |
            sed -n 's/^PD_API[^(]*[ *]\(pd_[A-Za-z0-9_]*\) *(.*/\1/p' | sort >"$tmp/declared"
        if ! cmp -s "$tmp/listed" "$tmp/declared"; then
            echo "docs/api.md, $h: listed vs declared:"
            diff "$tmp/listed" "$tmp/declared" | grep '^[<>]'
            ok=1
        fi
        [ "$said" = "$(wc -l <"$tmp/declared")" ] ||
            { echo "docs/api.md, $h: says ($said), declares $(wc -l <"$tmp/declared")"; ok=1; }
    done
    return $ok
}
check "docs/api.md lists the exports" documented

# tests/test_api_null.c is generated from the installed headers: the
# committed file must be what the generator makes of them (python3: CI).
null_test() {
    command -v python3 >/dev/null || { echo "skip: no python3" >&2; return 0; }
    inc=$root/include/pound
    python3 scripts/gen_api_null.py "$inc/pound.h" "$inc/pd_core.h" "$inc/pd_lcp.h" \
        "$inc/pd_engine.h" "$inc/pd_problems.h" >"$tmp/test_api_null.c" || return 1
    diff -u tests/test_api_null.c "$tmp/test_api_null.c" | head -20
    cmp -s tests/test_api_null.c "$tmp/test_api_null.c" ||
        { echo "tests/test_api_null.c is stale: python3 scripts/gen_api_null.py \$(PUB_HDRS) > tests/test_api_null.c"; return 1; }
}
check "tests/test_api_null.c from the installed headers" null_test

# python/pound/_structs.py, the Python package's ctypes mirrors of the public
# structs, is generated from the headers too (scripts/gen_py_structs.py).
py_structs() {
    command -v python3 >/dev/null || { echo "skip: no python3" >&2; return 0; }
    python3 scripts/gen_py_structs.py --check
}
check "python/pound/_structs.py from the headers" py_structs

# ---- the examples against the installed library ------------------------
PKG="pkg-config --define-variable=prefix=$root"
cflags= libs= static=
export PKG_CONFIG_PATH="$root/lib/pkgconfig"
cflags=$($PKG --cflags pound 2>/dev/null) && libs=$($PKG --libs pound 2>/dev/null) &&
    static=$($PKG --static --libs pound 2>/dev/null)
check "pkg-config pound" test -n "$libs"
case $cflags in *"$root/include"*) ;; *) check "pkg-config --cflags" false ;; esac

# Build and run one example: shared, or static (libpound.a, the rest shared).
example() {
    ex=$1 how=$2 bin=$tmp/$1-$2
    if [ "$how" = shared ]; then
        # the README's line: cc prog.c $(pkg-config --cflags --libs pound), no -lm
        $CC -std=c11 -Wall -Wextra -Wpedantic -Werror examples/api/$ex.c $cflags $libs -o "$bin" ||
            return 1
        LD_LIBRARY_PATH=$root/lib ldd "$bin" | grep -q "libpound.so.0 => $root/lib/" ||
            { LD_LIBRARY_PATH=$root/lib ldd "$bin"; return 1; }
    else
        $CC -std=c11 -Wall -Wextra -Wpedantic -Werror examples/api/$ex.c $cflags \
            $(echo " $static " | sed 's/ -lpound / -Wl,-Bstatic -lpound -Wl,-Bdynamic /') \
            -lm -o "$bin" || return 1
        ! readelf -d "$bin" | grep -q 'NEEDED.*libpound' || { echo "linked to libpound.so"; return 1; }
    fi
    LD_LIBRARY_PATH=$root/lib "$bin"
}
nex=0
for src in examples/api/*.c; do
    ex=$(basename "$src" .c)
    nex=$((nex + 1))
    check "example $ex (shared)" example "$ex" shared
done
check "example spectrum (static)" example spectrum static
[ "$nex" -ge 4 ] || check "at least 4 examples in examples/api/" false

# A C++ user includes the umbrella header too.
cxx() {
    command -v c++ >/dev/null || return 0
    printf '#include <pound/pound.h>\nint main() { return pd_version()[0] == PD_VERSION[0] ? 0 : 1; }\n' \
        >"$tmp/cxx.cc"
    c++ -Wall -Wextra -Werror "$tmp/cxx.cc" $cflags $libs -o "$tmp/cxx" &&
        LD_LIBRARY_PATH=$root/lib "$tmp/cxx"
}
check "C++ includes pound.h" cxx

# ---- the installed command, man page and completion --------------------
check "pound --version" sh -c '"$1/bin/pound" --version | head -1 | grep -qx "pound $2"' - \
    "$root" "$version"
man_page() {
    command -v groff >/dev/null || return 0
    groff -man -Tutf8 -ww -z "$root/share/man/man1/pound.1" 2>&1 | { ! grep .; }
}
check "man page" man_page
completion() {
    command -v bash >/dev/null || return 0
    bash -c '. "$1"; COMP_WORDS=(pound simulate --method ""); COMP_CWORD=3; _pound
        [ "${COMPREPLY[*]}" = "auto moreau event penalty newmark event-general" ] || { echo "got: ${COMPREPLY[*]}"; exit 1; }
        COMP_WORDS=(pound sp); COMP_CWORD=1; _pound; [ "${COMPREPLY[*]}" = spectrum ]' - \
        "$root/share/bash-completion/completions/pound"
}
check "bash completion" completion

# ---- uninstall -----------------------------------------------------------
left() {
    $MAKE --no-print-directory BUILD="$BUILD" uninstall DESTDIR="$stage" PREFIX=/usr || return 1
    rest=$(find "$stage" \( -type f -o -type l \))
    [ -z "$rest" ] || { echo "left behind: $rest"; return 1; }
    [ ! -d "$root/include/pound" ] || { echo "include/pound/ left"; return 1; }
}
check "make uninstall leaves nothing" left

secs=$(($(date +%s) - start))
nsyms=$(cat "$tmp/nsyms" 2>/dev/null || echo "?")
if [ "$failed" -eq 0 ]; then
    echo "api-check: $checks checks passed: installed $version, $nex examples built against it" \
        "(shared and static), $nsyms exports (pd_* only), uninstall clean (${secs} s)"
    exit 0
fi
echo "api-check: $failed of $checks checks FAILED (${secs} s)"
exit 1
