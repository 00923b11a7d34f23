"""Errors raised by clumpforge: one class per library error code, each carrying the
library's message (the same one the command line prints) and the code."""


class Error(Exception):
    """A clumpforge failure. ``code`` is the library's error code, e.g. ``"invalid mesh"``."""

    def __init__(self, message, code="invalid argument"):
        super().__init__(message)
        self.message = message
        self.code = code


class InvalidArgumentError(Error, ValueError):
    """An option out of range or malformed."""


class NotFoundError(Error, FileNotFoundError):
    """A file or directory that does not exist."""


class ParseError(Error, ValueError):
    """A file whose content could not be read as its format."""


class InvalidMeshError(Error, ValueError):
    """Geometry that breaks a precondition (open, inside-out, ...): repair it first."""


class RepairFailedError(Error):
    """A repair step that could not reach its goal."""


class IoError(Error, OSError):
    """Reading or writing failed at the operating-system level."""


class CancelledError(Error):
    """The work was asked to stop."""


_BY_CODE = {
    "invalid argument": InvalidArgumentError,
    "not found": NotFoundError,
    "parse error": ParseError,
    "invalid mesh": InvalidMeshError,
    "repair failed": RepairFailedError,
    "i/o error": IoError,
    "cancelled": CancelledError,
}


def from_code(code, message):
    """The exception for a library error code (used by the compiled module)."""
    return _BY_CODE.get(code, Error)(message, code)
