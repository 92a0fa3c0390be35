"""Evaluation: models with known answers, error measures, baselines, benchmarks, the demo.

Generated models with known answers (:mod:`~meshvis.eval.generators`), error measures
(:mod:`~meshvis.eval.metrics`), the dense visibility reference and false pixels of real
scenes (:mod:`~meshvis.eval.reference`, :mod:`~meshvis.eval.false_pixels`), the
baselines a user would pick instead (:mod:`~meshvis.eval.baselines`), the
``meshvis bench`` commands (:mod:`meshvis.eval.bench`) and the demo on the bundled model
(:mod:`~meshvis.eval.demo`).
"""
