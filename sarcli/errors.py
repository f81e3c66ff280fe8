"""User-facing errors.

Any mistake a user can make (bad file, bad option, impossible geometry) is raised as a
:class:`SarcliError` whose message is one line: what went wrong, where, and what to do.
The CLI prints it as ``sarcli: error: <message>`` and exits non-zero, never with a traceback.
"""


class SarcliError(Exception):
    """An error caused by input or configuration, reported to the user in one line."""

    exit_code = 2

    def __init__(self, message: str, exit_code: int | None = None):
        super().__init__(" ".join(str(message).split()))
        if exit_code is not None:
            self.exit_code = exit_code


class ProductError(SarcliError):
    """A product file is missing, malformed or of the wrong type."""


class FormatError(SarcliError):
    """An external format (CEOS, MATLAB, TOML) could not be decoded."""
