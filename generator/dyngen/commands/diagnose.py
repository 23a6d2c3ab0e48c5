"""`dyngen diagnose`: where the measured-model gap lies and which effect explains it (dyngen/measured_cli.py holds the command)."""

from __future__ import annotations


def main(argv, prog="dyngen diagnose") -> int:
    from ..measured_cli import cmd_diagnose as run

    return run(argv, prog)
