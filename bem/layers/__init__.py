"""Interface-layer laws ``w(p)``: the normal closure of the layer under pressure ``p``.

Every law subclasses :class:`Layer` and provides ``w``, ``dw`` (right derivative), ``energy``
(``W = integral_0^p w``), ``inverse`` (pressure from closure), ``secant`` (``w/p``),
``to_dict`` (rebuilt by :func:`from_dict`); ``a + b`` is :class:`Series`. Pressures ``p < 0``
are treated as 0; inputs are never modified.
"""

from .analytic import Bilinear, ElasticRigid, Linear, Power, Root
from .base import Layer
from .custom import Custom
from .serial import LAWS, from_dict
from .series import Series
from .tabulated import Tabulated, beyond_table

__all__ = [
    "Layer",
    "Linear",
    "Power",
    "Root",
    "ElasticRigid",
    "Bilinear",
    "Tabulated",
    "Custom",
    "Series",
    "LAWS",
    "from_dict",
    "beyond_table",
]
