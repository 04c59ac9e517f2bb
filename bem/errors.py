"""The exceptions of contactlab.

Every error a user can cause is an :class:`InputError` (a ``ValueError``) whose
message names the argument, shows the value and states the rule.
"""

__all__ = ["InputError", "RegionTooSmallError"]


class InputError(ValueError):
    """Bad input: the message names the argument, the value and the rule."""


class RegionTooSmallError(InputError):
    """The computed contact reaches the border of the candidate region."""
