#!/bin/bash
# The first `run_demo` after an install, when numba compiles every kernel: two checkouts
# alternately, each with an empty kernel cache, twice each.
#
#   bash docs/bench/first_run.sh OLD_CHECKOUT NEW_CHECKOUT [PYTHON]
#
# PYTHON (default: python) must have meshvis' dependencies; each checkout is put first on
# PYTHONPATH, and the script checks that its meshvis is the one imported.
set -euo pipefail
old=$(realpath "$1"); new=$(realpath "$2"); py=${3:-python}
work=$(mktemp -d)
cd "$work"
for rep in 1 2; do
  for label in old new; do
    if [ "$label" = old ]; then src=$old; else src=$new; fi
    rm -rf "$work/cache" "$work/demo"
    start=$(date +%s.%N)
    PYTHONPATH=$src NUMBA_CACHE_DIR=$work/cache "$py" -c "
import meshvis
assert meshvis.__file__.startswith('$src'), meshvis.__file__
from meshvis.eval.demo import run_demo
run_demo('$work/demo', say=lambda s: None)"
    end=$(date +%s.%N)
    echo "$label $(echo "$end - $start" | bc) s load=$(cut -d' ' -f1 /proc/loadavg)"
  done
done
rm -rf "$work"
