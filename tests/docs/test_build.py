"""The documentation builds without a warning, and nothing in it points outside the repository.

- ``sphinx-build -W --keep-going -b dummy docs OUT`` succeeds (every page read,
  every reference resolved; the html build is a slow test; both skipped, with
  the reason, when Sphinx or myst-parser is not installed: ``pip install ".[docs]"``);
- every link in ``README.md`` and ``docs/**/*.md`` is either a file of this
  repository (that exists; with an anchor that exists when it points into a
  Markdown page) or a page of published literature on one of
  :data:`ALLOWED_HOSTS`;
- every ``docs/PAGE.md#ANCHOR`` cited in the code, the tests or the docs names
  a section that exists.
"""

from __future__ import annotations

import functools
import importlib.util
import re
import subprocess
import sys
from pathlib import Path
from urllib.parse import urlparse

import pytest

from tests.docs.examples import ROOT, doc_files

#: Hosts a link may point to: DOI resolvers, arXiv and journal publishers
#: (published literature only; no project pages, no personal sites).
ALLOWED_HOSTS = frozenset({
    "doi.org",
    "dx.doi.org",
    "arxiv.org",
    "link.springer.com",
    "www.sciencedirect.com",
    "journals.aps.org",
    "pubs.aip.org",
    "iopscience.iop.org",
    "royalsocietypublishing.org",
    "onlinelibrary.wiley.com",
    "www.cambridge.org",
    "casopisi.junis.ni.ac.rs",  # Facta Universitatis, Series Mechanical Engineering
})

_FENCE = re.compile(r"^(`{3,}|~{3,})")
_INLINE_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_AUTOLINK = re.compile(r"<((?:https?|ftp|mailto):[^>\s]+)>")
_HTML_LINK = re.compile(r"(?:href|src)\s*=\s*\"([^\"]+)\"")
_BARE_URL = re.compile(r"(?<![(<\"])\bhttps?://[^\s)>\]]+")
_INLINE_CODE = re.compile(r"`[^`]*`")
_LABEL = re.compile(r"^\(([\w-]+)\)=\s*$")
_HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
_CITED = re.compile(r"\b(docs/[\w/.-]+\.md)#([a-z0-9][a-z0-9-]*)")


def _prose_lines(path: Path):
    """(line number, text) of the lines outside fenced code, inline code removed."""
    inside = None
    for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = _FENCE.match(line)
        if m:
            fence = m.group(1)
            if inside is None:
                inside = fence
            elif fence.startswith(inside[0] * len(inside)):
                inside = None
            continue
        if inside is None:
            yield k, _INLINE_CODE.sub("", line)


def links(path: Path) -> list[tuple[int, str]]:
    """Every link target written in the prose of a Markdown file."""
    found = []
    for k, line in _prose_lines(path):
        for pattern in (_INLINE_LINK, _AUTOLINK, _HTML_LINK):
            found += [(k, m.group(1)) for m in pattern.finditer(line)]
        without_links = _AUTOLINK.sub("", _INLINE_LINK.sub("", line))
        found += [(k, m.group(0)) for m in _BARE_URL.finditer(without_links)]
    return found


def slug(heading: str) -> str:
    """The anchor of a heading, as GitHub and MyST (``myst_heading_anchors``) make it."""
    text = re.sub(r"[`*_]", "", heading).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path: Path) -> frozenset[str]:
    """Heading slugs and explicit ``(label)=`` targets of a Markdown page."""
    stat = path.stat()  # a page is read once per version (it is cited some 200 times)
    return _anchors(path.resolve(), stat.st_mtime_ns, stat.st_size)


@functools.cache
def _anchors(path: Path, mtime_ns: int, size: int) -> frozenset[str]:
    out = set()
    for _, line in _prose_lines(path):
        if m := _LABEL.match(line):
            out.add(m.group(1))
        elif m := _HEADING.match(line):
            out.add(slug(m.group(1)))
    return frozenset(out)


def _problem(path: Path, target: str) -> str | None:
    """Why a link target is not allowed (None: it is fine)."""
    parsed = urlparse(target)
    if parsed.scheme:
        if parsed.scheme not in ("http", "https"):
            return f"scheme {parsed.scheme!r} (only links to published literature are allowed)"
        if parsed.hostname not in ALLOWED_HOSTS:
            return (f"host {parsed.hostname!r} is not published literature "
                    f"(allowed: {', '.join(sorted(ALLOWED_HOSTS))})")
        return None
    file_part, _, anchor = target.partition("#")
    dest = (path.parent / file_part).resolve() if file_part else path.resolve()
    try:
        dest.relative_to(ROOT)
    except ValueError:
        return "points outside the repository"
    if not dest.exists():
        return "no such file in the repository"
    if anchor and dest.suffix == ".md" and anchor not in anchors(dest):
        return f"no section #{anchor} in {dest.relative_to(ROOT)}"
    return None


def test_links_stay_in_the_repository_or_point_to_literature():
    bad = []
    for path in doc_files():
        for line, target in links(path):
            why = _problem(path, target)
            if why:
                bad.append(f"{path.relative_to(ROOT)}:{line}: {target}: {why}")
    assert not bad, "\n".join(bad)


def test_nothing_refers_to_the_shared_folder_beside_the_repository():
    """Not even in code blocks: the project explains itself in its own words."""
    bad = [f"{p.relative_to(ROOT)}:{k}" for p in doc_files()
           for k, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
           if "../shared" in line or "shared/PHYSICS" in line or "shared/DESIGN" in line]
    assert not bad, bad


def test_the_link_checker_catches_what_it_must():
    page = ROOT / "README.md"
    assert _problem(page, "../shared/PHYSICS.md") == "points outside the repository"
    assert "not published literature" in _problem(page, "https://github.com/x/y")
    assert _problem(page, "https://doi.org/10.1103/PhysRevE.53.5382") is None
    assert _problem(page, "docs/physics.md#kelvin-voigt-continuum") is None
    assert "no section" in _problem(page, "docs/physics.md#no-such-section")


def _cited_anchors():
    """(where, page, anchor) of every ``docs/PAGE.md#ANCHOR`` in the code, tests and docs."""
    files = [p for top in ("vimpact", "tests", "benchmarks") for p in (ROOT / top).rglob("*.py")]
    files += doc_files()
    for path in files:
        if path == Path(__file__):
            continue
        for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for m in _CITED.finditer(line):
                yield f"{path.relative_to(ROOT)}:{k}", m.group(1), m.group(2)


def test_cited_sections_exist():
    cited = list(_cited_anchors())
    assert any(page == "docs/physics.md" for _, page, _ in cited)
    bad = [f"{where}: {page}#{anchor}" for where, page, anchor in cited
           if not (ROOT / page).exists() or anchor not in anchors(ROOT / page)]
    assert not bad, "cited sections that do not exist:\n" + "\n".join(bad)


_NO_SPHINX = pytest.mark.skipif(
    not (importlib.util.find_spec("sphinx") and importlib.util.find_spec("myst_parser")),
    reason='Sphinx and myst-parser are not installed (pip install ".[docs]")')


@_NO_SPHINX
@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::PendingDeprecationWarning")
def test_docs_read_and_resolve_without_warnings(tmp_path, monkeypatch):
    """Every page read and every reference resolved, warnings as errors (nothing written).

    The ``dummy`` builder runs the whole of an html build but the writing: a
    broken cross-reference, label, toctree entry or image, a duplicate target or
    a page in no toctree fails it with the warning html gives. It runs in this
    process, where the package autodoc imports is already loaded; the html build
    itself is :func:`test_docs_build_html_without_warnings` (slow).
    """
    import pickle

    from sphinx.cmd.build import build_main

    monkeypatch.setattr(sys, "path", list(sys.path))  # docs/conf.py prepends to it
    warnings = tmp_path / "warnings.txt"
    doctrees = tmp_path / "doctrees"
    code = build_main(["-W", "--keep-going", "-b", "dummy", "-q", "-w", str(warnings),
                       "-d", str(doctrees), str(ROOT / "docs"), str(tmp_path / "out")])
    assert code == 0, warnings.read_text(encoding="utf-8") if warnings.exists() else code
    with open(doctrees / "reference" / "cli.doctree", "rb") as f:
        cli = pickle.load(f).astext()
    from vimpact.cli.main import SUBCOMMANDS
    for name in SUBCOMMANDS:  # the generated reference has every subcommand
        assert f"vimpact {name}" in cli, name


@pytest.mark.slow
@_NO_SPHINX
def test_docs_build_html_without_warnings(tmp_path):
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q",
           "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(tmp_path / "html")]
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stdout}\n{proc.stderr}"
    assert (tmp_path / "html" / "reference" / "cli.html").exists()
    cli = (tmp_path / "html" / "reference" / "cli.html").read_text(encoding="utf-8")
    from vimpact.cli.main import SUBCOMMANDS
    for name in SUBCOMMANDS:  # the generated reference has every subcommand
        assert f"vimpact {name}" in cli, name


# --------------------------------------------------------------------------
# the two Sphinx extensions of docs/_ext (plain functions, no Sphinx needed)
# --------------------------------------------------------------------------

def _ext(name: str):
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.pop(0)


def _all_parsers(parser):
    yield parser
    for action in parser._actions:
        if hasattr(action, "choices") and isinstance(action.choices, dict):
            for sub in action.choices.values():
                yield from _all_parsers(sub)


def test_cli_reference_lists_every_command_and_option():
    from vimpact.cli.main import build_parser

    text = _ext("cli_reference").cli_markdown()
    missing = [f"{p.prog} {opt}" for p in _all_parsers(build_parser())
               for a in p._actions for opt in a.option_strings if opt not in text]
    missing += [p.prog for p in _all_parsers(build_parser()) if f"`{p.prog}`" not in text]
    assert not missing, missing


def test_prose_after_the_colon_becomes_the_description():
    prose = _ext("numpydoc_prose")
    lines = ["Summary.", "", "Parameters", "----------",
             "nu : Poisson ratio, dimensionless, in [0, 0.5]",
             "R : float", "    sphere radius, m",
             "mu : float | None, optional", "v_z0 : normal speed, m/s"]
    assert prose.prose_to_description(lines) == [
        "Summary.", "", "Parameters", "----------",
        "nu", "    Poisson ratio, dimensionless, in [0, 0.5]",
        "R : float", "    sphere radius, m",
        "mu : float | None, optional", "v_z0", "    normal speed, m/s"]
