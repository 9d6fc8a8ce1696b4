"""Intervox: probabilistic voxel mapping with interval probabilities and next-best-view planning.

The classes and functions live in the extension module ``intervox._intervox``; this package
re-exports them. See docs/python.md for the conventions (numpy shapes, dtypes, poses, the GIL).
"""

from ._intervox import *  # noqa: F401,F403
from ._intervox import __doc__ as _ext_doc, __version__  # noqa: F401

GRID_TYPES = (BayesGrid, DenseBayesGrid, IntervalGrid, IntervalLowerGrid,  # noqa: F405
              IntervalUpperGrid, DenseIntervalGrid, CompactIntervalGrid,  # noqa: F405
              DenseIntervalLowerGrid, DenseIntervalUpperGrid, DenseCompactIntervalGrid,  # noqa: F405
              DirichletGrid, DenseDirichletGrid, BeliefGrid, DenseBeliefGrid)  # noqa: F405
"""Every grid class, in a fixed order."""
