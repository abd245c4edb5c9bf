"""Benchmarks: scripts that measure and write JSON and plots to benchmarks/results/."""
