"""OFF round trips: comments, face colours and polygons kept; the face count follows the faces."""

import numpy as np

import meshvis

QUADS = (
    "COFF\n# a comment\n6 2 0\n0 0 0 9 9 9 255\n1 0 0 9 9 9 255\n1 1 0 9 9 9 255\n0 1 0 9 9 9 255\n"
    "2 0 0 9 9 9 255\n2 1 0 9 9 9 255\n4 0 1 2 3 255 0 0\n4 1 4 5 2 0 255 0 # second\n"
)


def test_unchanged_off_is_the_same_text(tmp_path):
    src = tmp_path / "q.off"
    src.write_text(QUADS)
    out = tmp_path / "o.off"
    meshvis.save(meshvis.load(str(src)), str(out))
    assert out.read_text() == QUADS


def test_turned_polygon_stays_a_polygon_and_a_cut_one_becomes_triangles(tmp_path):
    src = tmp_path / "q.off"
    src.write_text(QUADS)
    soup = meshvis.load(str(src))
    out = tmp_path / "o.off"
    meshvis.save(soup.flipped(soup.source_face == 1), str(out))
    lines = out.read_text().splitlines()
    assert lines[:-1] == QUADS.splitlines()[:-1]
    assert lines[-1] == "4 1 2 5 4 0 255 0 # second"
    first = np.flatnonzero(soup.source_face == 0)[0]
    meshvis.save(soup.subset(np.arange(soup.n_faces) != first), str(out))
    lines = out.read_text().splitlines()
    assert lines[2] == "6 2 0" and lines[-2].split()[0] == "3" and lines[-2].split()[-3:] == ["255", "0", "0"]
    back = meshvis.load(str(out))
    assert back.n_faces == 3
