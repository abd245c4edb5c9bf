"""From validated scenes to results: routing (which kernel, why), packing into
kernel arrays, running, and unpacking into SI result columns."""
