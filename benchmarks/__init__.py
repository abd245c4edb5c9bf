"""Benchmarks of the repository: full-size runs of :mod:`vimpact.bench` (the
same code as ``vimpact bench``) and other scripts; they write JSON and charts
to ``benchmarks/results/``."""
