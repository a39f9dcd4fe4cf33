#!/bin/sh
# stress.sh — `make stress`: build the libFuzzer harnesses (clang, ASan +
# UBSan) and a ThreadSanitizer pound (clang, LLVM's OpenMP with the Archer
# tool), then run the adversarial suite stress/run.py against BUILD/pound.
#
#   sh scripts/stress.sh BUILD [run.py options...]
#
# Without clang the fuzz and tsan categories report "skip" with the reason;
# every other category still runs.
set -eu
build=$1
shift
s=$build/stress
mkdir -p "$s/fuzz" "$s/tsan"
rm -f "$s/fuzz.skip" "$s/tsan.skip" "$s/archer.path"
clang=$(command -v clang || true)

if [ -z "$clang" ]; then
    echo "fuzz: skip (clang not installed)" > "$s/fuzz.skip"
    echo "tsan: skip (clang not installed)" > "$s/tsan.skip"
else
    # The library under ASan + UBSan with libFuzzer's coverage hooks, no OpenMP.
    fz="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
    make --no-print-directory BUILD="$s/fuzzlib" CC=clang OPT=-O1 OPENMP= XCFLAGS="$fz" \
        "$s/fuzzlib/libpound.a" "$s/fuzzlib/cli/spectrum_journal.o"
    libs=$(make --no-print-directory -s print-libs)
    for t in lcp scene record journal; do
        extra=""
        [ $t = journal ] && extra="$s/fuzzlib/cli/spectrum_journal.o"
        echo "  LD    $s/fuzz/fuzz_$t"
        clang -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
            -Icore -Ilcp -Iengine -Iproblems -Icli stress/fuzz/fuzz_$t.c $extra \
            "$s/fuzzlib/libpound.a" $libs -o "$s/fuzz/fuzz_$t"
    done
    # pound under ThreadSanitizer; Archer makes LLVM OpenMP's synchronisation visible.
    make --no-print-directory BUILD="$s/tsanlib" CC=clang OPT=-O1 OPENMP=-fopenmp \
        XCFLAGS="-fsanitize=thread -fno-omit-frame-pointer" "$s/tsanlib/pound"
    cp "$s/tsanlib/pound" "$s/tsan/pound"
    archer=$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | tail -1 || true)
    [ -n "$archer" ] && echo "$archer" > "$s/archer.path"
fi
exec python3 stress/run.py --pound "$build/pound" --stress "$s" "$@"
