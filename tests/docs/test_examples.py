"""The examples in README.md and docs/ print what the code prints.

Every shell example (``$ vimpact ...`` in a ``text``/``console`` block) and
every doctest-style ``pycon`` block is run and its output compared with the
block, numbers to their printed digits (rules: :mod:`tests.docs.examples`).
After an intended change of numbers, ``python -m tests.docs.refresh`` rewrites
the outputs; review the diff like any other change.
"""

from __future__ import annotations

import pytest

from tests.docs import examples as ex

SHELL, PYCON = ex.executable_blocks()
PYCON_FILES = sorted({b.path for b in PYCON})


def test_the_documentation_has_examples():
    """The README tour and the tutorial are executable (a renamed language tag would silently skip them)."""
    where = {b.path.relative_to(ex.ROOT).as_posix() for b in SHELL + PYCON}
    assert "README.md" in where
    assert "docs/tutorial.md" in where


@pytest.mark.parametrize("block", SHELL, ids=[b.where for b in SHELL])
def test_shell_example(block):
    failures = ex.shell_failures(block)
    assert not failures, ("the output differs from the documentation (python -m "
                          "tests.docs.refresh rewrites it):\n" + "\n".join(failures))


@pytest.mark.parametrize("path", PYCON_FILES, ids=[p.relative_to(ex.ROOT).as_posix() for p in PYCON_FILES])
def test_python_examples(path):
    failures = ex.pycon_failures([b for b in PYCON if b.path == path])
    assert not failures, ("the output differs from the documentation (python -m "
                          "tests.docs.refresh rewrites it):\n" + "\n\n".join(failures))


# --------------------------------------------------------------------------
# the comparison itself
# --------------------------------------------------------------------------

@pytest.mark.parametrize("expected, got, same", [
    ("  e_x                0.15243", "  e_x               0.152556 ", False),  # the old README
    ("  e_x               0.152556", "  e_x               0.152557", True),   # last digit +-1
    ("  e_x               0.152556", "  e_x               0.152558", False),
    ("  t_contact   2.91101e-04 s", "  t_contact   2.91102e-04 s", True),
    ("  t_contact   2.91101e-04 s", "  t_contact   2.91101e-04 m", False),    # text exactly
    ("path continuum (44 steps)", "path continuum (45 steps)", False),      # integers exactly
    ("vimpact 0.1.0: kelvin_voigt", "vimpact 0.1.1: kelvin_voigt", False),  # versions are text
    ("wrote 306 rows in ... s", "wrote 306 rows in 1.2 s", True),
    ("wrote 306 rows in ... s", "wrote 307 rows in 1.2 s", False),
    ("first\n...\nlast", "first\nlast", True),                        # ... alone: any lines
    ("first\n...\nlast", "first\na\nb\nlast", True),
    ("first\n...\nlast", "first\na\nb\nlast but one", False),
])
def test_comparison_rules(expected, got, same):
    assert ex.same_output(expected, got) is same


def test_a_changed_number_in_the_code_fails_the_example(monkeypatch):
    """Demonstration: the README's first example, run with the Hertz contact time
    factor rounded the way the thesis rounds it (2.94 instead of 2.9432...),
    no longer matches its block; unpatched it does (test_shell_example)."""
    import vimpact.model.hertz as hertz

    readme = [b for b in SHELL if b.path.name == "README.md"]
    tour = next(b for b in readme if any("t_hertz" in line for line in b.body))
    assert not ex.shell_failures(tour)
    monkeypatch.setattr(hertz, "HERTZ_TIME_FACTOR", 2.94)
    failures = ex.shell_failures(tour)
    assert len(failures) == 1 and "t_hertz" in failures[0], failures


def test_refresh_rewrites_outputs_and_keeps_everything_else(tmp_path):
    """python -m tests.docs.refresh: stale numbers rewritten, indentation and
    abbreviations (``...``) kept, prose untouched."""
    from tests.docs.refresh import refresh_file

    # a command of many output lines that takes milliseconds (the tutorial's first impact)
    cmd = ("vimpact simulate --E 20e6 --nu 0.49 --eta 53.4077 --R 0.005 --m 0.000575959 "
           "--vz0 1 --vx0 0.5 --tangential none")
    page = tmp_path / "page.md"
    page.write_text("\n".join([
        "Prose stays.", "",
        "1. In a list:", "",
        "   ```console",
        f"   $ {cmd}",
        "   ...",
        "   ```", "",
        "2. Stale in a list:", "",
        "   ```text",
        f"   $ {cmd}",
        "   stale",
        "   ```", "",
        "```text",
        f"$ {cmd}",
        "stale",
        "```", "",
        "```pycon",
        ">>> 6 * 7",
        "41",
        "```", ""]), encoding="utf-8")
    assert len(refresh_file(page)) == 3  # the abbreviated block still matches
    text = page.read_text(encoding="utf-8")
    assert text.startswith("Prose stays.\n") and "   ...\n   ```\n" in text
    assert "\n     e_z " in text and "\n  e_z " in text  # in the list and outside it
    assert "stale" not in text and "\n>>> 6 * 7\n42\n" in text
    shell = [b for b in ex.blocks(page) if b.is_shell]
    assert all(not ex.shell_failures(b) for b in shell)
