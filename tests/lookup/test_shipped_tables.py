"""Stale-table guard: a shipped lookup table must be what its spec makes today.

For each shipped production table (``sweeps/tables/<name>.parquet``) and its
spec (``sweeps/<name>.toml``), fail with the spec to re-run when:

- its numerics or schema version differ from what the spec resolves to today,
- the spec file changed since the table was made,
- a sample of its nodes, simulated again with its numerics, differs by more than
  1e-6 (the continuum path's error is ~1e-8: a larger gap means the table was
  made by older numerics or code),
- it carries no measured interpolation error (``vimpact table verify --write``).

Live since the tables were regenerated with the final sweep driver and verified
(``REGENERATED = True``); the mark stays for the next time the tables must be
remade.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tests.lookup import shipped

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ("kelvin_voigt_table", "standard_solid_table", "standard_solid_band")
#: Set to True once the shipped tables are regenerated; then this guard is live.
REGENERATED = True
SAMPLE = 12
NODE_TOLERANCE = 1e-6


def _stale_reasons(name: str) -> list[str]:
    from vimpact.sweep import load_spec
    from vimpact.tablebuild.verify import numerics_of, simulate_dimensionless
    from vimpact.tableformat.schema import SCHEMA_VERSION

    spec_path = ROOT / "sweeps" / f"{name}.toml"
    table = shipped(name)
    model = table.model
    spec = load_spec(spec_path)
    reasons = []
    if table.numerics != dataclasses.asdict(spec.numerics):
        reasons.append(f"numerics {table.numerics} != the spec's {dataclasses.asdict(spec.numerics)}")
    if table.meta("schema_version") != SCHEMA_VERSION:
        reasons.append(f"schema version {table.meta('schema_version')} != {SCHEMA_VERSION}")
    if table.meta("spec") is not None and table.meta("spec") != spec.text:
        reasons.append("the spec file changed since the table was made")
    rows = table.ok
    pick = rows.iloc[np.linspace(0, len(rows) - 1, SAMPLE).astype(int)]
    sim = simulate_dimensionless(
        model, pick["Q1"].to_numpy(float), pick["nu"].to_numpy(float),
        pick["Q2"].to_numpy(float) if model == "standard_solid" else None,
        numerics=numerics_of(table))
    for name in ("e_z", "beta_x"):
        gap = float(np.nanmax(np.abs(sim[name].to_numpy(float) - pick[name].to_numpy(float))))
        if not gap <= NODE_TOLERANCE:
            reasons.append(f"{name} at its nodes differs by {gap:.2g} from what its numerics "
                           f"give today (> {NODE_TOLERANCE:g})")
    if table.interpolation_error is None:
        reasons.append("no measured interpolation error (vimpact table verify TABLE --write)")
    command = "vimpact table build" if table.is_adaptive else "vimpact sweep"
    return [f"{r}: re-run `{command} {spec_path.relative_to(ROOT)}`" for r in reasons]


@pytest.mark.xfail(not REGENERATED, strict=True,
                   reason="shipped tables predate today's numerics; regenerate them, "
                          "then set REGENERATED = True")
@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_table_is_what_its_spec_makes_today(name):
    reasons = _stale_reasons(name)
    assert not reasons, f"sweeps/tables/{name}.parquet is stale:\n  " + "\n  ".join(reasons)
