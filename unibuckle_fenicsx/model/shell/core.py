r"""The core as an obstacle: constrained normal directions, each made one DOF by a change of basis.

At every node of the walls the core covers, the wall may only move away from it:
:math:`n_{in}\cdot u \le 0` with :math:`n_{in}` the unit normal toward the core
(:meth:`~unibuckle_fenicsx.model.shell.geometry.SectionMesh.inward_normals`): one per
node of a face or of a tube, two at a box's corner (the two faces' normals). The
package's contact manager and algorithms remove *single* DOFs with a sign
(:class:`~unibuckle_fenicsx.model.contact.ContactSetManager`). A change of basis at the
constrained nodes turns each constrained direction into one DOF: with the node's
:math:`3\times3` block :math:`Q_k = R_k^{-1}`, :math:`R_k` the rows
:math:`(n_1, [n_2,] m\ldots)` (the normals, completed to a basis by Gram-Schmidt on
e_x, e_y, e_z), the global displacement is :math:`u = T u'` with T block-diagonal
(:math:`Q_k` on the node's displacement DOFs, the identity elsewhere), and the first
(and second) of the node's displacement DOFs in the new basis is :math:`n_j\cdot u`.
The pencil becomes :math:`(A', B') = (T^TAT, T^TBT)` (PETSc ``PtAP``): congruent, so A'
stays SPD and the eigenvalues do not change; a candidate set is again a set of rows to
zero. When the normals are orthonormal (a box's corner, any single normal) T is
orthogonal.

Nodes whose normal displacement a support holds already (the loaded ends) are left out,
as the plate's edge-held zone nodes are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.model.shell.forms import cell_frame
from unibuckle_fenicsx.model.shell.geometry import SectionMesh
from unibuckle_fenicsx.model.shell.model import DOFS_PER_NODE, ShellModel
from unibuckle_fenicsx.spec.base import in_file
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

__all__ = [
    "CoreConstraints",
    "axis_turns",
    "change_of_basis",
    "core_constraints",
    "core_springs",
    "perimeter_coordinate",
    "quarter_turns",
]


@dataclass(frozen=True)
class CoreConstraints:
    r"""The constrained directions, numbered 0..i-1 the same way on every rank.

    Attributes:
        coordinates: (i, 3) the node of each constraint (a box's corner node appears
            twice), same on all ranks.
        normals: (i, 3) its unit normal toward the core, same on all ranks.
        unrolled: (i, 2) (x, s), s the arc length around the section's mid-line (m).
        owned_positions: Constraint numbers of the constraints whose node this rank owns.
        owned_local_dofs: Local W DOF (new basis) of each: ``6 k + j``, j the normal's
            place at node k.
        owned_global_dofs: Its global DOF.
        owned_nodes: Local node (block) k of each.
        num_held: Constrained nodes left out because a support holds their normal motion.
    """

    coordinates: npt.NDArray[np.float64]
    normals: npt.NDArray[np.float64]
    unrolled: npt.NDArray[np.float64]
    owned_positions: npt.NDArray[np.int64]
    owned_local_dofs: npt.NDArray[np.int32]
    owned_global_dofs: npt.NDArray[np.int64]
    owned_nodes: npt.NDArray[np.int32]
    num_held: int

    @property
    def size(self) -> int:
        """Number i of constrained directions."""
        return int(self.coordinates.shape[0])


def perimeter_coordinate(
    section: SectionMesh, x: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    r"""Arc length s (m) along the section's mid-line of the points ``x`` (3, n).

    Box: counter-clockwise from the corner (+b/2, -d/2); tube: :math:`R\varphi`,
    :math:`\varphi` from +y toward +z in [0, 2 pi); flat face: y.
    """
    y, z = x[1], x[2]
    if section.shape == "flat":
        return np.asarray(y, dtype=float)
    if section.shape == "tube":
        return section.radius * np.mod(np.arctan2(z, y), 2.0 * math.pi)
    b, d = section.width, section.depth
    hb, hd = 0.5 * b, 0.5 * d
    tol = section.tolerance
    s = np.empty(y.shape)
    right = np.abs(y - hb) < tol
    top = (np.abs(z - hd) < tol) & ~right
    left = (np.abs(y + hb) < tol) & ~top
    bottom = ~(right | top | left)
    s[right] = z[right] + hd
    s[top] = d + (hb - y[top])
    s[left] = d + b + (hd - z[left])
    s[bottom] = 2 * d + b + (y[bottom] + hb)
    return s


def core_constraints(model: ShellModel, span: tuple[float, float] | None = None) -> CoreConstraints:
    """The core's constrained directions at the nodes of the walls it covers.

    Args:
        model: The section's shell model (its supports decide which nodes are held).
        span: The core's extent (x0, x1) along the member (m); None: the whole length.
            Nodes within the closed span count (tolerance of the section's geometry).
            Its messages are in the units of the file solved
            (:func:`~unibuckle_fenicsx.spec.base.file_units`).

    Raises:
        InputError: The span holds no free node, or a support holds part of a
            constrained node's displacement (the change of basis would mix held and
            free components).

    Note:
        Collective.
    """
    section = model.section
    tol = section.tolerance
    x0, x1 = (0.0, section.length) if span is None else span
    (a, b, length), unit = in_file((x0, x1, section.length), "m")
    if not (0.0 <= x0 < x1 <= section.length + tol):
        raise InputError(
            f"core span must satisfy 0 <= x0 < x1 <= length = {length:g} {unit}, got ({a:g}, {b:g})"
        )
    X = model.W.tabulate_dof_coordinates()[: model.W.dofmap.index_map.size_local]
    inside = (X[:, 0] >= x0 - tol) & (X[:, 0] <= x1 + tol)
    owned_nodes, js, normals, num_held = _directions(model, X, np.flatnonzero(inside))
    coords = X[owned_nodes] if owned_nodes.size else np.zeros((0, 3))
    s = perimeter_coordinate(section, coords.T) if owned_nodes.size else np.zeros(0)
    unrolled = np.stack([coords[:, 0], s], axis=1) if owned_nodes.size else np.zeros((0, 2))
    # One numbering on every rank: by quantised (x, s), then the normal's place.
    gathered = model.mesh.comm.allgather((coords, normals, unrolled, js))
    all_j = np.concatenate([g[3] for g in gathered])
    if all_j.size == 0:
        held = model.mesh.comm.allreduce(int(inside.sum()), op=MPI.SUM) > 0
        what = "only nodes held by the end supports" if held else "no node of the mesh"
        raise InputError(
            f"the core covers no free node: its span ({a:g}, {b:g}) {unit} (obstacle.span) holds "
            f"{what}; lengthen obstacle.span or refine mesh.size"
        )
    all_u = np.vstack([g[2] for g in gathered])
    size = max(section.length, section.perimeter)
    keys = np.round(all_u / (GEOMETRY_RTOL * size)).astype(np.int64)
    order = np.lexsort((all_j, keys[:, 1], keys[:, 0]))
    rank_pos = np.empty(all_j.size, dtype=np.int64)
    rank_pos[order] = np.arange(all_j.size, dtype=np.int64)
    offset = int(sum(g[3].size for g in gathered[: model.mesh.comm.rank]))
    local_dofs = (owned_nodes.astype(np.int64) * DOFS_PER_NODE + js).astype(np.int32)
    return CoreConstraints(
        coordinates=np.vstack([g[0] for g in gathered])[order],
        normals=np.vstack([g[1] for g in gathered])[order],
        unrolled=all_u[order],
        owned_positions=rank_pos[offset : offset + js.size],
        owned_local_dofs=local_dofs,
        owned_global_dofs=model.global_dofs(local_dofs),
        owned_nodes=owned_nodes,
        num_held=int(model.mesh.comm.allreduce(num_held, op=MPI.SUM)),
    )


def quarter_turns(constraints: CoreConstraints) -> tuple[npt.NDArray[np.int64], ...]:
    r"""The constrained directions' permutations under a square box's quarter turns.

    A turn by :math:`k\pi/2` (k = 1, 2, 3) about the member's axis (the x-axis through the
    section's centre) maps the point :math:`(x, y, z)` and its normal to
    :math:`(x, y\cos\theta - z\sin\theta, y\sin\theta + z\cos\theta)`. Each turn
    that maps every constrained direction onto one (its node onto a node and its normal
    onto that node's normal, to :data:`~unibuckle_fenicsx.tolerances.GEOMETRY_RTOL` of
    the section's size) is returned as the array ``perm``: direction ``k`` goes to
    ``perm[k]``, a set ``Z`` to ``perm[Z]``. Whether the section's pencil is invariant
    under them (a square box, a load that is the same on every face) is the caller's
    to decide (:func:`~unibuckle_fenicsx.model.shell.section.build_section`); this
    checks the mesh. The same on every rank (the constraints are).
    """
    turns = (_turn(constraints, 0.5 * math.pi * k) for k in (1, 2, 3))
    return tuple(perm for perm in turns if perm is not None)


def axis_turns(
    constraints: CoreConstraints, cells_around: int
) -> tuple[npt.NDArray[np.int64], ...]:
    r"""The constrained directions' permutations under a tube's turns about its axis.

    A tube meshed with ``cells_around`` equal facets is the same after a turn by
    :math:`2\pi k/n` (n = ``cells_around``, k = 1, ..., n - 1) about its axis. The turn
    by :math:`2\pi/n` is checked on the mesh as :func:`quarter_turns` checks a box's
    (every constrained direction mapped onto one); its powers are the others, each as
    the array ``perm`` (direction ``k`` to ``perm[k]``). None if that turn maps some
    direction onto none (a mesh that is no such polygon swept along x). Whether the
    pencil is invariant under them (a load the same all around) is the caller's to
    decide (:func:`~unibuckle_fenicsx.model.shell.section.build_section`). The same on
    every rank (the constraints are).
    """
    if cells_around < 2:
        raise InputError(f"cells_around must be an integer >= 2, got {cells_around}")
    step = _turn(constraints, 2.0 * math.pi / cells_around)
    if step is None:
        return ()
    turns = [step]
    for _ in range(cells_around - 2):
        turns.append(step[turns[-1]])  # one step more: k -> step[perm[k]]
    return tuple(turns)


def _turn(constraints: CoreConstraints, theta: float) -> npt.NDArray[np.int64] | None:
    """The permutation of the constrained directions under a turn by ``theta`` about x.

    None where the turn maps some direction (node and normal) onto none, to
    :data:`~unibuckle_fenicsx.tolerances.GEOMETRY_RTOL` of the section's size.
    """
    from scipy.spatial import cKDTree

    points = np.hstack([constraints.coordinates, constraints.normals])
    n = points.shape[0]
    if n == 0:
        return None
    size = float(np.abs(constraints.coordinates).max())
    scale = np.array([size] * 3 + [1.0] * 3)
    tree = cKDTree(points / scale)
    c, s = math.cos(theta), math.sin(theta)
    image = points.copy()
    for j in (0, 3):  # the node, then its normal
        y, z = points[:, j + 1], points[:, j + 2]
        image[:, j + 1] = c * y - s * z
        image[:, j + 2] = s * y + c * z
    dist, perm = tree.query(image / scale)
    if np.all(dist <= GEOMETRY_RTOL) and np.unique(perm).size == n:
        return perm.astype(np.int64)
    return None


def _directions(
    model: ShellModel, X: npt.NDArray[np.float64], nodes: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int32], npt.NDArray[np.float64], int]:
    """(node, normal's place j, normal) of each direction at the owned ``nodes``, and the held.

    A node whose normal motion a support holds is left out (counted); one whose support
    holds only part of it is refused (:func:`core_constraints`).
    """
    held = np.zeros((X.shape[0], DOFS_PER_NODE), dtype=bool)
    bc = model.bc_dofs[model.bc_dofs < X.shape[0] * DOFS_PER_NODE]
    held.reshape(-1)[bc] = True
    normals_per_node = model.section.inward_normals(X[nodes].T) if nodes.size else []
    rec_nodes, rec_j, rec_n = [], [], []
    num_held = 0
    for k, normals in zip(nodes.tolist(), normals_per_node, strict=True):
        fixed = held[k, :3]
        if not fixed.any():
            for j, n in enumerate(normals):
                rec_nodes.append(k)
                rec_j.append(j)
                rec_n.append(n)
            continue
        free_part = np.abs(normals[:, ~fixed]).max() if (~fixed).any() else 0.0
        if free_part < 1e-12:
            num_held += 1
            continue
        raise InputError(
            f"a support holds part of the displacement of the core's node at {X[k].tolist()}: "
            "the core may cover only nodes whose displacement is free or whose normal "
            "motion is held"
        )
    return (
        np.asarray(rec_nodes, dtype=np.int32),
        np.asarray(rec_j, dtype=np.int32),
        np.asarray(rec_n, dtype=float).reshape(-1, 3),
        num_held,
    )


def core_springs(
    model: ShellModel,
    constraints: CoreConstraints,
    stiffness: float,
    span: tuple[float, float] | None = None,
) -> npt.NDArray[np.float64]:
    r"""The core's lumped foundation spring (N/m) of each constrained direction, on every rank.

    The spring of node k is :math:`k_f \int \varphi_k\,dx` (the row sum of the Q1 mass
    matrix, as the plate's foundation), the area the node stands for: the half cells
    around it. A box corner's two directions get their own faces' halves,
    :math:`\int \varphi_k (n_c\cdot n_j)^2\,dx` with :math:`n_c` the cell's normal and
    :math:`n_j` the direction's (1 on its face, 0 on the other: the faces' cells differ
    in width when the width and depth do). With a ``span``, the part of that area the
    core covers: the fraction of the node's stretch along the member
    :math:`[x_k - h/2, x_k + h/2]` (h the cells' length along, uniform) inside the span,
    so a node at the span's end stands for its inner half.

    Args:
        model: The section's shell model.
        constraints: Its constrained directions.
        stiffness: The Winkler modulus :math:`k_f` (N/m^3), > 0.
        span: The core's extent (x0, x1) along the member (m); None: the whole length.

    Note:
        Collective.
    """
    v = ufl.TestFunction(model.W)
    n = cell_frame(model.mesh)[2]
    # Components 0..2 of a node's row: its area on cells of normal e_c (weight n_c^2); 3: all.
    form = sum(v[c] * n[c] ** 2 for c in range(3)) + v[3]
    areas = dolfinx.fem.assemble_vector(dolfinx.fem.form(form * ufl.dx))
    areas.scatter_reverse(dolfinx.la.InsertMode.add)
    rows = areas.array.reshape(-1, DOFS_PER_NODE)
    nodes = constraints.owned_nodes
    share = np.unique(nodes, return_counts=True)
    count = dict(zip(share[0].tolist(), share[1].tolist(), strict=True))
    normals = constraints.normals[constraints.owned_positions]
    covered = _covered_fraction(model, nodes, span)
    local = np.array(
        [
            stiffness * f * (rows[k, 3] if count[k] == 1 else float(rows[k, :3] @ nj**2))
            for k, nj, f in zip(nodes.tolist(), normals, covered, strict=True)
        ]
    )
    springs = np.zeros(constraints.size)
    for positions, values in model.mesh.comm.allgather((constraints.owned_positions, local)):
        springs[positions] = values
    return springs


def _covered_fraction(
    model: ShellModel, nodes: npt.NDArray[np.int32], span: tuple[float, float] | None
) -> npt.NDArray[np.float64]:
    """The fraction of each node's stretch along the member that ``span`` covers."""
    if span is None:
        return np.ones(nodes.size)
    section = model.section
    h = section.length / section.cells_along
    x = model.W.tabulate_dof_coordinates()[nodes, 0]
    low = np.maximum(x - 0.5 * h, 0.0)
    high = np.minimum(x + 0.5 * h, section.length)
    inside = np.minimum(high, span[1]) - np.maximum(low, span[0])
    return np.asarray(np.clip(inside / (high - low), 0.0, 1.0), dtype=float)


def _node_block(normals: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    r""":math:`Q = R^{-1}`, R the rows (normals, completion): :math:`(Q^{-1}u)_j = n_j\cdot u`."""
    rows = [np.asarray(n, dtype=float) for n in normals]
    basis: list[npt.NDArray[np.float64]] = []
    for n in rows:  # orthonormalised normals span the normals' plane
        v = n - sum((n @ q) * q for q in basis)
        basis.append(v / np.linalg.norm(v))
    while len(rows) < 3:
        cands = [e - sum((e @ q) * q for q in basis) for e in np.eye(3)]
        best = max(cands, key=lambda v: float(np.linalg.norm(v)))
        best = best / np.linalg.norm(best)
        basis.append(best)
        rows.append(best)
    R = np.vstack(rows)
    if abs(np.linalg.det(R)) < 1e-6:
        raise InputError("the core's normals at a node are (nearly) parallel")
    return np.linalg.inv(R)


def change_of_basis(model: ShellModel, constraints: CoreConstraints) -> PETSc.Mat:
    r"""The matrix T with :math:`u = T u'`: :math:`Q_k` on each constrained node's displacement.

    Returns:
        T, square, with W's layout; the caller must destroy it.

    Note:
        Collective.
    """
    V = model.W
    bs = V.dofmap.index_map_bs
    n_local = model.num_owned_dofs
    start = int(model.global_dofs(np.zeros(1, np.int32))[0]) if n_local else 0
    by_node: dict[int, list[npt.NDArray[np.float64]]] = {}
    normals = constraints.normals[constraints.owned_positions]
    for k, n in zip(constraints.owned_nodes.tolist(), normals, strict=True):
        by_node.setdefault(k, []).append(n)
    # Q_k depends on the node's normals alone, which repeat (a box's faces, a tube's
    # generators): each distinct set's block is computed once, the same bits.
    blocks: dict[bytes, npt.NDArray[np.float64]] = {}
    nodes = np.fromiter(by_node, dtype=np.int64, count=len(by_node))
    Qs = np.empty((nodes.size, 3, 3))
    for i, ns in enumerate(by_node.values()):
        key = np.array(ns).tobytes()
        if key not in blocks:
            blocks[key] = _node_block(np.array(ns))
        Qs[i] = blocks[key]
    # CSR: identity rows, the three displacement rows of a constrained node a 3x3 block.
    blocked = (nodes[:, None] * bs + np.arange(3)).ravel()  # rows, node by node
    counts = np.ones(n_local, dtype=np.int64)
    counts[blocked] = 3
    indptr = np.zeros(n_local + 1, dtype=np.int64)
    indptr[1:] = np.cumsum(counts)
    cols = np.empty(indptr[-1], dtype=np.int64)
    vals = np.empty(indptr[-1], dtype=PETSc.ScalarType)
    plain = np.flatnonzero(counts == 1)
    cols[indptr[plain]] = start + plain
    vals[indptr[plain]] = 1.0
    first = indptr[blocked][:, None] + np.arange(3)  # (rows, 3) positions of a block row
    cols[first] = start + (np.repeat(nodes, 3) * bs)[:, None] + np.arange(3)
    vals[first] = Qs.reshape(-1, 3)
    T = PETSc.Mat().createAIJ(
        ((n_local, None), (n_local, None)),  # type: ignore[arg-type]
        csr=(  # type: ignore[arg-type]
            indptr.astype(PETSc.IntType),
            cols.astype(PETSc.IntType),
            vals,
        ),
        comm=model.mesh.comm,
    )
    T.assemble()
    return T
