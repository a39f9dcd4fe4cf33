#!/bin/sh
# scripts/layers-check.sh — the layers' second rule (make check): a file
# includes the headers of its own folder, and of the folders below it only
# their interfaces, pd_*.h (the first rule, no folder above, is the
# compiler's: each folder compiles with the include paths of its layer,
# Makefile INC_*).  Prints every breach and exits 1 on any.
cd "$(dirname "$0")/.." || exit 2
layers="core lcp engine problems cli bench"
bad=0
for dir in $layers; do
    for f in "$dir"/*.c "$dir"/*.h; do
        [ -e "$f" ] || continue
        for h in $(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f"); do
            [ -e "$dir/$h" ] && continue
            for low in $layers; do
                [ "$low" = "$dir" ] && break
                if [ -e "$low/$h" ]; then
                    case "$h" in
                    pd_*.h) ;;
                    *) echo "layers-check: $f includes $low/$h, private to $low/"; bad=1 ;;
                    esac
                fi
            done
        done
    done
done
[ $bad -eq 0 ] && echo "layers-check: every include is its folder's own or a lower layer's pd_*.h"
exit $bad
