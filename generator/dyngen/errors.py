"""The errors the dyngen command reports in one line (a light module: the command imports it
before anything heavy, so that even an early Ctrl-C or failure is one line)."""


def shorten(text: str, limit: int = 60) -> str:
    """User input as quoted in an error: at most `limit` characters, control characters escaped
    (the input may be anyone's, and an error is one line)."""
    text = str(text)
    text = text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"
    return text.encode("unicode_escape").decode("ascii").replace('"', '\\"')


_HIDDEN = ("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn")  # controls, format (bidi overrides), separators, ...


def printable(text) -> str:
    """A file name (or other user text) as it may appear in a message, a YAML or XML comment or
    on the terminal: control characters (newline, escape, ...), line separators and invisible
    format characters (bidirectional overrides) written as escapes; everything else as it is."""
    import unicodedata

    out = []
    for c in str(text):
        if c == " " or unicodedata.category(c) not in _HIDDEN:
            out.append(c)
        else:
            code = ord(c)
            out.append(f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}")
    return "".join(out)


def xml_comment(text) -> str:
    """Text that may stand inside <!-- -->: printable, no "--" (XML forbids it there), no
    trailing "-"."""
    text = printable(text)
    while "--" in text:
        text = text.replace("--", "- -")
    return text + " " if text.endswith("-") else text


class InputError(Exception):
    """Bad user input. str() is one line: `file: field: what is wrong`."""

    def __init__(self, source: str, field: str, message: str):
        source, field, message = printable(source), printable(field), printable(message)
        self.source, self.field, self.message = source, field, message
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {message}")


class Infeasible(Exception):
    """The bounds and constraints admit no solution; the message names the conflicts."""


class DriverError(RuntimeError):
    """The extractor driver could not be built or failed."""
