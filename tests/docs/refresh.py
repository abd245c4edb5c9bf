"""Rewrite the outputs of the executable examples from the current code.

    python -m tests.docs.refresh [FILE.md ...]

Runs every shell (``$ vimpact ...``) and ``pycon`` example of README.md and
docs/**/*.md (or of the files given) and writes what the code prints under each
command, keeping the commands and everything else in the files untouched, and
lines with ``...`` that still match. Prints the examples whose output changed;
review them with ``git diff`` before committing. Rules:
:mod:`tests.docs.examples`.
"""

from __future__ import annotations

import sys
from pathlib import Path

from tests.docs import examples as ex


def _refresh_shell(block: ex.Block) -> list[str]:
    body = list(block.body)
    new, pos = [], 0
    for cmd, got in ex.run_shell_block(block):
        new += body[pos:cmd.last + 1]
        new += ex.refreshed("\n".join(cmd.expected), got)
        pos = cmd.out_end
    return new + body[pos:]


def _refresh_pycon(blocks: list[ex.Block]) -> dict[int, list[str]]:
    """New bodies of the pycon blocks of one file, by block start line."""
    by_block: dict[int, list] = {b.start: [] for b in blocks}
    for block, example, got in ex.run_pycon_blocks(blocks):
        by_block[block.start].append((example, got))
    new = {}
    for block in blocks:
        body, out, pos = block.body, [], 0
        for example, got in by_block[block.start]:
            n_src = example.source.count("\n")
            out += body[pos:example.lineno + n_src]
            want = example.want
            if want.startswith("Traceback") and ex._same_example_output(want, got):
                lines = ex._lines(want)
            else:
                lines = ex.refreshed(want, got)
                if got.startswith("Traceback") and not want.startswith("Traceback"):
                    print(f"warning: {block.name}:"
                          f"{block.line + example.lineno}: the example now raises; "
                          f"{ex._lines(got)[-1]}", file=sys.stderr)
            out += [(" " * example.indent) + line if line else line for line in lines]
            pos = example.lineno + n_src + len(ex._lines(want))
        new[block.start] = out + body[pos:]
    return new


def refresh_file(path: Path) -> list[str]:
    """Rewrite the example outputs of one file; returns where something changed."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found = ex.blocks(path)
    pycon = [b for b in found if b.is_pycon]
    new_pycon = _refresh_pycon(pycon) if pycon else {}
    changed = []
    for block in reversed(found):  # from the end, so earlier line numbers stay valid
        if block.is_shell:
            body = _refresh_shell(block)
        elif block.is_pycon:
            body = new_pycon[block.start]
        else:
            continue
        if body != block.body:
            changed.append(block.where)
            lines[block.start + 1:block.start + 1 + len(block.body)] = block.indented(body)
    if changed:
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return sorted(changed)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    paths = [Path(a).resolve() for a in args] or ex.doc_files()
    total = 0
    for path in paths:
        for where in refresh_file(path):
            print(f"rewrote {where}")
            total += 1
    print(f"{total} example block(s) changed" if total else "all examples up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
