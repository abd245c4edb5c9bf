"""Sphinx extension: the command-line reference, generated from the argparse parsers.

``docs/reference/cli.md`` holds only an introduction; at build time the
``source-read`` event appends one section per command and subcommand of
:func:`vimpact.cli.main.build_parser` (usage, description, every option with its
help), so the page cannot disagree with ``vimpact --help``.
"""

from __future__ import annotations

import argparse
import re

#: the page that receives the generated reference
DOCNAME = "reference/cli"

_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>{}#|$~])")


def _escape(text: str) -> str:
    """Plain help text as Markdown (backslash-escape the characters Markdown would read)."""
    return _MD_SPECIAL.sub(r"\\\1", " ".join(text.split()))


def _usage(parser: argparse.ArgumentParser) -> str:
    formatter = argparse.HelpFormatter(prog=parser.prog, width=88)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups, prefix="")
    return formatter.format_help().strip()


def _subparsers(parser: argparse.ArgumentParser):
    """(name, help, subparser) of every subcommand of ``parser``, in order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help or "" for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, helps.get(name, ""), sub


def _invocation(action: argparse.Action) -> str:
    if not action.option_strings:
        return action.metavar or action.dest
    if action.nargs == 0:
        return ", ".join(action.option_strings)
    metavar = action.metavar or action.dest.upper()
    if isinstance(metavar, tuple):
        metavar = " ".join(metavar)
    if action.choices is not None and action.metavar is None:
        metavar = "{" + ",".join(map(str, action.choices)) + "}"
    return ", ".join(f"{o} {metavar}" for o in action.option_strings)


def _help(action: argparse.Action) -> str:
    text = action.help or ""
    if "%(" in text:
        params = dict(vars(action), prog="vimpact")
        params = {k: (v.__name__ if hasattr(v, "__name__") else v) for k, v in params.items()}
        text = text % params
    return _escape(text) if text else "(no help text)"


def _text(parser: argparse.ArgumentParser, text: str) -> list[str]:
    """A description or epilog: a paragraph, or a literal block where the
    parser keeps its own line breaks (``RawDescriptionHelpFormatter``)."""
    if issubclass(parser.formatter_class, argparse.RawDescriptionHelpFormatter):
        return ["```text", text.strip("\n"), "```", ""]
    return [_escape(text), ""]


def _section(parser: argparse.ArgumentParser, title: str, level: int) -> list[str]:
    out = [f"{'#' * level} `{title}`", "", "```text", _usage(parser), "```", ""]
    if parser.description:
        out += _text(parser, parser.description)
    for group in parser._action_groups:
        actions = [a for a in group._group_actions
                   if a.help is not argparse.SUPPRESS
                   and not isinstance(a, argparse._SubParsersAction)]
        if not actions:
            continue
        out += [f"**{_escape(group.title or 'options')}**", ""]
        for action in actions:
            out += [f"`{_invocation(action)}`", f":   {_help(action)}", ""]
    subs = list(_subparsers(parser))
    if subs:
        out += ["**subcommands**", ""]
        out += [f"- `{parser.prog} {name}`: {_escape(help_)}" for name, help_, _ in subs] + [""]
    if parser.epilog:
        out += _text(parser, parser.epilog)
    for name, _, sub in subs:
        out += _section(sub, f"{parser.prog} {name}", min(level + 1, 4))
    return out


def cli_markdown() -> str:
    """The generated Markdown: one section per command, nested like the command line."""
    from vimpact.cli.main import build_parser

    return "\n".join(_section(build_parser(), "vimpact", 2)) + "\n"


def _append_reference(app, docname: str, source: list[str]) -> None:
    if docname == DOCNAME:
        source[0] = source[0].rstrip("\n") + "\n\n" + cli_markdown()


def _always_reread(app, env, added, changed, removed) -> list[str]:
    """The parsers change without the page changing: re-read it on every build."""
    return [DOCNAME] if DOCNAME in env.found_docs else []


def setup(app):
    app.connect("source-read", _append_reference)
    app.connect("env-get-outdated", _always_reread)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
