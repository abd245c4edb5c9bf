"""Validated inputs: materials, scenes, numerics and the Hertz scales they are measured in."""
