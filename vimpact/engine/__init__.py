"""From validated scenes to results.

Routing (which kernel, why), packing into kernel arrays, running, and unpacking into SI
result columns.
"""
