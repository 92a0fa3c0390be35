"""Write the project's small sample models (and their ground truth) into ``models/``.

Usage::

    python models/make_models.py            # (re)write models/
    python models/make_models.py --out DIR  # write somewhere else

Every model comes from a generator of :mod:`meshvis.eval.generators` with small size
parameters, so that the folder stays well below 1 MB.  The generators build z-up; the
files are turned y-up (z becomes y), the convention of OBJ that meshvis and other tools
read them with, so that they stand upright.  Next to every ``<stem>.obj`` the
script writes ``<stem>.truth.npz`` (see :meth:`meshvis.eval.generators.GroundTruth.save_arrays`),
whose arrays are indexed like the faces of the OBJ file in file order.  Coordinates are
rounded to 6 decimals before writing (shorter files; rounding keeps coincident corners
and coplanar walls coincident, so no truth changes).  The output is identical byte for
byte from run to run.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, str(HERE.parent))

from meshvis.eval import generators as g  # noqa: E402
from meshvis.eval.generators import GroundTruth  # noqa: E402

#: file name -> how to make it; documented one by one in models/README.md
MODELS: dict[str, Callable[[], GroundTruth]] = {
    "nested_shells.obj": lambda: g.nested_shells(n=3, subdivisions=2, seed=0),
    "house.obj": lambda: g.house(rooms=(3, 2), floors=2, cell=1.0, furniture=2, seed=0),
    "cracked_box.obj": lambda: g.cracked_box(cell=0.125, crack_width=1e-3, face_cracks=3, seed=0),
    "cave.obj": lambda: g.box_with_opening(cell=0.125, opening=0.6, side="-y"),
    "cup.obj": lambda: g.cup(sections=32, bottom_rings=4, wall_rings=8),
    "terrain.obj": lambda: g.terrain(n=24, seed=0),
    "overlapping_solids.obj": lambda: g.overlapping_solids(subdivisions=3, cell=0.2, seed=0),
    "sphere_pair_soup.obj": lambda: g.soupify(g.sphere_pair(subdivisions=3, seed=0), flip=0.3, seed=1),
    "assembly.obj": lambda: g.assembly(sections=16, cell=0.3),
}

DECIMALS = 6

#: the turn from the generators' z-up to OBJ's y-up: (x, y, z) -> (x, z, -y), a rotation
Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def _rounded(truth: GroundTruth) -> GroundTruth:
    soup = truth.soup
    return replace(truth, soup=replace(soup, vertices=np.round(soup.vertices, DECIMALS) + 0.0))


def _y_up(truth: GroundTruth) -> GroundTruth:
    """The model and its hint points turned y-up (exact: the turn only swaps and negates)."""
    soup = truth.soup
    hints = {k: v @ Y_UP.T + 0.0 for k, v in truth.hints.items()}  # + 0.0: no -0.0 in the files
    return replace(
        truth, soup=replace(soup, vertices=soup.vertices @ Y_UP.T + 0.0, up=(0.0, 1.0, 0.0)), hints=hints
    )


def _save(truth: GroundTruth, path: Path) -> None:
    """Write the soup with the project's writer (parts as OBJ ``o`` statements)."""
    try:
        from meshvis.io import save
    except ImportError:  # pragma: no cover - io is part of the package
        save = None
    if save is not None:
        save(truth.soup, path)
        return
    _write_obj_plain(truth, path)  # pragma: no cover


def _write_obj_plain(truth: GroundTruth, path: Path) -> None:  # pragma: no cover - fallback only
    s = truth.soup
    lines = [f"# {truth.name}: {s.n_faces} faces\n"]
    lines += [f"v {x!r} {y!r} {z!r}\n" for x, y, z in s.vertices.tolist()]
    last = -1
    for pid, (a, b, c) in zip(s.part_id.tolist(), (s.faces + 1).tolist()):
        if pid != last:
            lines.append(f"o {s.part_names[pid]}\n")
            last = pid
        lines.append(f"f {a} {b} {c}\n")
    tmp = f"{path}.tmp"
    with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.writelines(lines)
    os.replace(tmp, path)


def _check_round_trip(truth: GroundTruth, path: Path) -> None:
    """Read the file back and make sure face ``i`` of the file is face ``i`` of the truth."""
    try:
        from meshvis.io import load
    except ImportError:  # pragma: no cover
        return
    back = load(path)
    if back.n_faces != truth.n_faces:
        raise RuntimeError(f"{path}: {back.n_faces} faces read back, {truth.n_faces} written")
    if not np.array_equal(back.triangles, truth.soup.triangles):
        raise RuntimeError(f"{path}: triangles read back differ from those written")


def build(out: str | os.PathLike = HERE, names: list[str] | None = None, verbose: bool = False) -> list[Path]:
    """Write the models (all, or ``names``) and their truth files into ``out``.

    Returns the written paths.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for fname, make in MODELS.items():
        if names and fname not in names:
            continue
        truth = _y_up(_rounded(make()))
        problems = truth.check()
        if problems:
            raise RuntimeError(f"{fname}: inconsistent truth: {problems}")
        path = out / fname
        _save(truth, path)
        _check_round_trip(truth, path)
        tpath = out / (Path(fname).stem + ".truth.npz")
        truth.save_arrays(tpath)
        written += [path, tpath]
        if verbose:
            print(
                f"{fname:26s} {truth.n_faces:6d} faces  {path.stat().st_size / 1024:7.1f} KiB  "
                f"layers {np.bincount(truth.layer)[1:].tolist()}"
            )
    return written


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE), help="folder to write into (default: models/)")
    ap.add_argument("names", nargs="*", help="only these files (default: all)")
    args = ap.parse_args(argv)
    paths = build(args.out, args.names or None, verbose=True)
    total = sum(p.stat().st_size for p in paths)
    print(f"{len(paths)} files, {total / 1024:.1f} KiB in {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
