"""The command line: the typer application, its shared pieces and its worker pools.

:mod:`~fi_design.cli.app` is the application (``fi-design``, ``python -m
fi_design``), a thin layer over the library; :mod:`~fi_design.cli.parts` its
shared command pieces (options, errors to exit codes, outputs written whole);
:mod:`~fi_design.cli.pools` the worker pools a command starts and stops.
"""
