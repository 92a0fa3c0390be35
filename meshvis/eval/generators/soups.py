"""Turn any truth into a messy triangle soup whose truth arrays stay consistent."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from meshvis.errors import ParameterError

from .closed import _welded
from .truth import GroundTruth


def _punch_holes(t: GroundTruth, holes: int, rng: np.random.Generator) -> GroundTruth:
    """Delete ``holes`` random faces and every face sharing a corner position with one."""
    m = t.n_faces
    keys = _welded(t.soup)
    seeds = rng.choice(m, size=min(holes, m), replace=False)
    marked = np.zeros(int(keys.max()) + 1, bool)
    marked[keys[seeds].ravel()] = True
    return t.subset(~marked[keys].any(axis=1))


def _shuffle(t: GroundTruth, rng: np.random.Generator) -> GroundTruth:
    """Shuffle the face order and rotate every face's corners cyclically (keeps the winding)."""
    t = t.subset(rng.permutation(t.n_faces))
    shift = rng.integers(0, 3, t.n_faces)
    order = (np.arange(3)[None, :] + shift[:, None]) % 3  # cyclic: keeps the winding
    rows = np.arange(t.n_faces)[:, None]
    s = t.soup
    return replace(
        t,
        soup=replace(
            s,
            faces=s.faces[rows, order],
            uv=None if s.uv is None else s.uv[rows, order],
            colors=None if s.colors is None else s.colors[rows, order],
        ),
    )


def _unweld(t: GroundTruth) -> GroundTruth:
    """Give every face its own three vertices."""
    s = t.soup
    return replace(
        t,
        soup=replace(
            s,
            vertices=s.triangles.reshape(-1, 3).copy(),
            faces=np.arange(3 * s.n_faces, dtype=np.int64).reshape(-1, 3),
        ),
    )


def soupify(
    truth: GroundTruth,
    flip: float = 0.3,
    unweld: bool = True,
    shuffle: bool = True,
    duplicate: float = 0.0,
    holes: int = 0,
    seed: int = 0,
) -> GroundTruth:
    """Turn a truth into a messy triangle soup whose truth is still known.

    Steps, in this order: punch ``holes`` small holes (a random face and every face sharing
    a corner position with it is deleted); duplicate a fraction ``duplicate`` of the faces
    (exact copies, coplanar with their original); turn over ``round(flip * m)`` random
    faces; shuffle the face order and rotate every face's corners cyclically; give every
    face its own three vertices.

    Truth bookkeeping: a turned face swaps its ``outside`` columns and toggles
    ``outward`` and ``flipped``; ``origin_face`` maps every output face to the input
    face it copies.  Small holes are defects and change no truth; duplicates share their
    original's truth.

    Parameters
    ----------
    truth : GroundTruth
        The model and its truth (not modified).
    flip : float
        Fraction of the faces to turn over, in [0, 1].
    unweld : bool
        Give every face its own three vertices.
    shuffle : bool
        Shuffle the face order and rotate the corners of every face.
    duplicate : float
        Fraction of the faces to store twice, in [0, 1].
    holes : int
        Number of small holes to punch, at least 0.
    seed : int
        Seeds every random choice (holes, duplicates, flips, order).

    Returns
    -------
    GroundTruth
        The soup and its truth, named ``<name>_soup``; the notes list the steps applied.

    Raises
    ------
    ParameterError
        ``flip`` or ``duplicate`` outside [0, 1], or ``holes`` negative.

    Examples
    --------
    >>> from meshvis.eval.generators import nested_shells
    >>> t = soupify(nested_shells(n=2, subdivisions=1), flip=0.5, seed=0)
    >>> t.name, t.n_faces, int(t.flipped.sum()), len(t.soup.vertices)
    ('nested_shells_soup', 160, 80, 480)
    >>> t.check()
    []
    """
    for nm, v in (("flip", flip), ("duplicate", duplicate)):
        if not 0.0 <= v <= 1.0:
            raise ParameterError(f"{nm} must be in [0, 1], got {v}")
    if holes < 0:
        raise ParameterError(f"holes must be >= 0, got {holes}")
    rng = np.random.default_rng(seed)
    t = truth
    if holes and t.n_faces:
        t = _punch_holes(t, int(holes), rng)
    if duplicate:
        k = int(round(duplicate * t.n_faces))
        extra = rng.choice(t.n_faces, size=k, replace=False)
        t = t.subset(np.concatenate([np.arange(t.n_faces), np.sort(extra)]))
    if flip:
        k = int(round(flip * t.n_faces))
        mask = np.zeros(t.n_faces, bool)
        mask[rng.choice(t.n_faces, size=k, replace=False)] = True
        t = t.flip_faces(mask)
    if shuffle:
        t = _shuffle(t, rng)
    if unweld:
        t = _unweld(t)
    bits = (
        [f"flip={flip:g}"]
        + (["unwelded"] if unweld else [])
        + (["shuffled"] if shuffle else [])
        + ([f"duplicate={duplicate:g}"] if duplicate else [])
        + ([f"holes={holes}"] if holes else [])
    )
    return replace(t, name=f"{truth.name}_soup", notes=f"{truth.notes} | soupified: {', '.join(bits)}")
