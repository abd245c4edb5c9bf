"""The ``vimpact`` command line: the parser and the dispatch to one module per subcommand.

Each subcommand lives in ``vimpact/cli/<name>.py`` with ``add_parser(sub)``,
which registers it and sets ``func`` (the handler, returning the exit code).
Bad input (``ValueError``, including :class:`vimpact.InputError`) and
``OSError`` (a file that cannot be read or written) give one line on stderr and
exit code 2; anything else is a bug and shows its traceback.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from vimpact import __version__

#: Subcommands in the order ``vimpact --help`` lists them; module ``vimpact.cli.<name>``.
SUBCOMMANDS = ("simulate", "sweep", "table", "plot", "bench", "dem", "material")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """Return the ``vimpact`` parser.

    Parameters
    ----------
    argv : the arguments the parser is built for. When the first names a subcommand,
        only that subcommand is registered (argparse then never shows the others:
        their options, help lines and checks are not built, a few milliseconds per
        command); otherwise (``None``, ``--help``, ``--version``, an unknown command)
        every subcommand is.
    """
    parser = _Parser(prog="vimpact", description=(
        "Coefficients of restitution of a sphere hitting a viscoelastic "
        "half-space (method of dimensionality reduction)."))
    parser.add_argument("--version", action="version", version=f"vimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    names = (argv[0],) if argv and argv[0] in SUBCOMMANDS else SUBCOMMANDS
    for name in names:
        importlib.import_module(f"vimpact.cli.{name}").add_parser(sub)
    return parser


def _negative_values(argv: list[str]) -> list[str]:
    """``--E -1e9`` -> ``--E=-1e9``.

    Argparse takes a token like ``-1e9`` (or ``-inf``, ``-1/4``) for an option; joined to
    its flag it is read as the value it is (and then refused by the option's own check
    with a message that names it).
    """
    out: list[str] = []
    for token in argv:
        if (out and out[-1].startswith("--") and "=" not in out[-1] and token.startswith("-")
                and (_is_number(token) or token[1:2].isdigit() or token[1:2] == ".")):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def main(argv: list[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); returns the exit code."""
    argv = _negative_values(sys.argv[1:] if argv is None else list(argv))
    args = build_parser(argv).parse_args(argv)
    try:
        return args.func(args)
    except BrokenPipeError:  # the reader went away (``| head``): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ValueError, OSError) as exc:
        text = " ".join(str(exc).split()) or type(exc).__name__
        print(f"vimpact {args.command}: error: {text}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("vimpact: interrupted", file=sys.stderr)
        return 130


#: Thresholds of the cyclic garbage collector in a ``vimpact`` process (:func:`run`):
#: the young generations fill more before a pass. numba's compiler makes millions of
#: short-lived containers; with Python's default (700, 10, 10) the first command on an
#: empty numba cache spent about 6 % more CPU (3 cold starts in turns).
GC_THRESHOLDS = (10_000, 50, 100)


def run() -> int:
    """Run the ``vimpact`` command (the console script, ``python -m vimpact``): :func:`main`.

    The process is the command's own, so its garbage collector is set for a short
    program that compiles (:data:`GC_THRESHOLDS`); :func:`main` called from Python
    leaves the caller's collector as it is.
    """
    import gc

    gc.set_threshold(*GC_THRESHOLDS)
    return main()


if __name__ == "__main__":
    sys.exit(run())
