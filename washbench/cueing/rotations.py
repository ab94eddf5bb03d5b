"""Moved to :mod:`washbench.numerics.rotations` (the floor below cueing, platform and perception).

This name stays for code written against it: importing it gives the very same module object.
"""

from __future__ import annotations

import sys

from washbench.numerics import rotations as _moved

sys.modules[__name__] = _moved
