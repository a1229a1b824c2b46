"""Options prefixes and PETSc's options database: one table, one place that writes to it.

Every PETSc/SLEPc object of the package has a non-empty options prefix from
:class:`Prefix`, so ``-<prefix><option>`` on the command line reaches it (e.g.
``-unibuckle_eps_view``). Defaults are pushed under the prefix, read by
``setFromOptions`` and popped again (:func:`set_options`): a default never leaks into
another object, and an option given on the command line wins over it. The options a
Python caller gives a run's eigen solvers stay in the database for the run
(:func:`push_run_options`, :func:`pop_run_options`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from enum import StrEnum
from typing import Any

from petsc4py import PETSc

__all__ = [
    "NESTED_DISSECTION_ROWS",
    "ORDERINGS",
    "ORDERING_BELOW",
    "RUN_EPS_PREFIXES",
    "Options",
    "Prefix",
    "mumps_ordering",
    "option_defaults",
    "ordering_options",
    "pop_run_options",
    "push_run_options",
    "set_options",
]

#: PETSc/SLEPc options as a mapping: option name (without its prefix) to value.
Options = Mapping[str, str | float | int | bool]


class Prefix(StrEnum):
    """Every options prefix of the package (its users append a suffix where noted).

    The pencil's eigen solver (:class:`~unibuckle_fenicsx.la.eigen.GEPSolver`) appends
    ``near_`` (the solves shifted below an estimate), ``ldl_`` (the mesh's shared
    :math:`LDL^T`), ``abs_`` and ``radius_`` (the checks of a round-off spectrum) to its
    own prefix (:attr:`EIGEN`, :attr:`PENALTY` or :attr:`FOUNDATION`).
    """

    #: The buckling pencil's eigen solver on every mesh level.
    EIGEN = "unibuckle_"
    #: The in-plane (membrane) solve of the prestress.
    PRESTRESS = "unibuckle_prestress_"
    #: The :math:`LDL^T` that checks that a fixed load alone does not buckle the plate.
    FIXED = "unibuckle_fixed_"
    #: The coarse mesh's eigen solve that estimates the free load (the free solve's shift).
    ESTIMATE = "unibuckle_estimate_"
    #: The certificate's own factorisations (``sdp_`` and ``modes_`` appended by the SDP).
    CERTIFY = "unibuckle_certify_"
    #: The interior point's relaxation solves (``relax_w_``, ``relax_theta_`` appended).
    IPM = "unibuckle_ipm_"
    #: The free plate's second mode, a start of the interior point's coarsest mesh.
    IPM_SECOND_MODE = "unibuckle_ipm_free2_"
    #: The feasible descent's gradient solve.
    DESCENT = "unibuckle_descent_"
    #: The penalty method's eigen solver.
    PENALTY = "unibuckle_penalty_"
    #: The penalty method's extreme eigenvalues (its condition number).
    PENALTY_CONDITION = "unibuckle_penalty_cond_"
    #: The tensionless foundation's spring-set iteration.
    FOUNDATION = "unibuckle_foundation_"
    #: The nonlinear path's SNES and its KSP.
    NONLINEAR = "unibuckle_nl_"
    #: The nonlinear analysis' imperfection shape (one LU).
    NONLINEAR_SHAPE = "unibuckle_nl_shape_"


#: Options prefixes of the eigen solvers of one run that take the EPS options given in
#: Python (:func:`~unibuckle_fenicsx.analysis.solve`'s ``eps_options``): the pencil on
#: every mesh level, the penalty stages and the foundation's spring iteration.
RUN_EPS_PREFIXES = (Prefix.EIGEN, Prefix.PENALTY, Prefix.FOUNDATION)


#: MUMPS's sequential fill-reducing orderings, by name (ICNTL(7)).
ORDERINGS = {"amd": 0, "amf": 2, "scotch": 3, "pord": 4, "metis": 5, "qamd": 6}

#: The ordering of a matrix below :data:`NESTED_DISSECTION_ROWS` rows, by kind: the
#: plate's (w, theta) matrices (the pencil's factorisations, the stiffness's LU) by
#: approximate minimum fill, the membrane stiffness of the prestress by approximate
#: minimum degree; of the orderings whose analysis costs little, each gives the
#: fastest factorisation there (:doc:`/verification/floor`).
ORDERING_BELOW = {"plate": "amf", "membrane": "amd"}
#: Rows from which a factorisation is ordered by nested dissection (METIS) instead, by
#: kind and by whether its analysis serves one numeric factorisation or many (the eigen
#: solves of a route's contact sets, the interior point's Newton steps). METIS's
#: analysis costs more than the minimum-degree orderings' and saves part of every
#: numeric factorisation: on a plate's matrices it pays for one factorisation only on
#: the largest meshes, for a route's many on much smaller ones. On the membrane
#: stiffness of a large mesh a minimum-degree ordering needs several times METIS's
#: operations on some plates (AMD on one, AMF on another), METIS never much more than
#: the least (up to 10^6 rows: :doc:`/verification/floor`). The package
#: factorises a membrane stiffness once.
NESTED_DISSECTION_ROWS = {
    "plate": {False: 600_000, True: 100_000},
    "membrane": {False: 200_000, True: 100_000},
}


def mumps_ordering(rows: int, kind: str = "plate", reused: bool = False) -> int:
    """MUMPS ICNTL(7) for a matrix of ``rows`` rows of ``kind`` ("plate" or "membrane").

    METIS from :data:`NESTED_DISSECTION_ROWS` rows (``reused``: for an analysis that
    serves many numeric factorisations), else :data:`ORDERING_BELOW`'s. The option
    ``-<prefix>mat_mumps_icntl_7`` (e.g. ``-unibuckle_ldl_mat_mumps_icntl_7 5``)
    overrides it for one factorisation.
    """
    if rows >= NESTED_DISSECTION_ROWS[kind][reused]:
        return ORDERINGS["metis"]
    return ORDERINGS[ORDERING_BELOW[kind]]


def ordering_options(
    mat: PETSc.Mat, key: str = "mat_mumps_icntl_7", kind: str = "plate", reused: bool = False
) -> dict[str, int]:
    """``{key: mumps_ordering(rows of mat, ...)}``: the ordering as a default option."""
    return {key: mumps_ordering(int(mat.getSize()[0]), kind, reused)}


@contextmanager
def option_defaults(prefix: str, options: Options) -> Iterator[None]:
    """Put ``options`` in PETSc's options database under ``prefix`` for the block's duration.

    A default goes in only where the database holds no value for ``prefix + key`` (an
    option from the command line, e.g. ``-unibuckle_eps_max_it 1000``, wins), and it is
    removed again on leaving the block, so nothing leaks into other objects.
    """
    opts = PETSc.Options(prefix)  # names below are relative to the prefix
    pushed = [key for key in options if not opts.hasName(key)]
    for key in pushed:
        opts.setValue(key, options[key])
    try:
        yield
    finally:
        for key in pushed:
            opts.delValue(key)


def set_options(obj: Any, prefix: str, options: Options, *, setup: bool = False) -> None:
    """Set the options prefix of ``obj`` and default ``options``; then ``setFromOptions``.

    The defaults are in the database only during the call (:func:`option_defaults`: a
    value already there wins). Options read only when the object is set up (MUMPS ICNTL
    settings are read at the symbolic factorisation) need ``setup=True``: ``obj.setUp()``
    then runs before the defaults are removed.

    Args:
        obj: A PETSc/SLEPc object with ``setOptionsPrefix`` and ``setFromOptions``.
        prefix: Non-empty options prefix.
        options: Option names (without prefix) and default values.
        setup: Call ``obj.setUp()`` (its operators must be set) while the defaults are in.
    """
    if not prefix:
        raise ValueError("PETSc/SLEPc objects need a non-empty options prefix")
    obj.setOptionsPrefix(prefix)
    with option_defaults(prefix, options):
        obj.setFromOptions()
        if setup:
            obj.setUp()


def push_run_options(options: Options | None) -> list[tuple[str, str]]:
    """Put ``options`` in PETSc's options database under each of :data:`RUN_EPS_PREFIXES`.

    Every eigen solver the run creates afterwards reads them there (its
    ``setFromOptions``), whichever module builds it. An option the database already
    holds (the command line's) is left alone: it wins. Returns what was put, for
    :func:`pop_run_options`.
    """
    pushed: list[tuple[str, str]] = []
    for prefix in RUN_EPS_PREFIXES:
        opts = PETSc.Options(prefix)
        for key, value in (options or {}).items():
            if not opts.hasName(key):
                opts.setValue(key, value)
                pushed.append((prefix, key))
    return pushed


def pop_run_options(pushed: list[tuple[str, str]]) -> None:
    """Remove from the options database what :func:`push_run_options` put there."""
    for prefix, key in pushed:
        PETSc.Options(prefix).delValue(key)
    pushed.clear()
