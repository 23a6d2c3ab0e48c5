"""The errors the dyngen command reports in one line (a light module: the command imports it
before anything heavy, so that even an early Ctrl-C or failure is one line)."""


def shorten(text: str, limit: int = 60) -> str:
    """User input as quoted in an error: at most `limit` characters, control characters escaped
    (the input may be anyone's, and an error is one line)."""
    text = str(text)
    text = text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"
    return text.encode("unicode_escape").decode("ascii").replace('"', '\\"')


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
