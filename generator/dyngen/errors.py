"""One error type for user input: says the file, the field and what was expected."""


class InputError(Exception):
    """Bad user input. str() is one line: `file: field: what is wrong`."""

    def __init__(self, source: str, field: str, message: str):
        self.source, self.field, self.message = source, field, message
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {message}")
