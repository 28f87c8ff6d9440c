"""armscope: a robot arm's rigid-body dynamics, motors and recordings, from Python.

The same library as the ``armscope`` command, NumPy in and out::

    import armscope
    m = armscope.Model("so101.urdf")
    tau = m.rnea(q, v, a)            # one state: (nq,) arrays
    taus = m.rnea(Q, V, A)           # a trajectory: (N, nq) arrays, the GIL released

Bad input raises :class:`ArmscopeError` (what armscope refused, in the command line's one line),
``ValueError`` (an array of the wrong shape) or ``TypeError``.
"""

import sys

from ._armscope import ArmscopeError, Model
from ._armscope import main as _main

__all__ = ["ArmscopeError", "Model", "main"]


def main() -> None:
    """The ``armscope`` command (``pip install armscope`` puts it on PATH)."""
    sys.exit(_main(sys.argv))
