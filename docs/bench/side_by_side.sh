#!/bin/bash
# Time two installs of meshvis alternately on the same commands, three runs each.
#
#   bash docs/bench/side_by_side.sh OLD_VENV NEW_VENV [MODELS_DIR]
#
# OLD_VENV and NEW_VENV are virtual environments with meshvis installed (each from its own
# checkout); MODELS_DIR holds real/ and real2/ (default ../shared/models).  Prints one line
# per run: install, case, wall seconds, peak memory (KB), 1-minute load.  The outputs go to
# a temporary folder per install; compare them with cmp afterwards (the folders are printed).
set -euo pipefail
old=$1; new=$2; models=${3:-../shared/models}
out=$(mktemp -d)
echo "outputs in $out/old and $out/new"
mkdir -p "$out/old" "$out/new"
run() {  # label venv case args...
  local label=$1 venv=$2 name=$3; shift 3
  /usr/bin/time -f "$label $name %e s %M KB load=$(cut -d' ' -f1 /proc/loadavg)" \
    "$venv/bin/meshvis" "$@" --quiet --force 2>&1 >/dev/null | tail -1
}
for rep in 1 2 3; do
  for label in old new; do
    if [ "$label" = old ]; then venv=$old; else venv=$new; fi
    d=$out/$label
    run $label "$venv" mon-object remove-interior "$models/real/pybullet__samurai_monastry.obj" -o "$d/m.obj" --visibility object
    run $label "$venv" mon-both remove-interior "$models/real/pybullet__samurai_monastry.obj" -o "$d/mb.obj"
    run $label "$venv" pandora orient "$models/real2/pandora_level.obj" -o "$d/p.obj"
    run $label "$venv" vangogh orient "$models/real2/van_gogh_room.glb" -o "$d/v.glb"
    run $label "$venv" chair orient "$models/real/chair_model.obj" -o "$d/c.obj"
  done
done
