"""MorphFX for Python: scenes, images as numpy arrays, and renders through the
MorphFX nodes, pixel for pixel as the ``morphfx`` command line renders them.

The module's code is the extension ``morphfx.morphfx``; beside it lies the
plugin's x86-64-v3 build, which renders on CPUs with AVX2 and FMA.
"""

from .morphfx import *  # noqa: F401,F403
from .morphfx import __all__, __version__  # noqa: F401
