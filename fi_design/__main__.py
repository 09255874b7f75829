"""``python -m fi_design``: the command-line interface."""

from fi_design.cli.app import main

main()
