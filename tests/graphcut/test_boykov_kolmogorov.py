"""The compiled Boykov–Kolmogorov solver cuts where PyMaxflow cuts, with the same labels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from meshvis.graphcut.boykov_kolmogorov import _settle_decided, arcs_by_tail, min_cut_bk
from meshvis.graphcut.classify import classify
from meshvis.graphcut.mincut import cut_value, min_cut
from meshvis.io import load

MODELS = Path(__file__).resolve().parents[2] / "models"


def _random_graph(rng, n, k, integer):
    """k distinct undirected edges on n nodes; integer capacities make many equal cuts."""
    pairs = rng.integers(0, n, size=(3 * k, 2))
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    pairs = np.unique(np.sort(pairs, axis=1), axis=0)[:k]
    draw = (
        (lambda size: rng.integers(0, 4, size).astype(float)) if integer else (lambda size: rng.random(size))
    )
    cap_ij, cap_ji = draw(len(pairs)), draw(len(pairs))
    # sparse terminals, as in the visibility graph: most nodes are linked to neither
    cap_s = np.where(rng.random(n) < 0.2, draw(n), 0.0)
    cap_t = np.where(rng.random(n) < 0.2, draw(n), 0.0)
    return pairs[:, 0], pairs[:, 1], cap_ij, cap_ji, cap_s, cap_t


@pytest.mark.parametrize("integer", [True, False])
@pytest.mark.parametrize("seed", range(12))
def test_labels_and_value_equal_pymaxflow_on_random_graphs(seed, integer):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 400))
    graph = _random_graph(rng, n, int(rng.integers(1, 4 * n)), integer)
    ours = min_cut(n, *graph, solver="bk")
    theirs = min_cut(n, *graph, solver="pymaxflow")
    # the source side of a maximum flow's residual graph is unique: ties change nothing
    assert np.array_equal(ours.outside, theirs.outside)
    assert ours.value == pytest.approx(theirs.value, rel=1e-12, abs=1e-12)
    assert cut_value(ours.outside, *graph) == pytest.approx(ours.value, rel=1e-12, abs=1e-12)


def test_a_node_linked_to_nothing_is_inside_and_equal_links_cancel():
    e = np.zeros(0, np.int64)
    f = np.zeros(0)
    out, value, _ = min_cut_bk(3, e, e, f, f, np.array([2.0, 1.0, 0.0]), np.array([1.0, 1.0, 0.0]))
    # more from the source than to the sink: outside; a tie or no link: inside
    assert out.tolist() == [True, False, False]
    assert value == 2.0


def test_the_empty_graph():
    e = np.zeros(0, np.int64)
    out, value, _ = min_cut_bk(0, e, e, np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
    assert out.shape == (0,) and value == 0.0


def test_a_chain_is_cut_at_its_weakest_directed_link():
    # source -> 0 -> 1 -> 2 -> 3 -> sink; the 1 -> 2 capacity is the smallest
    i, j = np.array([0, 1, 2]), np.array([1, 2, 3])
    cap_ij, cap_ji = np.array([5.0, 0.5, 4.0]), np.array([9.0, 9.0, 9.0])
    s, t = np.array([3.0, 0, 0, 0]), np.array([0, 0, 0, 3.0])
    out, value, _ = min_cut_bk(4, i, j, cap_ij, cap_ji, s, t)
    assert out.tolist() == [True, True, False, False] and value == 0.5


def test_a_node_whose_terminal_link_outweighs_its_edges_is_settled_and_passes_it_on():
    # source -5-> 0 -3-> 1 -1-> 2 -10-> sink: 0 settles outside (5 > 3), which gives 1 a
    # source link of 3 > 1, settled in the second pass; 2 settles inside (10 > 1)
    i, j = np.array([0, 1]), np.array([1, 2])
    cap_ij, cap_ji = np.array([3.0, 1.0]), np.array([0.0, 0.0])
    excess = np.array([5.0, 0.0, -10.0])
    side, flow, *rest = _settle_decided(i, j, cap_ij, cap_ji, excess.copy())
    assert side.tolist() == [1, 1, -1] and flow == 1.0  # the edge 1 -> 2 is cut
    assert all(len(a) == 0 for a in rest)
    out, value, settled = min_cut_bk(3, i, j, cap_ij, cap_ji, np.array([5.0, 0, 0]), np.array([0, 0, 10.0]))
    assert out.tolist() == [True, True, False] and value == 1.0 and settled == 3


def test_a_terminal_link_equal_to_the_edges_does_not_settle_a_node():
    # a tie: node 0 may go either way, so the max flow decides (it leaves 0 inside)
    i, j = np.array([0]), np.array([1])
    side, flow, *_ = _settle_decided(i, j, np.array([2.0]), np.array([0.0]), np.array([2.0, -2.0]))
    assert side.tolist() == [0, 0] and flow == 0.0


@pytest.mark.parametrize("seed", range(8))
def test_labels_equal_pymaxflow_when_most_nodes_have_strong_terminal_links(seed):
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(50, 400))
    i, j, cap_ij, cap_ji, _, _ = _random_graph(rng, n, int(rng.integers(n, 3 * n)), False)
    # terminal links of every size against the edges: many nodes settle, some in the second pass
    cap_s = np.where(rng.random(n) < 0.6, 4 * rng.random(n), 0.0)
    cap_t = np.where(rng.random(n) < 0.6, 4 * rng.random(n), 0.0)
    side, *_ = _settle_decided(i, j, cap_ij, cap_ji, cap_s - cap_t)
    assert (side != 0).sum() > n // 10
    ours = min_cut(n, i, j, cap_ij, cap_ji, cap_s, cap_t, solver="bk")
    theirs = min_cut(n, i, j, cap_ij, cap_ji, cap_s, cap_t, solver="pymaxflow")
    assert np.array_equal(ours.outside, theirs.outside)
    assert ours.value == pytest.approx(theirs.value, rel=1e-12)


def test_arcs_by_tail_pairs_every_arc_with_its_reverse():
    i, j = np.array([0, 0, 2, 1]), np.array([1, 3, 3, 2])
    first, head, sister, arc_ij, arc_ji = arcs_by_tail(4, i, j)
    tail = np.repeat(np.arange(4), np.diff(first))
    assert np.array_equal(sister[sister], np.arange(8))
    assert np.array_equal(tail[arc_ij], i) and np.array_equal(head[arc_ij], j)
    assert np.array_equal(tail[arc_ji], j) and np.array_equal(head[arc_ji], i)
    assert np.array_equal(head[sister], tail)


@pytest.mark.parametrize("name", ["house.obj", "assembly.obj", "overlapping_solids.obj"])
def test_labels_equal_pymaxflow_on_the_visibility_graphs_of_bundled_models(name):
    c = classify(load(MODELS / name), seed=0, solver="pymaxflow")
    w = c.graph.weights
    graph = (w.edges_i, w.edges_j, w.cap_ij, w.cap_ji, w.cap_out, w.cap_in)
    ours = min_cut(c.graph.n, *graph, solver="bk")
    assert np.array_equal(ours.outside, c.cut.outside)
    assert ours.value == pytest.approx(c.cut.value, rel=1e-12)
    # and the whole classification, every round cut by the kernel, gives the same labels
    assert np.array_equal(classify(load(MODELS / name), seed=0).outside, c.outside)
