"""Errors a user can cause, each with a one-line message: what went wrong, where, what to do.

Every class is a :class:`ValueError`, so a library caller can ``except ValueError``. The exit codes
belong to the command line only (``sarcli.cli.common.exit_code_for``): 2 for a usage or
configuration mistake (a missing input file included), 1 for bad data (a malformed product or
file), 3 for an instrument fault, 130 for an interruption.
"""


class SarcliError(ValueError):
    """An error caused by input or configuration, reported to the user in one line."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).split()))


class ConfigError(SarcliError):
    """A bad option, configuration value or combination of them (a usage mistake)."""


class ProductError(SarcliError):
    """A product or input file is missing, malformed, physically implausible or of the wrong type."""


class MissingFileError(ProductError):
    """An input file or folder that does not exist: a usage mistake (exit 2), though found where the data
    are read."""


class FormatError(ProductError):
    """An external format (CEOS, MATLAB, TOML, Level-0 packets, ...) could not be decoded."""


class InstrumentError(SarcliError):
    """An instrument misbehaved (no answer after the retries, refused a command, wrong identity)."""


class Interrupted(SarcliError):
    """The user asked to stop (Ctrl-C); what was measured so far is kept."""
