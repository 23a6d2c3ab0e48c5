"""The `dyngen` command: dispatches to dyngen.commands and turns errors into one line."""

from __future__ import annotations

import os
import signal
import sys

from . import __version__, blas


def _interrupted_while_loading(signum, frame):
    # Ctrl-C while the modules below load: a KeyboardInterrupt raised inside the import
    # machinery can leave a module lock held, and the traceback Python then prints needs an
    # import itself: the process hung, silent (loaded CI machine, Ctrl-C at 1 s). Nothing has
    # been written yet, so leaving at once is clean.
    os.write(2, b"dyngen: interrupted\n")
    os._exit(130)


_LOADING = signal.getsignal(signal.SIGINT) is signal.default_int_handler  # not when SIGINT is ignored
if _LOADING:
    signal.signal(signal.SIGINT, _interrupted_while_loading)

blas.use_one_thread()  # before numpy loads: the imports below load it

from .commands import diagnose, excite, extract, generate, identify  # noqa: E402
from .errors import DriverError, Infeasible, InputError, printable  # noqa: E402

if _LOADING:  # from here on, Ctrl-C unwinds (main below): partial outputs are removed on the way
    signal.signal(signal.SIGINT, signal.default_int_handler)

MAIN_HELP = """\
dyngen: robot dynamic models as exact, standalone C from a DH table.

  dyngen ROBOT.yaml [options]          the main job: generate, then (when the YAML has identified
                                       coefficients and bounds) extract and export
  dyngen generate ROBOT.yaml [-o DIR]  derive, reduce to base coefficients, emit C into DIR/<name>/
  dyngen extract ROBOT.yaml [options]  physically consistent link parameters from the identified
                                       coefficients, written to OUT/<name>/
  dyngen identify ROBOT.yaml --data a.csv [--kind full|gravity|inertia] [--ols]
                                       physically consistent link parameters with friction from
                                       recordings (--ols, gravity, inertia: least squares)
  dyngen diagnose ROBOT.yaml --params P.yaml --data a.csv [--test b.csv]
                                       where the measured-model gap lies and which effect explains it
  dyngen excite ROBOT.yaml [-o CSV]    an optimised excitation trajectory within the joint limits

Run `dyngen COMMAND --help` for a command's options. The YAML schema and the parameter
conventions are in docs/conventions.md; examples/ has the KUKA LWR IV+ and other arms.
"""


COMMANDS = {"generate": generate.main, "extract": extract.main, "identify": identify.main, "diagnose": diagnose.main,
            "excite": excite.main}


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    from .output_paths import REPLACED

    REPLACED.clear()  # one run's record (main may be called more than once in a process)
    try:
        status = _dispatch(argv)
        _say_replaced(argv)
        return status
    except (InputError, Infeasible, DriverError) as err:
        print(f"dyngen: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `dyngen ... | head`
        return 0
    except KeyboardInterrupt:
        print("dyngen: interrupted", file=sys.stderr)
        return 130
    except OSError as err:  # e.g. an output folder that cannot be written
        where = f"{printable(err.filename)}: " if err.filename else ""
        print(f"dyngen: error: {_one_line(where)}{err.strerror or err}", file=sys.stderr)
        return 2
    except (RecursionError, MemoryError) as err:
        print(f"dyngen: error: the input is too large or nested too deeply ({type(err).__name__})", file=sys.stderr)
        return 2


def _say_replaced(argv) -> None:
    from .output_paths import REPLACED

    if REPLACED and not {"-q", "--quiet"} & set(argv):
        print("\n".join(f"dyngen: {_one_line(note)}" for note in REPLACED), file=sys.stderr)


def _dispatch(argv) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(MAIN_HELP, end="")
        return 0 if argv else 2
    if argv[0] == "--version":
        print(f"dyngen {__version__}")
        return 0
    if argv[0] in COMMANDS:
        return COMMANDS[argv[0]](argv[1:], prog=f"dyngen {argv[0]}")
    return extract.main_job(argv, prog="dyngen")


def _one_line(err, limit: int = 2000) -> str:
    """Errors quote user input; keep them one bounded line."""
    text = printable(" ".join(str(err).split("\n")))  # no control bytes reach the terminal
    return text if len(text) <= limit else text[:limit] + "..."


if __name__ == "__main__":
    sys.exit(main())
