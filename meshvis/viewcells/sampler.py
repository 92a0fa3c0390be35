"""Global visibility sampling (AGVS §4.1): one ray's free segment feeds every view cell it pierces.

A sample is a point and a direction; a ray is cast both ways from the point, and the
segment between the two hits (or the view space's box, where a ray meets nothing) is free:
every point on it sees the faces at its ends.  :meth:`GlobalSampler.cast` adds those faces
to the PVS of every cell the segment pierces (the compiled kD-tree walk of
:mod:`._kernels`), counts what was new (the sample's contribution, AGVS Eq. 2) and keeps the
successful segments as mutation candidates (§4.4).

The PVS is a bit set per cell; every new entry is also logged with the batch that found it,
so the PVS at any earlier moment can be rebuilt (the error-against-time curves).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from meshvis.viewcells import _kernels
from meshvis.viewcells.strategies import MutationBuffer, Samples

#: a face's size for mutations never falls below this fraction of the view space's diagonal
#: (a sliver's bounding sphere would keep its mutations within float round-off of the segment)
MIN_RADIUS = 1e-4
#: segments end this fraction of the model's diagonal before their hits (float32 hit
#: distances are good to about 1e-7 of it)
STOP_SHORT = 1e-6
#: room in the log of new entries, grown when a batch needs more
LOG_START = 1 << 20


@dataclass
class Traced:
    """The two rays of each sample: faces hit forwards and backwards (-1: none), distances, sides (both halves)."""

    face_fwd: np.ndarray
    face_back: np.ndarray
    t_fwd: np.ndarray
    t_back: np.ndarray
    side: np.ndarray


@dataclass
class BatchResult:
    """What one batch of samples of one distribution did.

    Attributes
    ----------
    samples : int
        Samples cast.
    rays : int
        Rays traced (both ways, and discovery rays).
    contribution : int
        New PVS entries (AGVS Eq. 2 summed).
    own_rays : int
        Rays (2 per sample) that started in a cell.
    own_contributing : int
        Of those, the ones that found a face new to the cell holding their start.
    seconds : float
        Time of the batch.
    """

    samples: int
    rays: int
    contribution: int
    own_rays: int
    own_contributing: int
    seconds: float


class GlobalSampler:
    """The PVS of every view cell, grown by samples.

    Parameters
    ----------
    cells : ViewCells
        The view cells.
    caster : RayCaster
        The model's caster.
    buffer : MutationBuffer, optional
        Where the successful segments are kept for mutation (a new one by default).

    Attributes
    ----------
    bits : (k, w) uint64
        The PVS of each cell as a bit set.
    sides : (m,) uint8
        Bit 0: the front of the face was hit, bit 1: the back.
    cell_segments : (k,) int64
        Segments that pierced each cell.
    face_hits : (m,) int64
        Segment ends on each face.
    """

    def __init__(self, cells, caster, buffer: MutationBuffer | None = None):
        self.cells = cells
        self.caster = caster
        m = caster.soup.n_faces
        self.n_faces = m
        self.bits = np.zeros((cells.n_cells, max(1, -(-m // 64))), np.uint64)
        self.sides = np.zeros(m, np.uint8)
        self.cell_segments = np.zeros(cells.n_cells, np.int64)
        self.face_hits = np.zeros(m, np.int64)
        self.buffer = buffer or MutationBuffer()
        #: new PVS entries with a point of the cell that saw the face (border mutations)
        self.border = MutationBuffer(("x", "face", "cell"))
        #: new PVS entries, for the cells next to theirs (adjacent-cell mutations)
        self.spread = MutationBuffer(("face", "cell"))
        #: cells sharing a wall with each cell, CSR (made on first use)
        self.adjacent: tuple[np.ndarray, np.ndarray] | None = None
        #: faces sharing a vertex with each face, CSR (made on first use)
        self.neighbours: tuple[np.ndarray, np.ndarray] | None = None
        self._log_cell = np.empty(LOG_START, np.int32)
        self._log_face = np.empty(LOG_START, np.int32)
        self._log_batch = np.empty(LOG_START, np.int32)
        self.n_log = 0
        self.batch = 0
        tri = caster.soup.triangles
        centre = tri.mean(axis=1)
        floor = MIN_RADIUS * cells.view_space.diagonal
        #: bounding-sphere radius of each face (about its centroid)
        self.face_radius = np.maximum(np.linalg.norm(tri - centre[:, None, :], axis=2).max(axis=1), floor)
        self.cell_radius = np.maximum(cells.radius(), floor)
        #: segments end this far before the surfaces they hit
        self.stop_short = STOP_SHORT * caster.diagonal
        self._tree = cells.tree_arrays()

    # ------------------------------------------------------------------ the PVS
    @property
    def log(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(cell, face, batch)`` of every PVS entry, in the order found."""
        n = self.n_log
        return self._log_cell[:n], self._log_face[:n], self._log_batch[:n]

    def sizes(self) -> np.ndarray:
        """(k,) PVS size of each cell."""
        return _kernels.count_rows(self.bits)

    def _room(self, need: int) -> None:
        if self.n_log + need <= len(self._log_cell):
            return
        size = max(2 * len(self._log_cell), self.n_log + need)
        for name in ("_log_cell", "_log_face", "_log_batch"):
            old = getattr(self, name)
            new = np.empty(size, old.dtype)
            new[: self.n_log] = old[: self.n_log]
            setattr(self, name, new)

    # ------------------------------------------------------------------ casting
    def trace(self, samples: Samples) -> Traced:
        """Cast every sample both ways: the faces and distances at the two ends of its segment."""
        o, d = samples.origin, samples.direction
        n = len(o)
        hits = self.caster.intersect(np.concatenate([o, o]), np.concatenate([d, -d]))
        return Traced(hits.face[:n], hits.face[n:], hits.distance[:n], hits.distance[n:], hits.side)

    def cast(
        self, parts: list[Samples], rng: np.random.Generator, traced: Traced | None = None
    ) -> list[BatchResult]:
        """Cast the samples of every part both ways and add their faces to the cells their segments pierce.

        Parameters
        ----------
        parts : list of Samples
            The batch, one part per distribution (results are counted per part).
        rng : numpy.random.Generator
            Picks the points of the border candidates.
        traced : Traced, optional
            The rays of all parts together, when they were cast already (:meth:`trace`).

        Returns
        -------
        list of BatchResult
            One per part; ``seconds`` is the walk's time shared out by samples.
        """
        t = time.perf_counter()
        lengths = [len(p.origin) for p in parts]
        n = sum(lengths)
        if n == 0:
            return [BatchResult(0, p.rays, 0, 0, 0, 0.0) for p in parts]
        o = np.ascontiguousarray(np.concatenate([p.origin for p in parts]), np.float64)
        d = np.ascontiguousarray(np.concatenate([p.direction for p in parts]), np.float64)
        tr = traced or self.trace(Samples(o, d))
        face_fwd, face_back = tr.face_fwd, tr.face_back
        # a segment stops short of the surfaces it hit: the float32 hit distance may pass
        # them by, and a surface on a cell's wall would put its far side's view in the cell
        t_fwd = np.maximum(tr.t_fwd - self.stop_short, 0.0)
        t_back = np.maximum(tr.t_back - self.stop_short, 0.0)
        faces = np.concatenate([face_fwd, face_back])
        hit = faces >= 0
        for side in (0, 1):
            self.sides[faces[hit & (tr.side == side)]] |= np.uint8(1 << side)
        self.face_hits += np.bincount(faces[hit], minlength=self.n_faces)
        origin_cell = np.empty(n, np.int32)
        contribution = np.empty(n, np.int32)
        own = np.empty(n, np.int8)
        useful = np.empty(n, np.int8)
        clip = np.empty((n, 2))
        start = 0
        found = []
        while start < n:
            self._room(max(1 << 16, 4 * self.cells.n_cells))
            log_start = self.n_log
            room = len(self._log_cell) - self.n_log
            new_sample, new_t0, new_t1 = np.empty(room, np.int64), np.empty(room), np.empty(room)
            start, self.n_log = _kernels.walk(
                self._tree,
                o,
                d,
                t_back,
                t_fwd,
                face_back,
                face_fwd,
                origin_cell,
                self.bits,
                self.cell_segments,
                contribution,
                own,
                useful,
                clip,
                self._log_cell,
                self._log_face,
                self.n_log,
                start,
                new_sample,
                new_t0,
                new_t1,
                log_start,
            )
            self._log_batch[log_start : self.n_log] = self.batch
            k = self.n_log - log_start
            found.append((log_start, new_sample[:k], new_t0[:k], new_t1[:k]))
        self._keep_border(o, d, found, rng)
        self._keep(o, d, t_back, t_fwd, face_back, face_fwd, clip, useful, origin_cell)
        seconds = time.perf_counter() - t
        out = []
        at = 0
        for p, k in zip(parts, lengths):
            part = slice(at, at + k)
            at += k
            in_cell = origin_cell[part] >= 0
            mine = own[part][in_cell]
            out.append(
                BatchResult(
                    samples=k,
                    rays=2 * k + p.rays,
                    contribution=int(contribution[part].sum()),
                    own_rays=2 * int(in_cell.sum()),
                    own_contributing=int(((mine & 1) != 0).sum() + ((mine & 2) != 0).sum()),
                    seconds=seconds * k / n,
                )
            )
        return out

    def _keep_border(self, o, d, found, rng) -> None:
        """Store every new entry with a random point of its segment inside the cell, and for its neighbours."""
        for log_start, sample, t0, t1 in found:
            if len(sample) == 0:
                continue
            cell = self._log_cell[log_start : log_start + len(sample)]
            face = self._log_face[log_start : log_start + len(sample)]
            t = t0 + (t1 - t0) * rng.random(len(sample))
            self.border.add(
                x=o[sample] + t[:, None] * d[sample], face=face.astype(np.int64), cell=cell.copy()
            )
            self.spread.add(face=face.astype(np.int64), cell=cell.astype(np.int64))

    def _keep(self, o, d, t_back, t_fwd, face_back, face_fwd, clip, useful, origin_cell) -> None:
        """Store the segments with a new entry as mutation candidates: one per end that found one."""
        keep = np.flatnonzero(useful)
        if len(keep) == 0:
            return
        o, d, useful, origin_cell = o[keep], d[keep], useful[keep], origin_cell[keep]
        face_back, face_fwd, clip = face_back[keep], face_fwd[keep], clip[keep]
        back_end = o + np.where(face_back >= 0, -t_back[keep], clip[:, 0])[:, None] * d
        fwd_end = o + np.where(face_fwd >= 0, t_fwd[keep], clip[:, 1])[:, None] * d
        mean_cell = float(self.cell_radius.mean())
        cell_r = np.where(origin_cell >= 0, self.cell_radius[np.maximum(origin_cell, 0)], mean_cell)
        parts = []
        # (end that found something, its face, the other end, the other end's face)
        for bit, end, face, other, other_face in (
            (2, fwd_end, face_fwd, back_end, face_back),
            (1, back_end, face_back, fwd_end, face_fwd),
        ):
            pick = np.flatnonzero((useful & bit) != 0)
            if len(pick) == 0:
                continue
            of = other_face[pick]
            r_o = np.where(of >= 0, self.face_radius[np.maximum(of, 0)], cell_r[pick])
            parts.append((other[pick], end[pick], face[pick], r_o, self.face_radius[face[pick]]))
        if parts:
            cat = [np.concatenate([p[i] for p in parts]) for i in range(5)]
            self.buffer.add(s_o=cat[0], s_t=cat[1], face=cat[2], r_o=cat[3], r_t=cat[4])
