"""`dyngen identify`: base coefficients by least squares from recordings (dyngen/measured_cli.py holds the command)."""

from __future__ import annotations


def main(argv, prog="dyngen identify") -> int:
    from ..measured_cli import cmd_identify as run

    return run(argv, prog)
