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
    """Select the evaluated faces: not ambiguous, and inside ``where`` when given."""
    keep = ~truth.ambiguous
    if where is not None:
        keep = keep & _per_face("where", where, truth, bool)
    return keep


def _fraction(num: float, den: float, empty: float) -> float:
    """Divide ``num`` by ``den``, or give ``empty`` when nothing is evaluated (``den`` is zero)."""
    return float(num / den) if den > 0 else float(empty)


def orientation_error(truth: GroundTruth, flipped: np.ndarray, *, where: np.ndarray | None = None) -> float:
    """Measure the area-weighted fraction of misoriented faces after turning over the ``flipped`` faces.

    A face ends up facing outward when ``outward XOR flipped`` holds (``truth.outward``
    says whether the input front faces outward with respect to the face's layer).
    Two-sided faces (``truth.two_sided``) are correct in either orientation.

    ``error = A(wrong) / A(evaluated)`` with ``wrong = ¬(outward ⊕ flipped) ∧ ¬two_sided``.

    Parameters
    ----------
    truth : GroundTruth
        The model's known answer.
    flipped : (m,) bool
        The faces a method turned over (e.g. ``OrientResult.flipped``).
    where : (m,) bool, optional
        Evaluate only these faces (e.g. ``truth.layer >= 2`` for hidden shells).

    Returns
    -------
    float
        The error in [0, 1]; 0.0 when no face is evaluated.

    Raises
    ------
    ParameterError
        ``flipped`` or ``where`` does not have one entry per face.

    Examples
    --------
    >>> import numpy as np
    >>> from meshvis.eval.generators import nested_shells
    >>> t = nested_shells(n=2, subdivisions=1)
    >>> orientation_error(t, np.zeros(t.n_faces, bool)), orientation_error(t, np.ones(t.n_faces, bool))
    (0.0, 1.0)
    >>> orientation_error(t, t.layer == 2, where=t.layer == 1)
    0.0
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
    precision : float
        A(removed ∩ hidden) / A(removed); 1.0 when nothing was removed.
    recall : float
        A(removed ∩ hidden) / A(hidden); 1.0 when nothing is hidden.
    error : float
        A(removed ⊕ hidden) / A(evaluated): the area decided wrongly, either way.
    """

    precision: float
    recall: float
    error: float


def removal_scores(truth: GroundTruth, keep: np.ndarray, *, where: np.ndarray | None = None) -> RemovalScores:
    """Score the removed faces (``~keep``) against ``truth.hidden``: precision, recall and error.

    The truth of removal: a face must go exactly when no side of it is outside
    (``truth.hidden``).  See :class:`RemovalScores` for the formulas.

    Parameters
    ----------
    truth : GroundTruth
        The model's known answer.
    keep : (m,) bool
        The faces a method kept (e.g. ``RemovalResult.keep``).
    where : (m,) bool, optional
        Evaluate only these faces.

    Returns
    -------
    RemovalScores
        Precision, recall and error, each in [0, 1].

    Raises
    ------
    ParameterError
        ``keep`` or ``where`` does not have one entry per face.

    Examples
    --------
    >>> import numpy as np
    >>> from meshvis.eval.generators import nested_shells
    >>> t = nested_shells(n=2, subdivisions=1)
    >>> removal_scores(t, t.visible)
    RemovalScores(precision=1.0, recall=1.0, error=0.0)
    >>> s = removal_scores(t, np.ones(t.n_faces, bool))  # nothing removed: the inner shell's area is wrong
    >>> s.precision, s.recall, round(s.error, 3)
    (1.0, 0.0, 0.109)
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
    """Measure the area-weighted fraction of faces whose layer index equals the truth's.

    ``accuracy = A(layer = truth.layer) / A(evaluated)``.

    Parameters
    ----------
    truth : GroundTruth
        The model's known answer.
    layer : (m,) int
        Layer per face (1 = outer), e.g. ``LayerResult.layer``.
    where : (m,) bool, optional
        Evaluate only these faces.

    Returns
    -------
    float
        The accuracy in [0, 1]; 1.0 when no face is evaluated.

    Raises
    ------
    ParameterError
        ``layer`` or ``where`` does not have one entry per face.

    Examples
    --------
    >>> import numpy as np
    >>> from meshvis.eval.generators import nested_shells
    >>> t = nested_shells(n=2, subdivisions=1)
    >>> layer_accuracy(t, t.layer), round(layer_accuracy(t, np.ones(t.n_faces, int)), 3)
    (1.0, 0.891)
    """
    layer = _per_face("layer", layer, truth, np.int64)
    ev = _mask(truth, where)
    a = truth.soup.areas
    return _fraction(a[ev & (layer == truth.layer)].sum(), a[ev].sum(), 1.0)


def layer_error(truth: GroundTruth, layer: np.ndarray, *, where: np.ndarray | None = None) -> float:
    """Measure the area-weighted fraction of faces in the wrong layer: ``1 - layer_accuracy``.

    Parameters
    ----------
    truth : GroundTruth
        The model's known answer.
    layer : (m,) int
        Layer per face (1 = outer), e.g. ``LayerResult.layer``.
    where : (m,) bool, optional
        Evaluate only these faces.

    Returns
    -------
    float
        The error in [0, 1]; 0.0 when no face is evaluated.

    Raises
    ------
    ParameterError
        ``layer`` or ``where`` does not have one entry per face.

    Examples
    --------
    >>> import numpy as np
    >>> from meshvis.eval.generators import nested_shells
    >>> t = nested_shells(n=2, subdivisions=1)
    >>> round(layer_error(t, np.ones(t.n_faces, int)), 3)
    0.109
    """
    return 1.0 - layer_accuracy(truth, layer, where=where)
