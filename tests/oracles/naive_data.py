"""Stored results of the NumPy reference for the default run of tests/engine/test_reference.py.

The NumPy reference, :func:`vimpact.reference.numpy_elements.naive_impact` (the element
model written again in SI units, no code shared with the kernel), takes about 36 ms of
CPU a scene and the default run of that file asks it for about 50 fixed scenes. Its
results are deterministic, so they are computed once by the reference and stored in
``data/naive_reference.json``, each with the whole scene, the resolution and the
refinement factors it was run with; the command that writes the file again runs that
test file with the reference called live and records every call::

    python -m tests.oracles.naive_data

Nothing in the file comes from the kernel under test. :func:`naive_reference` looks a
scene up by everything the reference's result depends on (every field of the scene and
its material, ``steps``, ``elements``, ``row_width`` and the engine's refinement factors
for the scene, bit for bit): a scene it does not find (a changed scene or refinement
rule, or another platform's last bit in a drawn scene) is computed on the spot, with a
:class:`StoredReferenceMissing` warning naming this command, so a result is never taken
for a scene it was not computed for. A ``slow`` test computes every stored result
again with the reference and checks that it is the stored one (within
:data:`STORED_RTOL`), so a change of the reference itself cannot go unnoticed either.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import warnings
from pathlib import Path
from typing import Any

from tests.oracles.naive import kernel_refinement
from vimpact import Material, Scene
from vimpact.reference import numpy_elements

DATA = Path(__file__).resolve().parent / "data" / "naive_reference.json"
COMMAND = "python -m tests.oracles.naive_data"

#: set (to anything) to call the reference live and record every call
RECORD_ENV = "VIMPACT_RECORD_NAIVE"

#: A recomputed result may differ from the stored one by this much, relative (with the
#: scales of the comparisons; the machine that wrote the file gives it bit for bit):
#: 1000x below the kernel comparison's 1e-8 and 100x below the 1e-9 of the reference's
#: own identities. The comparisons with stored results subtract it from their tolerances.
STORED_RTOL = 1e-11

#: the float outputs stored (the reference's dict also has ``status`` and ``steps``)
FLOAT_KEYS = ("e_z", "e_x", "beta_x", "v_z_end", "v_x_end", "omega_end", "t_contact",
              "u_max", "a_max", "energy_ratio", "t_gross_slip", "w_friction",
              "slip_width_max")

class StoredReferenceMissing(UserWarning):
    """A scene without a stored result: computed now (the default run is slower)."""


_RECORDED: dict[str, dict[str, Any]] = {}
_STORED: dict[str, dict[str, Any]] | None = None


def scene_record(scene: Scene) -> dict[str, Any]:
    """Every init field of ``scene`` and of its material, as plain JSON values."""
    record = {f.name: getattr(scene, f.name) for f in dataclasses.fields(scene) if f.init}
    material = record.pop("material")
    assert material.shift is None, "a material with a temperature shift is not stored"
    record["material"] = {f.name: getattr(material, f.name)
                          for f in dataclasses.fields(material) if f.name != "shift"}
    record["material"]["arms"] = [list(arm) for arm in material.arms]
    return record


def scene_of(record: dict[str, Any]) -> Scene:
    """The scene of a :func:`scene_record`."""
    fields = dict(record)
    material = dict(fields.pop("material"))
    material["arms"] = tuple(tuple(arm) for arm in material["arms"])
    return Scene(Material(**material), **fields)


def case_of(scene: Scene, steps: int, elements: int, row_width: float = 1.05) -> dict[str, Any]:
    """Everything the reference's result for ``scene`` depends on."""
    return dict(scene=scene_record(scene), steps=steps, elements=elements, row_width=row_width,
                refinement=[float(f) for f in kernel_refinement(scene, steps, elements,
                                                                row_width)])


def _key(case: dict[str, Any]) -> str:
    return json.dumps(case, sort_keys=True)


def compute(case: dict[str, Any]) -> dict[str, Any]:
    """The reference's result for a stored case, computed now."""
    return numpy_elements.naive_impact(scene_of(case["scene"]), case["steps"], case["elements"],
                                       case["row_width"], refinement=tuple(case["refinement"]))


def stored_cases() -> list[dict[str, Any]]:
    """Every stored case with its ``result``."""
    return json.loads(DATA.read_text())["cases"]


def naive_reference(scene: Scene, steps: int, elements: int, row_width: float = 1.05
                    ) -> dict[str, Any]:
    """The NumPy reference's result for ``scene`` at the kernel's refinement, as stored.

    Computed now if not stored (with a :class:`StoredReferenceMissing` warning); with
    the environment variable :data:`RECORD_ENV` set, computed now and recorded."""
    global _STORED
    case = case_of(scene, steps, elements, row_width)
    key = _key(case)
    if os.environ.get(RECORD_ENV):
        if key not in _RECORDED:
            assert scene_of(case["scene"]) == scene, "the record does not give the scene back"
            result = compute(case)
            result.update({k: float(result[k]) for k in FLOAT_KEYS}, steps=int(result["steps"]))
            _RECORDED[key] = dict(case, result=result)
        return dict(_RECORDED[key]["result"])
    if _STORED is None:
        _STORED = {_key({k: v for k, v in c.items() if k != "result"}): c["result"]
                   for c in stored_cases()}
    if key not in _STORED:
        warnings.warn(StoredReferenceMissing(
            f"no stored NumPy reference for {scene!r} at steps={steps}, elements={elements}, "
            f"refinement={case['refinement']}: computed now; write the stored results again "
            f"with `{COMMAND}`"), stacklevel=2)
        return compute(case)
    return dict(_STORED[key])


def _write() -> int:
    import pytest

    os.environ[RECORD_ENV] = "1"
    test_file = Path(__file__).resolve().parents[1] / "engine" / "test_reference.py"
    code = pytest.main(["-q", "-p", "no:cacheprovider", str(test_file)])
    if code != 0:
        return int(code)
    data = {
        "about": "results of vimpact.reference.numpy_elements.naive_impact (NumPy), not of "
                 "the kernel; SI units",
        "command": COMMAND,
        "cases": sorted(_RECORDED.values(), key=_key),
    }
    DATA.parent.mkdir(exist_ok=True)
    DATA.write_text(json.dumps(data, indent=0, sort_keys=True) + "\n")
    print(f"{len(_RECORDED)} cases written to {DATA}")
    return 0


if __name__ == "__main__":
    # the tests import this module as tests.oracles.naive_data: record through that one
    from tests.oracles import naive_data

    sys.exit(naive_data._write())
