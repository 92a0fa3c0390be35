"""Stability of the classification on stiff and extreme inputs (similarity transforms, slivers, cracks, ...).

``meshvis bench stability [--quick] [--json FILE]`` runs five groups of cases.  Each case
classifies a stressed model and compares it with the classification of the untouched
model (same seed), prints PASS or FAIL with the figure it was judged on, and the command
returns 1 when any case fails:

1. *similarity* — uniform scale 1e-6 … 1e6, translation by 1e6 × the size, a rotation, and
   a plain rerun: per-face side labels must agree on at least 99.9 % of the area (a rerun
   must agree exactly: same input and seed give the same output);
2. *degenerate* — slivers of aspect ratio up to 1e6, zero-area faces, duplicate faces,
   near-coplanar duplicates 1e-7 × size away, corners perturbed by 1e-9 × size: the
   original faces keep their labels on at least 99.9 % of their area;
3. *cracks* — a single-sheet box with slits of width 1e-1 … 1e-8 × size around a closed
   box: the width from which the interior leaks (the inner box turns outside), with the
   measured escape share of the box's inner sides next to the ``opening`` threshold, the
   terminal weights before and after the cosine filter, the leak under the paper's
   unfaded prior, and a probe of the slit width the float32 scene closes; it passes when
   leaking is monotone in the width;
4. *weights* — tiny lone triangles and closed cubes (1e-6 × size and up) beside large
   shells, so that edge weights span more than 12 orders of magnitude: the float solver
   (PyMaxflow) and the integer solver (scipy) cut the same graph; their cut values must
   agree within :func:`meshvis.graphcut.mincut.rounding_bound` and their labels on 99.9 % of the
   area; what the integer rounding loses is reported;
5. *tiny* — one triangle, two triangles, one quad (both sides of every face outside); an
   empty file, a file without faces and a single zero-area triangle (a clean
   :class:`~meshvis.errors.ModelError` naming the file).

Every case also checks that no float in the classification report, the node areas and the
graph weights (before and after the cosine filter) is NaN or infinite.

``--quick`` runs fewer scales and widths on smaller models (well under a minute).  The
crack threshold is explained in ``docs/limitations.md`` ("Cracks near the opening
threshold") and the results are in ``docs/benchmarks.md`` ("Stability").
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from dataclasses import asdict

from meshvis.eval import generators

from .stability_cases import (
    CRACK_WIDTHS_FULL,
    CRACK_WIDTHS_QUICK,
    OFFSET_RAYS,
    OFFSET_WIDTHS,
    SCALES_FULL,
    SCALES_QUICK,
    SHARE_RAYS_FULL,
    SHARE_RAYS_QUICK,
    SLIT_WIDTHS_FULL,
    SLIT_WIDTHS_QUICK,
    TINY_NAME,
    CaseResult,
    _timed,
    crack_case,
    degenerate_cases,
    similarity_cases,
    tiny_cases,
    weight_cases,
)
from .stability_models import tiny_beside_huge


def _crack_group(quick: bool, rays_per_node: int, seed: int) -> CaseResult:
    """Group 3, the cracked box at the widths, rays and probes of a quick or a full run."""
    return crack_case(
        CRACK_WIDTHS_QUICK if quick else CRACK_WIDTHS_FULL,
        0.1 if quick else 0.05,
        rays_per_node,
        seed,
        SHARE_RAYS_QUICK if quick else SHARE_RAYS_FULL,
        SLIT_WIDTHS_QUICK if quick else SLIT_WIDTHS_FULL,
        () if quick else OFFSET_WIDTHS,
        OFFSET_RAYS,
    )


def _machine() -> dict:
    """Python, platform, processor and CPU count of the machine the run measured."""
    import platform

    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
    }


def run(
    quick: bool = False,
    seed: int = 0,
    rays_per_node: int = 32,
    progress: Callable[[CaseResult], None] | None = None,
) -> dict:
    """Run every stability case (the five groups of the module docstring).

    Parameters
    ----------
    quick : bool
        Fewer scales and crack widths, smaller models, fewer measuring rays.
    seed : int
        Seed of every classification (stressed and untouched models use the same).
    rays_per_node : int
        Ray budget of every classification.
    progress : callable, optional
        Called with each :class:`CaseResult` as soon as it is known.

    Returns
    -------
    dict
        ``cases`` (list of :class:`CaseResult` as dicts), ``passed``, ``failed``,
        ``quick``, ``seed``, ``rays_per_node``, ``seconds``, ``machine``.
    """
    t0 = time.perf_counter()
    results: list[CaseResult] = []

    def emit(rs: list[CaseResult]) -> None:
        for r in rs:
            results.append(r)
            if progress is not None:
                progress(r)

    shells = generators.nested_shells(2, "sphere", subdivisions=3, seed=seed).soup
    cracked = generators.cracked_box(cell=0.1 if quick else 0.05, crack_width=1e-3, seed=seed).soup
    base = {"nested spheres": shells, "cracked box": cracked}
    if not quick:
        base["house"] = generators.house(seed=seed).soup
    emit(similarity_cases(base, SCALES_QUICK if quick else SCALES_FULL, rays_per_node, seed))
    emit(
        degenerate_cases(
            {"nested spheres": shells} if quick else {"nested spheres": shells, "house": base["house"]},
            rays_per_node,
            seed,
        )
    )
    emit([_timed(lambda: _crack_group(quick, rays_per_node, seed))])
    wmodels = {TINY_NAME: tiny_beside_huge(), "cracked box": cracked}
    if not quick:
        wmodels["house"] = base["house"]
    emit(weight_cases(wmodels, rays_per_node, seed, require_span={TINY_NAME}))
    emit(tiny_cases(rays_per_node, seed))
    cases = [asdict(r) for r in results]
    return {
        "quick": quick,
        "seed": seed,
        "rays_per_node": rays_per_node,
        "passed": sum(r.passed for r in results),
        "failed": sum(not r.passed for r in results),
        "seconds": time.perf_counter() - t0,
        "machine": _machine(),
        "cases": cases,
    }


def format_case(r: CaseResult | dict) -> str:
    """Format one case: a PASS/FAIL line, plus a table for the crack sweep and the tiny-cube parts.

    Parameters
    ----------
    r : CaseResult or dict
        The case, or its dictionary from a :func:`run` result.

    Returns
    -------
    str
        The line, with the table's lines below it when the case has one.
    """
    d = asdict(r) if isinstance(r, CaseResult) else r
    line = f"{'PASS' if d['passed'] else 'FAIL'}  [{d['group']}] {d['name']}: {d['figure']}  ({d['seconds']:.2f} s)"
    rows = d.get("table") or []
    if rows and "width" in rows[0]:
        line += (
            "\n      width     inner box out  inner sides out  escape share: classifier  measured (walls min..max)"
            "  w_out -> filtered   w_in -> filtered   paper prior: inner out  flagged"
        )
        for t in rows:
            line += (
                f"\n      {t['width']:<9.2g} {100 * t['inner_outside']:>11.1f}%  {100 * t['box_inner_side_outside']:>14.1f}%"
                f"  {t['share_classifier']:>18.5f}  {t['share_measured']:.2e} ({t['share_measured_min']:.2e}"
                f"..{t['share_measured_max']:.2e})"
                f"  {t['w_out']:8.3g} -> {t['cap_out']:<8.3g} {t['w_in']:8.3g} -> {t['cap_in']:<8.3g}"
                f" {100 * t['paper_inner_outside']:>18.1f}%  {t['flagged']:>7d}"
            )
        slits = d.get("values", {}).get("slit_transmission") or []
        if slits:
            line += (
                "\n      float32 probe: straight rays across a slit, share transmitted (slit at two places)"
            )
            for x0 in sorted({t["position"] for t in slits}, reverse=True):
                sel = [t for t in slits if t["position"] == x0]
                line += f"\n      float32 spacing {sel[0]['spacing']:.2e} x D: " + ", ".join(
                    f"{t['width']:g}: {100 * t['transmitted']:.0f}%" for t in sel
                )
        probe = d.get("values", {}).get("offset_probe") or []
        if probe:
            line += "\n      ray-offset probe: escape share / width of the inner sides (escaped rays)"
            for off in sorted({t["offset"] for t in probe}, reverse=True):
                sel = [t for t in probe if t["offset"] == off]
                line += f"\n      offset {off:g} x D: " + ", ".join(
                    f"{t['width']:g}: {t['share_per_width']:.2f} ({t['escaped']})" for t in sel
                )
    elif rows and "part" in rows[0]:
        line += "\n      part            faces  front outside  back outside"
        for t in rows:
            line += f"\n      {t['part']:<15} {t['faces']:>5d}  {t['front_outside']:>13.2f}  {t['back_outside']:>12.2f}"
    return line


def format(result: dict) -> str:
    """Format the printed report: one line per case, then the count.

    Parameters
    ----------
    result : dict
        A result of :func:`run`.

    Returns
    -------
    str
        The report.
    """
    lines = [format_case(c) for c in result["cases"]]
    total = result["passed"] + result["failed"]
    lines.append(
        f"stability{' (quick)' if result['quick'] else ''}: {result['passed']} of {total} cases passed, "
        f"{result['failed']} failed ({result['seconds']:.1f} s)"
    )
    return "\n".join(lines)


# ============================================================================ command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench stability`` to its parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The parser of the benchmark.
    """
    parser.add_argument(
        "--quick", action="store_true", help="reduced set (fewer scales and widths, smaller models)"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of every classification (default 0)")
    parser.add_argument("--rays-per-node", type=int, default=32, help="ray budget per node (default 32)")
    parser.add_argument("--json", metavar="FILE", help="also write every number as JSON")


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench stability``: print one line per case as it finishes, then the count.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments` (missing ones take their defaults).

    Returns
    -------
    int
        Exit status: 1 when any case failed, else 0.
    """
    from meshvis.io.jsonfile import write_json

    result = run(
        quick=bool(getattr(args, "quick", False)),
        seed=int(getattr(args, "seed", 0)),
        rays_per_node=int(getattr(args, "rays_per_node", 32)),
        progress=lambda r: print(format_case(r), flush=True),
    )
    total = result["passed"] + result["failed"]
    print(
        f"stability{' (quick)' if result['quick'] else ''}: {result['passed']} of {total} cases passed, "
        f"{result['failed']} failed ({result['seconds']:.1f} s)"
    )
    if getattr(args, "json", None):
        write_json(args.json, result)
    return 1 if result["failed"] else 0
