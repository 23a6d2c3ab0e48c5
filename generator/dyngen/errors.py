"""The errors the dyngen command reports in one line (a light module: the command imports it
before anything heavy, so that even an early Ctrl-C or failure is one line)."""


class InputError(Exception):
    """Bad user input. str() is one line: `file: field: what is wrong`."""

    def __init__(self, source: str, field: str, message: str):
        self.source, self.field, self.message = source, field, message
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {message}")


class Infeasible(Exception):
    """The bounds and constraints admit no solution; the message names the conflicts."""


class DriverError(RuntimeError):
    """The extractor driver could not be built or failed."""
