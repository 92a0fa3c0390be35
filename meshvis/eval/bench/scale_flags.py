"""Face-by-face check that the intersection flags of one checkout contain those of another.

The flags of appendix H §2 must stay conservative when their code changes: every face
flagged before must still be flagged.  Run ``snapshot`` with the Python of the old checkout
and ``compare`` with the new one (the file runs under any checkout's ``meshvis``)::

    /old/venv/bin/python meshvis/eval/bench/scale_flags.py snapshot /tmp/flags ../shared/models/real ../shared/models/real2
    /new/venv/bin/python meshvis/eval/bench/scale_flags.py compare /tmp/flags

``compare`` prints one line per model with the faces that lost (``-``) or gained (``+``)
each flag, and exits with status 1 when any face lost one.  ``snapshot --labels`` also
stores the labels of ``classify(model, seed=0)``; ``compare`` then reports the faces whose
labels differ (``labels =`` when none does).  The folder name ``accuracy`` stands for the
soups of the accuracy benchmark (:data:`meshvis.eval.bench.cases.CASES`, built from the real
models' folder ``../shared/models/real``), stored as ``case:<name>``.
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

import numpy as np

#: the per-face flags compared
FLAGS = ("intersects", "coplanar", "too_close")


def model_files(folders: list[str]) -> list[Path]:
    """The model files of the folders (every file but Markdown), sorted by name."""
    return sorted(
        (p for f in folders for p in Path(f).iterdir() if p.is_file() and p.suffix.lower() != ".md"),
        key=lambda p: p.name,
    )


#: the folder name that stands for the accuracy benchmark's cases
ACCURACY = "accuracy"


def model_specs(folders: list[str]) -> list[tuple[str, str]]:
    """(name, spec) of every model: a file path, or ``case:<name>`` for an accuracy case."""
    from meshvis.eval.bench.cases import CASES

    files = model_files([f for f in folders if f != ACCURACY])
    cases = [(f"case_{n}", f"case:{n}") for n in CASES] if ACCURACY in folders else []
    return [(p.name, str(p)) for p in files] + cases


def load_spec(spec: str):
    """The soup of a spec of :func:`model_specs` (an accuracy case built on its seed)."""
    from meshvis.eval.bench.cases import CASES, load_case
    from meshvis.io import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if spec.startswith("case:"):
            truth, note = load_case(CASES[spec[5:]])  # real cases from DEFAULT_MODELS
            if truth is None:
                raise FileNotFoundError(note)
            return truth.soup
        return load(spec)


def snapshot(out: str, folders: list[str], labels: bool = False) -> None:
    """Write the flags (and the labels) of every model of ``folders`` to ``out/<name>.npz``."""
    from meshvis.geometry.intersect import intersection_flags
    from meshvis.graphcut.classify import classify

    os.makedirs(out, exist_ok=True)
    for name, spec in model_specs(folders):
        soup = load_spec(spec)
        flags = intersection_flags(soup.vertices, soup.faces)
        extra = {"outside": classify(soup, seed=0).outside} if labels else {}
        np.savez_compressed(
            os.path.join(out, name + ".npz"), path=spec, **{k: flags[k] for k in FLAGS}, **extra
        )
        print(name, soup.n_faces, *(int(flags[k].sum()) for k in FLAGS), flush=True)


def compare(folder: str) -> int:
    """Compare the flags of this checkout with a snapshot; 1 when a face lost a flag."""
    from meshvis.geometry.intersect import intersection_flags
    from meshvis.graphcut.classify import classify

    lost_any = False
    for snap in sorted(Path(folder).glob("*.npz")):
        old = np.load(snap)
        soup = load_spec(str(old["path"]))
        new = intersection_flags(soup.vertices, soup.faces)
        cells = []
        for k in FLAGS:
            lost = int((old[k] & ~new[k]).sum())
            gained = int((new[k] & ~old[k]).sum())
            lost_any |= lost > 0
            cells.append(f"{k} -{lost} +{gained}")
        if "outside" in old.files:
            differ = int(np.any(classify(soup, seed=0).outside != old["outside"], axis=1).sum())
            cells.append(f"labels {'=' if differ == 0 else f'differ on {differ} faces'}")
        print(snap.name[:-4], soup.n_faces, *cells, flush=True)
    return int(lost_any)


def main(argv: list[str]) -> int:
    """``snapshot [--labels] OUT FOLDER...`` or ``compare SNAPSHOT``."""
    labels = "--labels" in argv
    argv = [a for a in argv if a != "--labels"]
    if len(argv) >= 3 and argv[0] == "snapshot":
        snapshot(argv[1], argv[2:], labels)
        return 0
    if len(argv) == 2 and argv[0] == "compare":
        return compare(argv[1])
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
