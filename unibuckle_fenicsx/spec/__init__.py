r"""The description of a problem: one tree of frozen msgspec Structs, read from a file.

:class:`ProblemSpec` and the tables below it (:class:`PlateSpec`, :class:`Material`,
:class:`ObstacleSpec`, ...) are the Python API and the problem file's schema at once:
their annotations hold each key's type, range, choices and unit, ``__post_init__`` the
rules between keys (:mod:`~unibuckle_fenicsx.spec.base`). A bad value raises
:class:`~unibuckle_fenicsx.errors.InputError` (a ``ValueError``) naming the key and the
allowed range, before any mesh or matrix is built.

The computation is in SI units (m, N, Pa). The load is *one* scalar :math:`\lambda`: the
membrane traction on a loaded edge is :math:`\lambda\, t\, (\sigma_n n + \tau_s s)` with
:math:`(\sigma_n, \tau_s)` the edge stress per unit load given here, so that
:math:`\lambda` is a stress in Pa (for the paper's plate, the compressive stress). A TOML
file may be written in another consistent system (``units``, :data:`UNITS`); it is
converted to SI when read, and results are printed in its stress unit.

Modules, each importing only those above it: :mod:`~unibuckle_fenicsx.spec.base` (the
Struct base, units, messages), :mod:`~unibuckle_fenicsx.spec.plate`,
:mod:`~unibuckle_fenicsx.spec.material`, :mod:`~unibuckle_fenicsx.spec.obstacles`,
:mod:`~unibuckle_fenicsx.spec.solver` (the methods and their options),
:mod:`~unibuckle_fenicsx.spec.checks` (rules across tables),
:mod:`~unibuckle_fenicsx.spec.problem`, :mod:`~unibuckle_fenicsx.spec.section` (a
section's file), :mod:`~unibuckle_fenicsx.spec.files` (a file read
and written), :mod:`~unibuckle_fenicsx.spec.schema` (its JSON Schema) and
:mod:`~unibuckle_fenicsx.spec.cases` (the paper's cases).
"""

from __future__ import annotations

from unibuckle_fenicsx.spec.base import (
    UNITS,
    Temperature,
    stress_ends,
    temperature_field,
)
from unibuckle_fenicsx.spec.cases import CASES, paper_case, plate_case
from unibuckle_fenicsx.spec.files import (
    OBSTACLE_KEYS,
    PLY_KEYS,
    is_section,
    load_problem,
    load_toml,
    problem_from_dict,
    problem_to_dict,
    section_from_dict,
    spec_from_dict,
    stress_value,
)
from unibuckle_fenicsx.spec.material import Material, Ply
from unibuckle_fenicsx.spec.obstacles import DesignSpec, LoadSpec, ObstacleSpec, PointSpec
from unibuckle_fenicsx.spec.plate import (
    EDGE_NAMES,
    HOLES,
    Circle,
    EdgeSpec,
    MeshSpec,
    PlateSpec,
    Polygon,
)
from unibuckle_fenicsx.spec.problem import ProblemSpec
from unibuckle_fenicsx.spec.schema import accepted_keys, json_schema
from unibuckle_fenicsx.spec.section import SectionProblemSpec
from unibuckle_fenicsx.spec.solver import (
    METHODS,
    OPTIONS,
    FoundationOptions,
    Method,
    SolverSpec,
)

__all__ = [
    "CASES",
    "EDGE_NAMES",
    "HOLES",
    "METHODS",
    "OBSTACLE_KEYS",
    "OPTIONS",
    "PLY_KEYS",
    "UNITS",
    "Circle",
    "DesignSpec",
    "EdgeSpec",
    "FoundationOptions",
    "LoadSpec",
    "Material",
    "MeshSpec",
    "Method",
    "ObstacleSpec",
    "PlateSpec",
    "Ply",
    "PointSpec",
    "Polygon",
    "ProblemSpec",
    "SectionProblemSpec",
    "SolverSpec",
    "Temperature",
    "accepted_keys",
    "is_section",
    "json_schema",
    "load_problem",
    "load_toml",
    "paper_case",
    "plate_case",
    "problem_from_dict",
    "problem_to_dict",
    "section_from_dict",
    "spec_from_dict",
    "stress_ends",
    "stress_value",
    "temperature_field",
]
