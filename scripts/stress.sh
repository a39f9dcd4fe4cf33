#!/bin/sh
# stress.sh — `make stress`: build the libFuzzer harnesses (clang, ASan +
# UBSan) and a ThreadSanitizer pound (clang, LLVM's OpenMP with the Archer
# tool), then run the adversarial suite stress/run.py against BUILD/pound.
#
#   sh scripts/stress.sh BUILD [run.py options...]
#
# Without clang the fuzz, tsan and capi categories report "skip" with the reason;
# every other category still runs.  The in-repo corpus (stress/corpus,
# stress/cases) is always required; ../shared's (or $POUND_SHARED's) LCPs and
# records are required when that folder exists or POUND_SHARED is set: a
# missing part is then a failure, not a skip.  POUND_STRESS_STRICT=1 (CI)
# fails a skipped capi or python category.
set -eu
build=$1
shift
s=$build/stress
mkdir -p "$s/fuzz" "$s/tsan"
rm -f "$s/fuzz.skip" "$s/tsan.skip" "$s/capi.skip" "$s/archer.path"
clang=$(command -v clang || true)

if [ -z "$clang" ]; then
    echo "fuzz: skip (clang not installed)" > "$s/fuzz.skip"
    echo "tsan: skip (clang not installed)" > "$s/tsan.skip"
    echo "capi: skip (clang not installed)" > "$s/capi.skip"
else
    # The library under ASan + UBSan with libFuzzer's coverage hooks, no OpenMP.
    fz="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
    make --no-print-directory BUILD="$s/fuzzlib" CC=clang OPT=-O1 OPENMP= XCFLAGS="$fz" \
        "$s/fuzzlib/libpound.a" "$s/fuzzlib/cli/spectrum_journal.o" "$s/fuzzlib/cli/journal.o" \
        "$s/fuzzlib/cli/suite_journal.o"
    libs=$(make --no-print-directory -s print-libs)
    for t in lcp scene record journal suite; do
        extra=""
        [ $t = journal ] && extra="$s/fuzzlib/cli/spectrum_journal.o $s/fuzzlib/cli/journal.o"
        [ $t = suite ] && extra="$s/fuzzlib/cli/suite_journal.o $s/fuzzlib/cli/journal.o"
        echo "  LD    $s/fuzz/fuzz_$t"
        clang -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
            -Icore -Ilcp -Iengine -Iproblems -Icli stress/fuzz/fuzz_$t.c $extra \
            "$s/fuzzlib/libpound.a" $libs -o "$s/fuzz/fuzz_$t"
    done
    # The C API misuse category: the generated NULL test and result-shape
    # misuse (stress/capi/capi_main.c) against the library under ASan + UBSan.
    mkdir -p "$s/capi"
    echo "  LD    $s/capi/capi"
    clang -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all \
        $(pkg-config --cflags hdf5) -Icore -Ilcp -Iengine -Iproblems -Icli -Itests \
        stress/capi/capi_main.c tests/test_api_null.c tests/api_fixtures.c \
        "$s/fuzzlib/libpound.a" $libs -o "$s/capi/capi"
    # pound under ThreadSanitizer; Archer makes LLVM OpenMP's synchronisation visible.
    make --no-print-directory BUILD="$s/tsanlib" CC=clang OPT=-O1 OPENMP=-fopenmp \
        XCFLAGS="-fsanitize=thread -fno-omit-frame-pointer" "$s/tsanlib/pound"
    cp "$s/tsanlib/pound" "$s/tsan/pound"
    archer=$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | tail -1 || true)
    [ -n "$archer" ] && echo "$archer" > "$s/archer.path"
fi
# The Python misuse category imports the package from python/ with this library.
make --no-print-directory BUILD="$build" shared
exec python3 stress/run.py --pound "$build/pound" --stress "$s" "$@"
