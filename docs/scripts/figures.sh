#!/bin/sh
# Regenerates every figure of the documentation into docs/figures/: the thesis load
# curves, curvature profiles and views (and the views as PNG), and the work-precision charts
# with their tables.
# Run from anywhere; uses `spira` from the PATH, or the binary named by $SPIRA
# (e.g. SPIRA=target/release/spira sh docs/scripts/figures.sh). Scratch runs go to out/docs/.
set -eu
cd "$(dirname "$0")/../.."
SPIRA=${SPIRA:-spira}
for n in 1 2 4 8; do
    "$SPIRA" run cases/thesis-n$n.toml --states --out out/docs/n$n > /dev/null
done
"$SPIRA" plot out/docs/n1 out/docs/n2 out/docs/n4 out/docs/n8 --out docs/figures --only load
"$SPIRA" plot out/docs/n1 out/docs/n8 --out docs/figures --eps 0.5 --only curvature
"$SPIRA" plot out/docs/n8 --out docs/figures --eps 0.5 --only views
# the joints side by side (docs/joints.md): n = 8 pinned, elastic, welded, sliding
for kind in pin elastic welded sliding; do
    case $kind in pin) c=cases/thesis-n8.toml ;; *) c=cases/thesis-n8-$kind.toml ;; esac
    "$SPIRA" run $c --out out/docs/joints/$kind > /dev/null
done
"$SPIRA" plot out/docs/joints/pin out/docs/joints/elastic out/docs/joints/welded out/docs/joints/sliding --out out/docs/joints --only load
cp out/docs/joints/load.svg docs/figures/joints-load.svg
for n in 1 8; do
    "$SPIRA" precision cases/thesis-n$n.toml --out out/docs/precision-n$n --repeats 3 > out/docs/precision-n$n.txt
    cp out/docs/precision-n$n/precision.svg docs/figures/precision-n$n.svg
    cp out/docs/precision-n$n/precision.csv docs/figures/precision-n$n.csv
done
# the README's figure, as PNG: librsvg and cairo through Python's ctypes
python3 docs/scripts/svg-to-png.py docs/figures/views-step10.svg docs/figures/views-step10.png
echo "figures written to docs/figures/"
