"""Error measures of orientation, inside removal and layers against a known answer.

Every measure takes a :class:`~meshvis.eval.generators.GroundTruth` and a per-input-face result
(from meshvis or from a baseline) and returns numbers in [0, 1].  Faces marked
``ambiguous`` in the truth (their answer depends on a convention) are left out, and every
measure is weighted by triangle area, so that a fine tessellation of one region does not
outweigh a coarse one (DESIGN.md §7).

Notation: ``A_f`` area of face ``f``, ``E`` the evaluated faces (not ambiguous),
``A(S) = Σ_{f ∈ S ∩ E} A_f``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.errors import ParameterError
from meshvis.eval.generators import GroundTruth

__all__ = [
    "orientation_error",
    "removal_scores",
    "RemovalScores",
    "layer_accuracy",
    "layer_error",
]


def _per_face(name: str, values: np.ndarray, truth: GroundTruth, dtype) -> np.ndarray:
    a = np.asarray(values)
    if a.shape != (truth.n_faces,):
        raise ParameterError(f"{name} must have one entry per face ({truth.n_faces}), got shape {a.shape}")
    return a.astype(dtype, copy=False)


def _mask(truth: GroundTruth, where: np.ndarray | None) -> np.ndarray:
    """Evaluated faces: not ambiguous, and inside ``where`` when given."""
    keep = ~truth.ambiguous
    if where is not None:
        keep = keep & _per_face("where", where, truth, bool)
    return keep


def _fraction(num: float, den: float, empty: float) -> float:
    """``num / den``, or ``empty`` when nothing is evaluated (den is zero)."""
    return float(num / den) if den > 0 else float(empty)


def orientation_error(truth: GroundTruth, flipped: np.ndarray, *, where: np.ndarray | None = None) -> float:
    """Area-weighted fraction of misoriented faces after turning over the ``flipped`` faces.

    A face ends up facing outward when ``outward XOR flipped`` holds (``truth.outward``
    says whether the input front faces outward with respect to the face's layer).
    Two-sided faces (``truth.two_sided``) are correct in either orientation.

    ``error = A(wrong) / A(evaluated)`` with ``wrong = ¬(outward ⊕ flipped) ∧ ¬two_sided``.

    Parameters
    ----------
    truth : GroundTruth
    flipped : (m,) bool, the faces a method turned over (e.g. ``OrientResult.flipped``)
    where : (m,) bool, optional, evaluate only these faces (e.g. ``truth.layer >= 2`` for
        hidden shells)

    Returns
    -------
    float in [0, 1]; 0.0 when no face is evaluated
    """
    flipped = _per_face("flipped", flipped, truth, bool)
    ev = _mask(truth, where)
    wrong = ~(truth.outward ^ flipped) & ~truth.two_sided
    a = truth.soup.areas
    return _fraction(a[ev & wrong].sum(), a[ev].sum(), 0.0)


@dataclass(frozen=True)
class RemovalScores:
    """Area-weighted scores of an inside removal.

    Attributes
    ----------
    precision : A(removed ∩ hidden) / A(removed); 1.0 when nothing was removed
    recall : A(removed ∩ hidden) / A(hidden); 1.0 when nothing is hidden
    error : A(removed ⊕ hidden) / A(evaluated): area decided wrongly, either way
    """

    precision: float
    recall: float
    error: float


def removal_scores(truth: GroundTruth, keep: np.ndarray, *, where: np.ndarray | None = None) -> RemovalScores:
    """Precision, recall and error of the removed faces (``~keep``) against ``truth.hidden``.

    The truth of removal: a face must go exactly when no side of it is outside
    (``truth.hidden``).  See :class:`RemovalScores` for the formulas.

    Parameters
    ----------
    truth : GroundTruth
    keep : (m,) bool, the faces a method kept (e.g. ``RemovalResult.keep``)
    where : (m,) bool, optional, evaluate only these faces

    Returns
    -------
    RemovalScores
    """
    removed = ~_per_face("keep", keep, truth, bool)
    ev = _mask(truth, where)
    hidden = truth.hidden
    a = truth.soup.areas
    both = a[ev & removed & hidden].sum()
    return RemovalScores(
        precision=_fraction(both, a[ev & removed].sum(), 1.0),
        recall=_fraction(both, a[ev & hidden].sum(), 1.0),
        error=_fraction(a[ev & (removed != hidden)].sum(), a[ev].sum(), 0.0),
    )


def layer_accuracy(truth: GroundTruth, layer: np.ndarray, *, where: np.ndarray | None = None) -> float:
    """Area-weighted fraction of faces whose layer index equals the truth's.

    ``accuracy = A(layer = truth.layer) / A(evaluated)``; 1.0 when no face is evaluated.

    Parameters
    ----------
    truth : GroundTruth
    layer : (m,) int, layer per face (1 = outer), e.g. ``LayerResult.layer``
    where : (m,) bool, optional, evaluate only these faces
    """
    layer = _per_face("layer", layer, truth, np.int64)
    ev = _mask(truth, where)
    a = truth.soup.areas
    return _fraction(a[ev & (layer == truth.layer)].sum(), a[ev].sum(), 1.0)


def layer_error(truth: GroundTruth, layer: np.ndarray, *, where: np.ndarray | None = None) -> float:
    """``1 - layer_accuracy``: the area-weighted fraction of faces in the wrong layer."""
    return 1.0 - layer_accuracy(truth, layer, where=where)
