"""Errors of the contact-mechanics core: one hierarchy, so callers catch one type."""


class ContactError(Exception):
    """Base of every error the contact-mechanics core raises on purpose."""


class InvalidInputError(ContactError, ValueError):
    """An input that cannot describe a physical contact (NaN, a/b <= 0, nu outside [0, 0.5])."""


class EmptyContactError(InvalidInputError):
    """The area has no cell in contact (no positive pressure, no cell inside the shape)."""


class IrregularGridError(InvalidInputError):
    """Cell centres that do not lie on one regular grid."""


class GridTooLargeError(InvalidInputError):
    """Cells that would span a grid larger than a caller's bound (checked before allocation)."""


class OutOfTableError(InvalidInputError):
    """A look-up outside the range a coefficient table covers."""


class DataError(ContactError):
    """The package's own data (the shipped coefficient tables) is inconsistent or unreadable."""


class ConvergenceError(ContactError, RuntimeError):
    """An iterative solver that did not reach its tolerance."""
