"""Double-sided by duplication: detection in ``info``, both copies kept by ``orient``,
only the copy facing the viewer kept by ``remove-interior`` where one side is hidden."""

from __future__ import annotations

import numpy as np
import trimesh

from meshvis.geometry.diagnostics import diagnose
from meshvis.geometry.duplicates import opposite_copies, winding_parity
from meshvis.repair.orient import orient
from meshvis.repair.remove import remove_interior


def _box_with_double_sided_top():
    """A closed outward box whose two top triangles are stored again with opposite winding."""
    box = trimesh.creation.box()
    v, f = np.asarray(box.vertices), np.asarray(box.faces, np.int64)
    top = np.flatnonzero(np.asarray(box.face_normals)[:, 2] > 0.9)
    return v, np.vstack([f, f[top][:, ::-1]]), top


def test_opposite_copies_pairs_faces_of_opposite_winding_only():
    faces = np.array([[0, 1, 2], [1, 2, 0], [2, 1, 0], [0, 2, 1], [3, 4, 5]])
    assert winding_parity(faces).tolist() == [True, True, False, False, True]
    assert opposite_copies(faces).tolist() == [[0, 2], [1, 3]]
    assert opposite_copies(np.array([[0, 1, 2], [1, 2, 0]])).shape == (0, 2)


def test_info_reports_double_sided_pairs():
    v, f, top = _box_with_double_sided_top()
    assert diagnose((v, f), intersections=False)["double_sided_pairs"] == len(top)
    assert diagnose(trimesh.creation.box(), intersections=False)["double_sided_pairs"] == 0


def test_orient_keeps_both_copies():
    v, f, top = _box_with_double_sided_top()
    r = orient((v, f), seed=0)
    assert not r.flipped.any()
    assert r.double_sided == 2 * len(top)
    assert r.soup.n_faces == len(f)


def test_remove_interior_keeps_the_copy_facing_the_viewer():
    v, f, top = _box_with_double_sided_top()
    r = remove_interior((v, f), visibility="object", seed=0)  # the cut's rule for the copies
    m = len(f) - len(top)
    np.testing.assert_array_equal(r.keep[:m], True)  # the box, its top faces outward included
    np.testing.assert_array_equal(r.keep[m:], False)  # the inward copies
