r"""What a structural model gives the problem, the contact manager and the outputs.

The buckling problem needs of its structural model the pencil (A, B) on a function space
W, the DOFs held by supports, and, node by node, the one DOF the obstacle constrains: the
displacement normal to the obstacle. For the plate (:class:`~.plate.model.PlateModel`,
W = (w, theta)) that is the deflection w, a sub-space of W. A shell on a 3-D surface
mesh (a box or a circular tube) constrains the displacement normal to its wall, a
combination of three components that changes from face to face; a change of basis at
the constrained nodes (a local frame whose first axis is the wall's normal) makes it one
DOF of W there, and the model then offers it exactly as the plate offers w: a scalar
space of the mesh nodes (``NodalDofs.Vw``), the W DOF of each of its DOFs
(``NodalDofs.w_dofs``) and the sub-space of W that holds it
(:attr:`NodalDofs.w_subspace`). The contact manager, the algorithms and the certificates
see constrained rows and their signs only, so a second model enters beside the plate
without a copy of them.

:class:`NodalDofs` is what the contact manager reads (the linear pencil's model and the
von Kármán plate both provide it); :class:`StructuralModel` adds the pencil, the springs
of a bilateral foundation and the mode's fields for output.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.model.points import SnappedPoints

__all__ = ["NodalDofs", "StructuralModel"]


class NodalDofs(Protocol):
    """The DOFs of a model as the contact manager sees them: one constrained DOF per node.

    Attributes:
        mesh: The mesh (its nodes are the candidate contact nodes).
        W: The function space of the mode.
        Vw: Scalar space of the constrained component at the mesh nodes (the plate's
            deflection w; a shell's wall-normal displacement in its local frames).
        w_dofs: The local W DOF of each local DOF of ``Vw``.
        bc_dofs: Local W DOFs held by supports (edges, bilateral points).
    """

    mesh: dolfinx.mesh.Mesh
    W: dolfinx.fem.FunctionSpace
    Vw: dolfinx.fem.FunctionSpace
    w_dofs: npt.NDArray[np.int32]
    bc_dofs: npt.NDArray[np.int32]

    @property
    def w_subspace(self) -> dolfinx.fem.FunctionSpace:
        """The sub-space of W holding the constrained component."""
        ...

    @property
    def extent(self) -> float:
        """The structure's largest extent (m): the scale of geometric tolerances."""
        ...

    @property
    def num_owned_dofs(self) -> int:
        """Owned DOFs of W on this rank."""
        ...

    def global_dofs(self, local: npt.NDArray[np.int32]) -> npt.NDArray[np.int64]:
        """Global (PETSc) indices of local W DOFs."""
        ...


class StructuralModel(NodalDofs, Protocol):
    """A linear buckling model: the pencil (A, B) on W and what its outputs show.

    Attributes:
        A: The stiffness (SPD after the supports; the fixed load's geometric stiffness
            subtracted).
        B: The geometric stiffness per unit load.
    """

    # PETSc matrices as DOLFINx assembles them (its API is untyped; petsc4py's stubs
    # misstate some returns, e.g. norm()).
    A: Any
    B: Any
    #: The supports' zero Dirichlet conditions on W.
    bcs: list[dolfinx.fem.DirichletBC]

    @property
    def points(self) -> Sequence[SnappedPoints]:
        """The point restraints on the mesh (empty for a model without them)."""
        ...

    @property
    def num_dofs(self) -> int:
        """Global DOFs of W."""
        ...

    def add_springs(self, rows: npt.NDArray[np.int64], stiffness: npt.NDArray[np.float64]) -> None:
        """Add nodal springs (N/m) to A at the global ``rows`` (a bilateral foundation)."""
        ...

    def split(self, u: dolfinx.fem.Function) -> tuple[dolfinx.fem.Function, ...]:
        """The mode's fields for output (the plate: w and theta), on collapsed spaces."""
        ...

    def destroy(self) -> None:
        """Destroy A and B (collective)."""
        ...
