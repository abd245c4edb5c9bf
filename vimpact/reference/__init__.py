"""Closed forms and independent references the kernels are checked against."""
