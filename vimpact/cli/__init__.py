"""The ``vimpact`` command line: one module per subcommand, :func:`main` the entry point."""

from vimpact.cli.main import main  # noqa: F401
