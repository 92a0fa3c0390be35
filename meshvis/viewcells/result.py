"""The PVS of every view cell: the result of :func:`meshvis.viewcells.pvs`, and its file.

The file is a NumPy ``.npz``: the view space and the cells' kD-tree, the PVS compressed by
the hierarchy (each tree node stores what every cell below it sees and its parent does not
store, 002 §5.2), the named parts each cell sees, which sides of the faces were seen, the
model's face count and a hash of its geometry (a PVS is only read back with the model it
was made for), and the run's summary as JSON.

>>> import trimesh
>>> from meshvis.viewcells import pvs
>>> result = pvs(trimesh.creation.box(), "grid:1,1,1", view_space="box:-2,-2,-2,2,2,2", budget=20000)
>>> result.sizes().tolist()
[12]
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field

import numpy as np

from meshvis.errors import ModelError, ParameterError
from meshvis.viewcells import _kernels
from meshvis.viewcells.cells import ViewCells

#: format of the PVS file
FILE_VERSION = 1


def model_key(soup) -> str:
    """A hash of the model's vertices and faces (which faces the ids of a PVS name)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(soup.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(soup.faces, np.int64).tobytes())
    return h.hexdigest()


@dataclass
class PVS:
    """Potentially visible sets of the view cells of a model.

    Attributes
    ----------
    cells : ViewCells
        The view cells (the leaves of a kD-tree over the view space).
    bits : (k, w) uint64
        The PVS of each cell as a bit set over face ids (face ``f`` is bit ``f % 64`` of
        word ``f // 64``).
    n_faces : int
        Faces of the model.
    part_id : (m,) int64 or None
        The named part of each face (None when the model has none or the file was read
        without its model).
    part_names : list of str
        The model's named parts (a file read without its model knows only the parts each
        cell sees, :attr:`cell_parts`).
    sides : (m,) uint8
        Bit 0: a sample saw the face's front, bit 1: its back.
    key : str
        :func:`model_key` of the model.
    summary : dict
        The run: rays and contributions per distribution, the history of mean PVS size and
        estimated pixel error, why it stopped, what was left out (:meth:`report`).
    log : tuple of (cell, face, batch) arrays, optional
        Every sampled entry with the batch that found it (runs only, not files).
    batches : dict, optional
        ``seconds``, ``cpu_seconds`` (of the whole process) and ``rays`` at the end of each
        batch (runs only).
    """

    cells: ViewCells
    bits: np.ndarray
    n_faces: int
    part_id: np.ndarray | None
    part_names: list[str]
    sides: np.ndarray
    key: str
    summary: dict = field(default_factory=dict)
    log: tuple | None = field(default=None, repr=False)
    batches: dict | None = field(default=None, repr=False)
    cell_parts: list | None = field(default=None, repr=False)

    # ------------------------------------------------------------------ queries
    def sizes(self) -> np.ndarray:
        """(k,) number of faces in each cell's PVS."""
        return _kernels.count_rows(self.bits)

    def faces(self, cell: int) -> np.ndarray:
        """Ascending face ids of the PVS of ``cell``."""
        if not 0 <= int(cell) < self.cells.n_cells:
            raise ParameterError(f"cell must be in 0..{self.cells.n_cells - 1}, got {cell}")
        _, faces = _kernels.unpack_rows(self.bits[int(cell) : int(cell) + 1], self.n_faces)
        return faces

    def matrix(self, bits: np.ndarray | None = None) -> np.ndarray:
        """(k, m) bool: face f is in the PVS of cell c (of ``bits``, default the result's)."""
        b = self.bits if bits is None else bits
        m = np.unpackbits(b.view(np.uint8), axis=1, bitorder="little")
        return m[:, : self.n_faces].astype(bool)

    def part_ids(self, cell: int) -> np.ndarray:
        """Ascending indices into :attr:`part_names` of the parts with a face in the PVS of ``cell``."""
        if self.part_id is None:
            assert self.cell_parts is not None
            return self.cell_parts[int(cell)]
        return np.unique(self.part_id[self.faces(cell)])

    def parts(self, cell: int) -> list[str]:
        """The named parts with a face in the PVS of ``cell``."""
        return [self.part_names[i] for i in self.part_ids(cell)]

    @property
    def seen(self) -> np.ndarray:
        """(m,) bool: in the PVS of some cell."""
        return (
            np.bitwise_or.reduce(self.matrix(), axis=0)
            if self.cells.n_cells
            else np.zeros(self.n_faces, bool)
        )

    def expected_cost(self, bits: np.ndarray | None = None) -> float:
        """Σ P(cell)·|PVS(cell)| (002 Eq. 1 with one unit per face): the faces rendered on average."""
        sizes = self.sizes() if bits is None else _kernels.count_rows(bits)
        return float(self.cells.volume @ sizes)

    def bits_at(self, batch: int) -> np.ndarray:
        """The PVS bit set as it was at the end of ``batch`` (runs only: rebuilt from the log)."""
        if self.log is None:
            raise ParameterError("the PVS history is kept by runs only, not by files")
        cell, face, when = self.log
        out = np.zeros_like(self.bits)
        pick = when <= batch
        c, f = cell[pick].astype(np.int64), face[pick].astype(np.int64)
        np.bitwise_or.at(out, (c, f >> 6), np.left_shift(np.uint64(1), (f & 63).astype(np.uint64)))
        return out

    # ------------------------------------------------------------------ report and file
    def report(self) -> dict:
        """JSON-ready summary: cells, PVS sizes, rays, convergence, what was left out."""
        sizes = self.sizes()
        seen = self.seen
        return {
            "faces": self.n_faces,
            "cells": self.cells.describe(),
            "view_space": self.cells.view_space.describe(),
            "pvs_size": {
                "mean": float(sizes.mean()) if len(sizes) else 0.0,
                "max": int(sizes.max()) if len(sizes) else 0,
                "per_cell": sizes.tolist(),
                "expected_render_cost": self.expected_cost(),
            },
            "faces_no_cell_sees": int((~seen).sum()),
            **self.summary,
        }

    def save(self, path: str | os.PathLike) -> None:
        """Write the PVS file (atomically)."""
        from meshvis.io import atomic_write

        stored = self.cells.compress(self.bits)
        ptr, faces = _kernels.unpack_rows(stored, self.n_faces)
        parts = [self.part_ids(c) for c in range(self.cells.n_cells)]
        part_ptr = np.concatenate([[0], np.cumsum([len(p) for p in parts])]).astype(np.int64)
        data = {
            "version": np.array(FILE_VERSION),
            "n_faces": np.array(self.n_faces),
            "key": np.array(self.key),
            "node_ptr": ptr,
            "node_faces": faces.astype(np.int32),
            "sides": self.sides,
            "part_names": np.array(self.part_names, dtype=str),
            "cell_part_ptr": part_ptr,
            "cell_parts": np.concatenate(parts).astype(np.int32) if parts else np.zeros(0, np.int32),
            "summary": np.array(json.dumps(_plain(self.summary))),
            **self.cells.arrays(),
        }
        with atomic_write(path, "wb") as fh:
            np.savez_compressed(fh, **data)

    @classmethod
    def load(cls, path: str | os.PathLike, model=None) -> PVS:
        """Read a PVS file; with ``model``, check that it was made for that model.

        Raises
        ------
        ModelError
            Not a PVS file, or made for another model.
        """
        path = os.fspath(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                d = {k: data[k] for k in data.files}
        except (OSError, ValueError, EOFError) as exc:
            raise ModelError(f"not a PVS file ({exc})", path) from None
        if "version" not in d or int(d["version"]) != FILE_VERSION or "node_ptr" not in d:
            raise ModelError("not a PVS file of this meshvis version", path)
        try:
            cells = ViewCells.from_arrays(d)
        except ParameterError as exc:
            raise ModelError(f"broken view cells ({exc})", path) from None
        n = int(d["n_faces"])
        ptr, faces = d["node_ptr"].astype(np.int64), d["node_faces"].astype(np.int64)
        if len(ptr) != len(cells.axis) + 1 or (len(faces) and (faces.min() < 0 or faces.max() >= n)):
            raise ModelError("broken PVS (node lists do not fit the tree or the faces)", path)
        w = max(1, -(-n // 64))
        stored = np.zeros((len(cells.axis), w), np.uint64)
        node = np.repeat(np.arange(len(cells.axis)), np.diff(ptr))
        np.bitwise_or.at(
            stored, (node, faces >> 6), np.left_shift(np.uint64(1), (faces & 63).astype(np.uint64))
        )
        names = [str(x) for x in d["part_names"]]
        pp, pc = d["cell_part_ptr"].astype(np.int64), d["cell_parts"].astype(np.int64)
        if len(pp) != cells.n_cells + 1 or (len(pc) and (pc.min() < 0 or pc.max() >= len(names))):
            raise ModelError("broken PVS (part lists do not fit the cells or the names)", path)
        part_id = None
        if model is not None:
            from meshvis.io import as_soup

            soup = as_soup(model)
            if soup.n_faces != n or model_key(soup) != str(d["key"]):
                raise ModelError(
                    f"the PVS was made for another model ({n} faces; this one has {soup.n_faces})", path
                )
            part_id = soup.part_id
        return cls(
            cells=cells,
            bits=cells.expand(stored),
            n_faces=n,
            part_id=part_id,
            part_names=names,
            sides=np.asarray(d["sides"], np.uint8),
            key=str(d["key"]),
            summary=json.loads(str(d["summary"])),
            cell_parts=[pc[pp[c] : pp[c + 1]] for c in range(cells.n_cells)],
        )


def _plain(obj):
    """``obj`` with numpy scalars and arrays as Python numbers and lists (for JSON)."""
    from meshvis.io.jsonfile import to_builtin

    return to_builtin(obj)
