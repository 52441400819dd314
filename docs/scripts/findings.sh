#!/bin/sh
# Runs what one table of docs/findings.md reports and prints the table as Markdown:
#   sh docs/scripts/findings.sh thesis|sweep-helices|sweep-turns|hypotheses|tube
# Uses `spira` from the PATH, or the binary named by $SPIRA. Runs go to out/findings/.
set -eu
cd "$(dirname "$0")/../.."
SPIRA=${SPIRA:-spira}
OUT=out/findings
mkdir -p "$OUT"
run() { "$SPIRA" run "$@" > /dev/null 2>&1 || true; }

case "${1:-}" in
thesis)
    for n in 1 2 4 8; do run cases/thesis-n$n.toml --out $OUT/n$n; done
    sed 's/^steps = 10 .*/steps = 10\nbranch = "switch"/' cases/thesis-n2.toml > $OUT/n2-switch.toml
    run $OUT/n2-switch.toml --out $OUT/n2-switch
    ;;
sweep-helices | sweep-turns)
    "$SPIRA" sweep cases/$1.toml --out $OUT/$1 > /dev/null
    ;;
hypotheses)
    # -s INT: a path that wanders keeps what converged
    for f in cases/hypotheses/*.toml; do
        timeout -s INT 120 "$SPIRA" run "$f" --out $OUT/"$(basename "$f" .toml)" > /dev/null 2>&1 || true
    done
    ;;
tube)
    # the thesis case with turns and elements scaled together (48 per 3.5 turns),
    # n >= 4 as its symmetric pair
    for n in 2 4 8 16; do
        for t in 3.5 7 14 28; do
            e=$(awk "BEGIN { print int(48 * $t / 3.5) }")
            sym=""
            [ "$n" -ge 4 ] && sym='\nsymmetric = true'
            sed -e "s/^helices = 8 /helices = $n /" -e "s/^turns = 3.5 /turns = $t /" \
                -e "s/^elements = 48 /elements = $e /" \
                -e "s/^order = \"quadratic\"/order = \"quadratic\"$sym/" \
                cases/thesis-n8.toml > $OUT/tube-n$n-t$t.toml
            run $OUT/tube-n$n-t$t.toml --out $OUT/tube-n$n-t$t
        done
    done
    ;;
*)
    echo "usage: sh docs/scripts/findings.sh thesis|sweep-helices|sweep-turns|hypotheses|tube" >&2
    exit 2
    ;;
esac
python3 docs/scripts/tables.py "$1" $OUT
