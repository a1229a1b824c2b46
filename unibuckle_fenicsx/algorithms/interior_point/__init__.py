"""The interior-point Newton method on one mesh (the nested route is ``algorithms.chain``).

- :mod:`.newton`: :class:`~.newton.InteriorPointNewton`, the runs down the central path
  and the contact set read off them;
- :mod:`.kernel`: the Newton step (matrix, inertia control, line search);
- :mod:`.curvature`: the step along negative curvature that leaves a saddle;
- :mod:`.starts`: points strictly inside the cone;
- :mod:`.options`: the settings, iterates and records.
"""

from unibuckle_fenicsx.algorithms.interior_point.newton import InteriorPointNewton
from unibuckle_fenicsx.algorithms.interior_point.options import (
    BarrierPoint,
    NewtonOptions,
    NewtonRecord,
    NewtonStatus,
)

__all__ = ["BarrierPoint", "InteriorPointNewton", "NewtonOptions", "NewtonRecord", "NewtonStatus"]
