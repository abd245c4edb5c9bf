"""Find, run and compare the examples written in ``README.md`` and ``docs/**/*.md``.

Two kinds of example are executable, everything else in the Markdown is prose:

* **shell examples**: a fenced block tagged ``text`` or ``console`` whose first
  line starts with ``$ ``. Every ``$ `` line must be a ``vimpact`` command (a
  trailing backslash continues it on the next line); the lines up to the next
  ``$ `` line are its expected output (stdout, and stderr as well when the
  command fails; a command that succeeds shows its stdout only, as
  progress reports on stderr depend on the machine). A block that shows a
  command without running it uses ``sh``.
* **Python examples**: a fenced block tagged ``pycon`` with doctest-style
  ``>>>`` / ``...`` lines followed by the expected output. The ``pycon`` blocks
  of one file share one namespace and run in the order they appear.

Where they run: each block (shell) or file (Python) gets a fresh temporary
directory in which every top-level entry of the repository (``sweeps``,
``docs``, ...) appears as a symbolic link, so ``sweeps/tables/...`` resolves
exactly as from the repository root while the files a command writes
(``--out curve.csv``) land in the temporary directory. Commands run in this
process through :func:`vimpact.cli.main.main` (the function behind the
``vimpact`` script), with ``COLUMNS=80`` so help text wraps the same everywhere.

How output is compared (:func:`same_output`): line by line, trailing blanks
ignored, runs of spaces inside a line treated as one (column alignment follows
the widest number). Numbers are compared **to the printed digits**: an integer
must match exactly; a number with a decimal point or exponent may differ from
the printed one by at most one unit in its last printed digit (so ``0.152556``
accepts ``0.152555`` .. ``0.152557``, which absorbs a rounding-boundary flip
from last-bit floating-point differences between machines, and rejects
``0.15243``). Everything that is not a number must match exactly. A line of
the expected output that contains ``...`` matches any text in its place (for
output that is not reproducible, such as wall times), and a line that is only
``...`` stands for any number of lines (to show the start of a long output);
``python -m tests.docs.refresh`` keeps such lines as written when the output
still matches.
"""

from __future__ import annotations

import contextlib
import doctest
import io
import os
import re
import shlex
import tempfile
import traceback
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: fenced-block languages whose ``$ `` lines are run
SHELL_LANGS = ("text", "console")
#: fenced-block language of doctest-style Python examples
PYCON_LANG = "pycon"
#: marks a part of an expected line that matches anything
ELLIPSIS = "..."

_FENCE = re.compile(r"^(?P<indent> {0,12})(?P<fence>`{3,}|~{3,})\s*(?P<info>[^`\s]*)")
# a number standing on its own: not part of a name (Q1, fig5_2) or a version (0.1.0)
_NUMBER_TEXT = r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])"
_NUMBER = re.compile(_NUMBER_TEXT)
_NUMBER_SPLIT = re.compile(f"({_NUMBER_TEXT})")


# --------------------------------------------------------------------------
# finding blocks
# --------------------------------------------------------------------------

@dataclass
class Block:
    """One fenced code block of a Markdown file.

    ``start`` is the 0-based index of the opening fence line in the file,
    ``body`` the lines between the fences (without newlines).
    """

    path: Path
    start: int
    lang: str
    body: list[str]
    indent: str = ""

    def indented(self, body: list[str]) -> list[str]:
        """``body`` lines as they are written in the file (with the fence's indentation)."""
        return [self.indent + ln if ln else ln for ln in body]

    @property
    def line(self) -> int:
        """1-based line number of the first body line."""
        return self.start + 2

    @property
    def where(self) -> str:
        return f"{self.name}:{self.line}"

    @property
    def name(self) -> str:
        """The file, relative to the repository when it is in it."""
        return str(self.path.relative_to(ROOT)) if self.path.is_relative_to(ROOT) else str(self.path)

    @property
    def is_shell(self) -> bool:
        return self.lang in SHELL_LANGS and bool(self.body) and self.body[0].startswith("$ ")

    @property
    def is_pycon(self) -> bool:
        return self.lang == PYCON_LANG


def doc_files() -> list[Path]:
    """``README.md`` and every Markdown page under ``docs/`` (not the build output)."""
    files = [ROOT / "README.md"]
    files += sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts)
    return [p for p in files if p.is_file()]


def blocks(path: Path) -> list[Block]:
    """Every fenced block of ``path``, in order (also those indented in a list item:
    their body is given without the fence's indentation)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, info = m.group("indent"), m.group("fence"), m.group("info").lower()
        j = i + 1
        while j < len(lines) and not (lines[j].strip().startswith(fence[0] * len(fence))
                                      and not lines[j].strip().strip(fence[0])):
            j += 1
        body = [ln[len(indent):] if ln.startswith(indent) else ln.lstrip()
                for ln in lines[i + 1:j]]
        found.append(Block(path, i, info, body, indent))
        i = j + 1
    return found


def executable_blocks() -> tuple[list[Block], list[Block]]:
    """(shell blocks, pycon blocks) of every documentation file."""
    shell, pycon = [], []
    for path in doc_files():
        for b in blocks(path):
            if b.is_shell:
                shell.append(b)
            elif b.is_pycon:
                pycon.append(b)
    return shell, pycon


# --------------------------------------------------------------------------
# comparing output
# --------------------------------------------------------------------------

def _unit_of_last_digit(token: str) -> float | None:
    """Size of one unit in the last printed digit, or None for an integer."""
    mantissa, _, exponent = token.lower().partition("e")
    if "." not in mantissa and not exponent:
        return None
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def _same_number(expected: str, got: str) -> bool:
    if expected == got:
        return True
    unit_e, unit_g = _unit_of_last_digit(expected), _unit_of_last_digit(got)
    if unit_e is None or unit_g is None:  # integers: exactly
        return False
    return abs(float(expected) - float(got)) <= max(unit_e, unit_g) * (1 + 1e-9)


def _split(line: str) -> list[str]:
    """Alternating text and number pieces of a line, runs of blanks in the text made one."""
    pieces = _NUMBER_SPLIT.split(line)  # text, number, text, ..., text
    return [p if k % 2 else re.sub(r" +", " ", p) for k, p in enumerate(pieces)]


def same_line(expected: str, got: str) -> bool:
    """One line of output against the expected one (rules in the module docstring)."""
    expected, got = expected.rstrip(), got.rstrip()
    if ELLIPSIS in expected:
        pattern = ".*".join(re.escape(re.sub(r" +", " ", p)) for p in expected.split(ELLIPSIS))
        return re.fullmatch(pattern, re.sub(r" +", " ", got), flags=re.DOTALL) is not None
    e, g = _split(expected), _split(got)
    if len(e) != len(g):
        return False
    return all((_same_number(pe, pg) if k % 2 else pe == pg)
               for k, (pe, pg) in enumerate(zip(e, g)))


def _lines(text: str) -> list[str]:
    lines = [ln.rstrip() for ln in text.splitlines()]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def _match(e: list[str], g: list[str]) -> bool:
    """Line lists: a line that is only ``...`` stands for any number of lines."""
    if not e:
        return not g
    if e[0].strip() == ELLIPSIS:
        return any(_match(e[1:], g[k:]) for k in range(len(g) + 1))
    return bool(g) and same_line(e[0], g[0]) and _match(e[1:], g[1:])


def same_output(expected: str, got: str) -> bool:
    """Whole output against the expected one, line by line (rules in the module docstring)."""
    return _match(_lines(expected), _lines(got))


def difference(expected: str, got: str) -> str:
    """A readable account of where ``got`` departs from ``expected``."""
    e, g = _lines(expected), _lines(got)
    out = []
    for k in range(max(len(e), len(g))):
        a = e[k] if k < len(e) else "<missing>"
        b = g[k] if k < len(g) else "<missing>"
        if k >= len(e) or k >= len(g) or not same_line(a, b):
            out.append(f"  line {k + 1}:\n    expected: {a}\n    got:      {b}")
    return "\n".join(out) or "  (no difference)"


def refreshed(expected: str, got: str) -> list[str]:
    """The output lines to write back: ``got``, keeping expected lines with ``...`` that still match."""
    e, g = _lines(expected), _lines(got)
    if any(line.strip() == ELLIPSIS for line in e) and _match(e, g):
        return e  # an abbreviated output that still matches stays as written
    if len(e) == len(g):
        return [a if ELLIPSIS in a and same_line(a, b) else b for a, b in zip(e, g)]
    return g


# --------------------------------------------------------------------------
# running
# --------------------------------------------------------------------------

@contextlib.contextmanager
def sandbox():
    """A temporary working directory that sees the repository's top level through symlinks."""
    old_cwd, old_columns = os.getcwd(), os.environ.get("COLUMNS")
    with tempfile.TemporaryDirectory(prefix="vimpact-docs-") as tmp:
        for entry in ROOT.iterdir():
            if entry.name not in (".git", ".venv") and not entry.name.startswith("."):
                os.symlink(entry, Path(tmp) / entry.name)
        os.chdir(tmp)
        os.environ["COLUMNS"] = "80"
        try:
            yield Path(tmp)
        finally:
            os.chdir(old_cwd)
            if old_columns is None:
                os.environ.pop("COLUMNS", None)
            else:
                os.environ["COLUMNS"] = old_columns


@dataclass
class Command:
    """One ``$ vimpact ...`` command of a shell block and the output written under it."""

    text: str                     # as written, continuation lines joined
    first: int                    # index in the block body of its first line
    last: int                     # index of its last line
    expected: list[str] = field(default_factory=list)
    out_end: int = 0              # index after its expected output

    @property
    def argv(self) -> list[str]:
        words = shlex.split(self.text)
        if not words or words[0] != "vimpact":
            raise ValueError(f"not a vimpact command: $ {self.text}")
        return words[1:]


def commands(block: Block) -> list[Command]:
    """Split a shell block into its commands and their expected outputs."""
    body, out, k = block.body, [], 0
    while k < len(body):
        line = body[k]
        if not line.startswith("$ "):
            raise ValueError(f"{block.name}:{block.line + k}: output line "
                             f"before any command: {line!r}")
        first, text = k, line[2:]
        while text.endswith("\\") and k + 1 < len(body):
            k += 1
            text = text[:-1] + " " + body[k].lstrip("> ").strip()
        cmd = Command(text=" ".join(text.split()), first=first, last=k)
        k += 1
        while k < len(body) and not body[k].startswith("$ "):
            cmd.expected.append(body[k])
            k += 1
        cmd.out_end = k
        out.append(cmd)
    return out


def run_command(argv: list[str]) -> str:
    """Run ``vimpact ARGV`` in this process: its stdout, followed by its stderr
    if it failed (exit code not 0). Progress reports on stderr of a command that
    succeeds are not part of the example (they depend on the machine's speed)."""
    from vimpact.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse: --help, --version, usage errors
            code = exc.code
    return out.getvalue() + (err.getvalue() if code not in (0, None) else "")


def run_shell_block(block: Block) -> list[tuple[Command, str]]:
    """Run every command of a shell block in one sandbox; (command, output) pairs."""
    cmds = commands(block)
    with sandbox():
        return [(c, run_command(c.argv)) for c in cmds]


def pycon_examples(block: Block) -> list[doctest.Example]:
    """The doctest examples of a ``pycon`` block (``lineno`` relative to the block body)."""
    return doctest.DocTestParser().get_examples("\n".join(block.body) + "\n")


def _run_example(example: doctest.Example, globs: dict, name: str) -> str:
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        try:
            exec(compile(example.source, name, "single"), globs)  # noqa: S102 (documentation examples)
        except Exception as exc:  # shown the way the interpreter shows it, last line compared
            buffer.write("Traceback (most recent call last):\n  ...\n")
            buffer.write("".join(traceback.format_exception_only(type(exc), exc)))
    return buffer.getvalue()


def _same_example_output(want: str, got: str) -> bool:
    if want.startswith("Traceback (most recent call last):"):
        want_last = _lines(want)[-1:] if _lines(want) else []
        got_last = _lines(got)[-1:] if _lines(got) else []
        return got.startswith("Traceback") and want_last == got_last
    return same_output(want, got)


def run_pycon_blocks(blocks_of_file: list[Block]) -> list[tuple[Block, doctest.Example, str]]:
    """Run the ``pycon`` blocks of one file in one namespace; (block, example, output) triples."""
    results = []
    with sandbox():
        globs: dict = {"__name__": "__docs__"}
        for block in blocks_of_file:
            for ex in pycon_examples(block):
                results.append((block, ex, _run_example(ex, globs, block.where)))
    return results


def pycon_failures(blocks_of_file: list[Block]) -> list[str]:
    """Readable failures of the ``pycon`` blocks of one file (empty: all pass)."""
    failures = []
    for block, ex, got in run_pycon_blocks(blocks_of_file):
        if not _same_example_output(ex.want, got):
            src = ex.source.rstrip().replace("\n", "\n    ... ")
            failures.append(f"{block.name}:{block.line + ex.lineno}: "
                            f">>> {src}\n{difference(ex.want, got)}")
    return failures


def shell_failures(block: Block) -> list[str]:
    """Readable failures of one shell block (empty: all commands printed what is written)."""
    failures = []
    for cmd, got in run_shell_block(block):
        expected = "\n".join(cmd.expected)
        if not same_output(expected, got):
            failures.append(f"{block.name}:{block.line + cmd.first}: "
                            f"$ {cmd.text}\n{difference(expected, got)}")
    return failures
