r"""Problem description: frozen dataclasses, the schema of a problem file, the loader.

The computation is in SI units (m, N, Pa). The load is *one* scalar :math:`\lambda`: the
membrane traction on a loaded edge is :math:`\lambda\, t\, (\sigma_n n + \tau_s s)` with
:math:`(\sigma_n, \tau_s)` the edge stress per unit load given here, so that
:math:`\lambda` is a stress in Pa (for the paper's plate, the compressive stress). A TOML
file may be written in another consistent system (``units``, :data:`UNITS`); it is
converted to SI when read, and results are printed in its stress unit.

Modules:

- :mod:`~unibuckle_fenicsx.spec.schema`: the schema of a problem file on msgspec
  (types, bounds, choices, unknown keys; error locations such as
  ``obstacles[1].circle.radius``), :func:`json_schema` and :func:`accepted_keys`. Its
  docstring gives the measurements that chose msgspec over pydantic and cattrs, and
  what stays checked by hand.
- :mod:`~unibuckle_fenicsx.spec.values`, :mod:`~unibuckle_fenicsx.spec.material`,
  :mod:`~unibuckle_fenicsx.spec.plate`, :mod:`~unibuckle_fenicsx.spec.obstacles`,
  :mod:`~unibuckle_fenicsx.spec.problem`: the frozen dataclasses of the Python API.
  They check their values in ``__post_init__`` (they are built in code too, without a
  file) and the rules no schema knows: geometry, the edge-load rule, material matrices.
- :mod:`~unibuckle_fenicsx.spec.units`: a file's numbers to SI and back.
- :mod:`~unibuckle_fenicsx.spec.loading` and :mod:`~unibuckle_fenicsx.spec.writing`:
  a TOML-shaped mapping (or a TOML file, or a JSON result) to a :class:`ProblemSpec`,
  and back (the JSON ``input`` echo: ``problem_from_dict(problem_to_dict(spec)) ==
  spec``).

A bad value raises :class:`~unibuckle_fenicsx.errors.InputError` (a ``ValueError``)
naming the key and the allowed range before any mesh or matrix is built.
"""

from __future__ import annotations

from unibuckle_fenicsx.spec.loading import (
    OBSTACLE_KEYS,
    PLY_KEYS,
    load_problem,
    load_toml,
    problem_from_dict,
)
from unibuckle_fenicsx.spec.material import Material, Ply
from unibuckle_fenicsx.spec.obstacles import DesignSpec, LoadSpec, ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import (
    Circle,
    EdgeSpec,
    MeshSpec,
    PlateSpec,
    Polygon,
    paper_edges,
)
from unibuckle_fenicsx.spec.problem import ProblemSpec, SolverSpec
from unibuckle_fenicsx.spec.schema import accepted_keys, json_schema
from unibuckle_fenicsx.spec.values import (
    BENDING_SUPPORTS,
    EDGE_NAMES,
    HOLES,
    INPLANE_SUPPORTS,
    METHODS,
    POINT_KINDS,
    SIDES,
    UNITS,
    Box,
    Predicate,
    Temperature,
    _boolean,
    _choice,
    _integer,
    _number,
    stress_ends,
    temperature_field,
)
from unibuckle_fenicsx.spec.writing import problem_to_dict, stress_value

__all__ = [
    "BENDING_SUPPORTS",
    "EDGE_NAMES",
    "HOLES",
    "INPLANE_SUPPORTS",
    "METHODS",
    "OBSTACLE_KEYS",
    "PLY_KEYS",
    "POINT_KINDS",
    "SIDES",
    "UNITS",
    "Box",
    "Circle",
    "DesignSpec",
    "EdgeSpec",
    "LoadSpec",
    "Material",
    "MeshSpec",
    "ObstacleSpec",
    "PlateSpec",
    "Ply",
    "PointSpec",
    "Polygon",
    "Predicate",
    "ProblemSpec",
    "SolverSpec",
    "Temperature",
    "_boolean",
    "_choice",
    "_integer",
    "_number",
    "accepted_keys",
    "json_schema",
    "load_problem",
    "load_toml",
    "paper_edges",
    "problem_from_dict",
    "problem_to_dict",
    "stress_ends",
    "stress_value",
    "temperature_field",
]
