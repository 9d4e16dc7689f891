"""Errors of the wheel-rail geometry: one hierarchy under the contact core's ``ContactError``.

Every error the geometry raises on purpose is a :class:`GeometryError`, so
that the command line and the pipeline turn it into one line (exit 2) or a
counted rejection, never a traceback, and never into a force from a wrong
geometry.
"""

from fastsim_ros.contact.errors import ContactError, InvalidInputError


class GeometryError(ContactError):
    """Base of every error the wheel-rail geometry raises on purpose."""


class ProfileError(GeometryError, InvalidInputError):
    """A profile file that cannot be read or does not describe a wheel or rail surface.

    The message names the file and, where there is one, the point (its
    1-based number in the file's point list and its coordinates).
    """


class PlacementError(GeometryError, InvalidInputError):
    """A placement value (gauge, flange-back distance, radius...) out of its range."""


class PoseError(GeometryError, InvalidInputError):
    """A wheelset pose or load that is not finite or out of its range."""


class DerailmentError(GeometryError):
    """A pose past the flange: the contact leaves the part of the profiles where it is defined."""


class NoContactError(GeometryError):
    """Profiles that never meet (no lateral overlap), or a load no position can carry."""


class BalanceError(GeometryError):
    """No vertical position of a wheel carries its load (the balance did not converge)."""


class TableError(GeometryError):
    """A contact table cannot be built, read or used as asked."""


class TableRangeError(TableError):
    """A pose outside the table's grid (the node's ``out_of_table``)."""
