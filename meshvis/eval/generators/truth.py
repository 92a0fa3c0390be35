"""The truth container: a model with its known inside/outside, layers and orientation."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from meshvis.errors import ModelError
from meshvis.soup import Soup


@dataclass(eq=False)
class GroundTruth:
    """A model together with its known inside/outside, layer and orientation answer.

    Parameters
    ----------
    soup : Soup
        The geometry, with meaningful ``part_names`` / ``part_id``.
    outside : (m, 2) bool
        ``outside[f, s]``: side ``s`` of face ``f`` is outside (side 0 = front).
    layer : (m,) int
        Layer index under layer semantics (1 = outer shell).
    outward : (m,) bool
        The front side is the side facing outward with respect to the face's layer.
    two_sided : (m,) bool, optional
        Sheets meant to be seen from both sides; default all False.
    ambiguous : (m,) bool, optional
        Faces to leave out of error measures; default all False.
    hints : dict, optional
        ``inside_points`` / ``outside_points``: (k, 3) float64 user hints the model needs.
    name, notes : str
        What the model is and what it tests.
    origin_face : (m,) int, optional
        Index of the face in the generator's original model (changed by :func:`soupify`);
        default ``arange(m)``.
    flipped : (m,) bool, optional
        The face is turned over with respect to ``origin_face``; default all False.
    """

    soup: Soup
    outside: np.ndarray
    layer: np.ndarray
    outward: np.ndarray
    two_sided: np.ndarray | None = None
    ambiguous: np.ndarray | None = None
    hints: dict = field(default_factory=dict)
    name: str = ""
    notes: str = ""
    origin_face: np.ndarray | None = None
    flipped: np.ndarray | None = None

    def __post_init__(self) -> None:
        """Broadcast the truth arrays to their per-face shapes and fill in the defaults."""
        m = self.soup.n_faces
        self.outside = np.array(np.broadcast_to(np.asarray(self.outside, bool), (m, 2)))
        self.layer = np.array(np.broadcast_to(np.asarray(self.layer, np.int64), (m,)))
        self.outward = np.array(np.broadcast_to(np.asarray(self.outward, bool), (m,)))
        self.two_sided = (
            np.zeros(m, bool)
            if self.two_sided is None
            else np.array(np.broadcast_to(np.asarray(self.two_sided, bool), (m,)))
        )
        self.ambiguous = (
            np.zeros(m, bool)
            if self.ambiguous is None
            else np.array(np.broadcast_to(np.asarray(self.ambiguous, bool), (m,)))
        )
        self.origin_face = (
            np.arange(m, dtype=np.int64)
            if self.origin_face is None
            else np.asarray(self.origin_face, np.int64).reshape(m)
        )
        self.flipped = (
            np.zeros(m, bool) if self.flipped is None else np.asarray(self.flipped, bool).reshape(m)
        )
        self.hints = {k: np.asarray(v, np.float64).reshape(-1, 3) for k, v in self.hints.items()}

    # ------------------------------------------------------------------ views
    @property
    def n_faces(self) -> int:
        """Number of faces of the model."""
        return self.soup.n_faces

    @property
    def hidden(self) -> np.ndarray:
        """(m,) bool: no side of the face is outside."""
        return ~self.outside.any(axis=1)

    @property
    def visible(self) -> np.ndarray:
        """(m,) bool: at least one side of the face is outside."""
        return self.outside.any(axis=1)

    @property
    def n_layers(self) -> int:
        """Deepest layer (0 for a model without faces)."""
        return int(self.layer.max()) if self.n_faces else 0

    def check(self) -> list[str]:
        """List the broken invariants (empty when the truth is self-consistent).

        Invariants: layers start at 1; layer 1 holds exactly the faces with an outside
        side; a visible one-sided face has exactly one outside side, the outward one; a
        visible two-sided face has both sides outside.

        Returns
        -------
        list of str
            One message per broken invariant.
        """
        problems = []
        if self.n_faces and self.layer.min() < 1:
            problems.append("layer below 1")
        if np.any((self.layer == 1) != self.visible):
            problems.append("layer 1 is not the set of faces with an outside side")
        one = self.visible & ~self.two_sided
        if np.any(self.outside[one, 0] != self.outward[one]) or np.any(
            self.outside[one, 1] == self.outward[one]
        ):
            problems.append("a visible one-sided face's outside side is not its outward side")
        two = self.visible & self.two_sided
        if np.any(~self.outside[two].all(axis=1)):
            problems.append("a visible two-sided face has an inside side")
        return problems

    # ------------------------------------------------------------------ derived truths
    def subset(self, index: np.ndarray) -> GroundTruth:
        """Take the truth of the faces ``index``.

        Parameters
        ----------
        index : (m,) bool or (k,) int
            A face mask, or face indices (repeats allowed).

        Returns
        -------
        GroundTruth
            The chosen faces with their truth; ``origin_face`` and ``flipped`` follow them, the
            hints are kept.
        """
        index = np.asarray(index)
        if index.dtype == bool:
            index = np.flatnonzero(index)
        return replace(
            self,
            soup=self.soup.subset(index),
            outside=self.outside[index],
            layer=self.layer[index],
            outward=self.outward[index],
            two_sided=self.two_sided[index],
            ambiguous=self.ambiguous[index],
            origin_face=self.origin_face[index],
            flipped=self.flipped[index],
            hints=dict(self.hints),
        )

    def flip_faces(self, flip: np.ndarray) -> GroundTruth:
        """Turn over the faces where ``flip`` is True.

        Turning a face over swaps its sides, so the two ``outside`` columns swap and
        ``outward`` toggles (and so does ``flipped``).

        Parameters
        ----------
        flip : (m,) bool
            The faces to turn over.

        Returns
        -------
        GroundTruth
            A new truth; this one is not modified.
        """
        flip = np.asarray(flip, bool).reshape(self.n_faces)
        return replace(
            self,
            soup=self.soup.flipped(flip),
            outside=np.where(flip[:, None], self.outside[:, ::-1], self.outside),
            outward=self.outward ^ flip,
            flipped=self.flipped ^ flip,
            two_sided=self.two_sided.copy(),
            ambiguous=self.ambiguous.copy(),
            layer=self.layer.copy(),
            origin_face=self.origin_face.copy(),
            hints=dict(self.hints),
        )

    def oriented(self) -> Soup:
        """Turn every face so that its front faces outward (the ideal output of normal orientation).

        Returns
        -------
        Soup
            The model with the faces whose ``outward`` is False turned over.
        """
        return self.soup.flipped(~self.outward)

    @classmethod
    def concatenate(cls, truths: Sequence[GroundTruth], name: str = "", notes: str = "") -> GroundTruth:
        """Join several truths into one (parts are kept apart, hints are merged).

        Parameters
        ----------
        truths : sequence of GroundTruth
            The truths, in order.
        name : str
            Name of the result; default the names joined by ``+``.
        notes : str
            What the joined model tests.

        Returns
        -------
        GroundTruth
            The faces of all truths in order; ``origin_face`` is offset by the faces before.
        """
        truths = list(truths)
        offsets = np.cumsum([0] + [t.n_faces for t in truths[:-1]])
        hints: dict[str, list] = {}
        for t in truths:
            for k, v in t.hints.items():
                hints.setdefault(k, []).append(v)
        return cls(
            soup=Soup.concatenate([t.soup for t in truths]),
            outside=np.concatenate([t.outside for t in truths]),
            layer=np.concatenate([t.layer for t in truths]),
            outward=np.concatenate([t.outward for t in truths]),
            two_sided=np.concatenate([t.two_sided for t in truths]),
            ambiguous=np.concatenate([t.ambiguous for t in truths]),
            hints={k: np.concatenate(v) for k, v in hints.items()},
            name=name or "+".join(t.name for t in truths),
            notes=notes,
            origin_face=np.concatenate([t.origin_face + o for t, o in zip(truths, offsets)]),
            flipped=np.concatenate([t.flipped for t in truths]),
        )

    # ------------------------------------------------------------------ files
    def save_arrays(self, path: str | os.PathLike) -> None:
        """Write the truth arrays (not the geometry) to a compressed ``.npz`` file.

        The arrays are indexed like the soup's faces; pair the file with the model file
        written from the same soup (faces in the same order).  Identical truths give identical
        files, and the file appears only once complete.

        Parameters
        ----------
        path : str or os.PathLike
            The ``.npz`` file to write.
        """
        arrays = dict(
            outside=self.outside,
            layer=self.layer,
            outward=self.outward,
            two_sided=self.two_sided,
            ambiguous=self.ambiguous,
            origin_face=self.origin_face,
            flipped=self.flipped,
            part_id=self.soup.part_id,
            part_names=np.array(self.soup.part_names),
            name=np.array(self.name),
            notes=np.array(self.notes),
        )
        for k, v in self.hints.items():
            arrays[f"hint_{k}"] = v
        _write_npz(os.fspath(path), arrays)

    @classmethod
    def load_arrays(cls, path: str | os.PathLike, soup: Soup) -> GroundTruth:
        """Pair truth arrays written by :meth:`save_arrays` with a soup loaded from the model file.

        Parameters
        ----------
        path : str or os.PathLike
            The ``.npz`` file.
        soup : Soup
            The model, faces in the order the arrays were written in.

        Returns
        -------
        GroundTruth
            The truth of ``soup``.

        Raises
        ------
        ModelError
            The file holds the truth of another number of faces.
        FileNotFoundError
            The file does not exist.
        """
        with np.load(os.fspath(path), allow_pickle=False) as z:
            if len(z["layer"]) != soup.n_faces:
                raise ModelError(
                    f"truth has {len(z['layer'])} faces but the model has {soup.n_faces}", os.fspath(path)
                )
            hints = {k[5:]: z[k] for k in z.files if k.startswith("hint_")}
            return cls(
                soup=soup,
                outside=z["outside"],
                layer=z["layer"],
                outward=z["outward"],
                two_sided=z["two_sided"],
                ambiguous=z["ambiguous"],
                hints=hints,
                name=str(z["name"]),
                notes=str(z["notes"]),
                origin_face=z["origin_face"],
                flipped=z["flipped"],
            )

    def __repr__(self) -> str:
        """Show the name and the counts of faces, visible faces, layers and parts on one line."""
        return (
            f"<GroundTruth {self.name!r}: {self.n_faces} faces, {int(self.visible.sum())} visible, "
            f"{self.n_layers} layers, {self.soup.n_parts} parts>"
        )


def _write_npz(path: str, arrays: dict[str, np.ndarray]) -> None:
    """Write a compressed ``.npz`` that is identical byte for byte for identical arrays.

    ``numpy.savez_compressed`` stamps every member with the current time; here every
    member gets a fixed date.  Written to a temporary file, then renamed.
    """
    import io
    import zipfile

    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
            for key in sorted(arrays):
                buf = io.BytesIO()
                np.lib.format.write_array(buf, np.asarray(arrays[key]), allow_pickle=False)
                info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16
                zf.writestr(info, buf.getvalue())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
