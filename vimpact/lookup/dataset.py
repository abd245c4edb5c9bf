"""A grid table as a labelled :class:`xarray.Dataset` (axes with units and descriptions).

xarray is optional (``pip install vimpact[xarray]``): it is imported when a dataset
is made, and its absence is an :class:`~vimpact.model.validation.InputError`.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from vimpact.lookup.columns import OUTPUTS, where
from vimpact.model.validation import InputError

if TYPE_CHECKING:
    from vimpact.lookup.table import RestitutionTable

__all__ = ["to_xarray"]


def to_xarray(table: RestitutionTable, theta_ratio=None):
    """Return the grid of ``table`` as an :class:`xarray.Dataset`.

    :meth:`vimpact.lookup.table.RestitutionTable.to_xarray` describes it.
    """
    try:
        import xarray as xr
    except ImportError:
        raise InputError("to_xarray = xarray is not allowed here: xarray is not installed "
                         "(pip install xarray); RestitutionTable.data is the same table "
                         "as a pandas DataFrame") from None
    if table.is_adaptive:
        raise InputError(f"to_xarray is not allowed for the adaptive table"
                         f"{where(table.path)}: its nodes are cells of different "
                         "sizes, not a grid; evaluate lookup() on the grid you need")
    theta = table.tensor.resolve_theta(theta_ratio)
    grid = table.tensor.lookup_grid() if theta is None else table.tensor.grid(theta)
    units = table.units
    described = {"Q1": "damping parameter sqrt(15/32) (eta/G_inf)/T",
                 "Q2": "G1/G2 of the standard solid", "nu": "Poisson ratio",
                 "theta_ratio": "moment of inertia ratio Theta / (m R^2)",
                 "psi": "friction incidence 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0",
                 "e_z": "normal coefficient of restitution",
                 "e_x": "tangential coefficient of restitution |beta_x|",
                 "beta_x": "tangential coefficient of restitution (signed)"}
    coords = {a: (a, n, {"units": units.get(a, "1"), "long_name": described.get(a, a)})
              for a, n in zip(grid.axes, grid.nodes)}
    data_vars = {k: (grid.axes, grid.values[k], {"units": units.get(k, "1"),
                                                 "long_name": described[k]})
                 for k in OUTPUTS}
    attrs = {"model": table.model,
             "numerics": json.dumps(table.numerics),
             "interpolation_error": json.dumps(table.interpolation_error),
             "vimpact_version": str(table.version),
             "source": "" if table.path is None else str(table.path)}
    if "mu" in table.data.columns:  # psi tables: the mu the rows were simulated with
        attrs["mu"] = json.dumps(sorted({float(x) for x in table.data["mu"].dropna()}))
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)
