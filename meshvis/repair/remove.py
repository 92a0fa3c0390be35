"""Inside removal (appendix H §5, "Inside Removal").

One classification; every face with an outside side — or, for faces classified through
sample points, at least one outside sample point — is kept, the rest is removed.  Of a
sheet stored twice with opposite winding (:mod:`meshvis.geometry.duplicates`) whose one
side is hidden, only the copy facing the seen side is kept.
Every input face ends up in exactly one of the two outputs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis import _validate
from meshvis.geometry.duplicates import hidden_copies, opposite_copies
from meshvis.graphcut.classify import Classification, classify
from meshvis.soup import Soup


@dataclass
class RemovalResult:
    """Result of :func:`remove_interior`.

    Attributes
    ----------
    kept, removed : Soup, the faces kept and removed (attributes preserved)
    keep : (m,) bool per input face
    """

    kept: Soup
    removed: Soup
    keep: np.ndarray
    classification: Classification

    def report(self, per_face: bool = True) -> dict:
        d = {
            "input_faces": int(len(self.keep)),
            "kept_faces": int(self.keep.sum()),
            "removed_faces": int((~self.keep).sum()),
            "removed_area_fraction": float(
                (self.classification.soup.areas * ~self.keep).sum()
                / max(self.classification.soup.total_area, 1e-300)
            ),
            "classification": self.classification.report(per_face=False),
        }
        if per_face:
            d["per_face"] = {
                "keep": self.keep,
                "outside_front": self.classification.outside[:, 0],
                "outside_back": self.classification.outside[:, 1],
            }
        return d


def remove_interior(
    model: Any, *, classification: Classification | None = None, **classify_kw: Any
) -> RemovalResult:
    """Remove the faces that cannot be seen from outside.

    Parameters
    ----------
    model : anything :func:`meshvis.classify` accepts
    classification : reuse an existing classification of the same model
    **classify_kw : passed to :func:`meshvis.classify` (``seed``, ``rays_per_node``, ...)

    Returns
    -------
    RemovalResult

    Examples
    --------
    >>> import trimesh, numpy as np
    >>> a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(2)
    >>> v = np.vstack([a.vertices, 0.5 * b.vertices]); f = np.vstack([a.faces, b.faces + len(a.vertices)])
    >>> r = remove_interior((v, f), seed=0)
    >>> r.kept.n_faces, r.removed.n_faces
    (320, 320)
    """
    _validate.repair_args(classification, Classification, classify_kw, classify)
    c = classification or classify(model, **classify_kw)
    keep = (c.outside > 0).any(axis=1)
    # a sheet stored twice with opposite winding keeps only the copy facing the viewer
    # where its other side is hidden
    keep &= ~hidden_copies(opposite_copies(c.pre.faces_welded), c.outside)
    return RemovalResult(c.soup.subset(keep), c.soup.subset(~keep), keep, c)
