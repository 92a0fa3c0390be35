"""The compiled view-line kernels against the numpy expressions they replace."""

import numpy as np

from meshvis.rays.samples import uniform_sphere
from meshvis.visibility import _kernels


def test_framed_targets_is_the_orthographic_frame_of_the_box():
    rng = np.random.default_rng(0)
    d = uniform_sphere(5000, rng)
    d[:10] = [1.0, 0, 0]  # along x: the frame takes the y axis
    u, v = rng.random(len(d)), rng.random(len(d))
    center, half = np.array([1.0, -2.0, 3.0]), np.array([0.5, 2.0, 0.1])
    got = _kernels.framed_targets(d, u, v, center, half)
    across = np.cross(d, np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
    across /= np.linalg.norm(across, axis=1, keepdims=True)
    other = np.cross(d, across)
    want = (
        center
        + ((2 * u - 1) * (np.abs(across) @ half))[:, None] * across
        + ((2 * v - 1) * (np.abs(other) @ half))[:, None] * other
    )
    assert np.abs(got - want).max() < 1e-12
    assert np.isfinite(got).all()
    assert np.abs(np.einsum("ij,ij->i", got - center, d)).max() < 1e-12  # across the direction


def test_tilt_into_planes_puts_directions_near_their_plane():
    rng = np.random.default_rng(1)
    d = uniform_sphere(4000, rng)
    axis = rng.integers(0, 3, 3000)
    tilt = np.radians(0.5) * rng.standard_normal(3000)
    want = d.copy()
    rows = np.arange(3000)
    flat = want[:3000]
    flat[rows, axis] = 0.0
    flat /= np.maximum(np.linalg.norm(flat, axis=1, keepdims=True), 1e-300)
    flat *= np.cos(tilt)[:, None]
    flat[rows, axis] = np.sin(tilt)
    rest = d[3000:].copy()
    _kernels.tilt_into_planes(d, axis, tilt)
    assert np.abs(d - want).max() < 1e-12
    assert np.array_equal(d[3000:], rest)  # only the first len(axis) rows turn
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
