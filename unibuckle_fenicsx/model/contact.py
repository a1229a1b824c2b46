"""Contact-node manager: obstacle zone -> constrained w-DOFs; candidate set -> removed DOFs.

The constrained set I holds the mesh nodes of the closed zone whose deflection is free
(nodes already fixed by an edge support are recorded but not counted). Nodes are numbered
0..i-1 in lexicographic (y, x) order of their coordinates, so a contact set, a sorted int64
array of these numbers, means the same nodes on every rank and for every partition.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.la
import ufl

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.errors import BilateralZoneError, EmptyZoneError, InputError
from unibuckle_fenicsx.model.structure import NodalDofs
from unibuckle_fenicsx.model.zones import discrete_zone
from unibuckle_fenicsx.spec import ObstacleSpec
from unibuckle_fenicsx.spec.base import in_file
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

__all__ = [
    "ZONE_TOLERANCE_CELLS",
    "ContactSetManager",
    "check_zone_has_nodes",
    "foundation_springs",
    "orientation",
    "smallest_cell_side",
    "tributary_areas",
    "zone_cells",
]


#: ``obstacle.tolerance`` may reach this fraction of the mesh's smallest cell side. The
#: tolerance is there to catch the nodes that lie on the zone's edge up to rounding or a
#: mesher's placement (1e-15 to 1e-9 of the plate); a tenth of a cell is far above that
#: and far below the next line of nodes, so it can never widen the zone by a row of
#: nodes (a wider zone is written as a wider zone).
ZONE_TOLERANCE_CELLS = 0.1

#: One obstacle, or several of them (a sequence).
ObstacleLike = ObstacleSpec | Sequence[ObstacleSpec]


def _as_tuple(obstacles: ObstacleLike) -> tuple[ObstacleSpec, ...]:
    return (obstacles,) if isinstance(obstacles, ObstacleSpec) else tuple(obstacles)


def _label(obstacles: tuple[ObstacleSpec, ...], k: int, labels: Sequence[str] | None) -> str:
    if labels is not None:
        return labels[k]
    return "obstacle" if len(obstacles) == 1 else f"obstacles[{k}]"


def check_zone_has_nodes(
    msh: dolfinx.mesh.Mesh,
    obstacles: ObstacleLike,
    size: float,
    labels: Sequence[str] | None = None,
) -> None:
    """Cheap pre-checks of the obstacle zones on the mesh nodes, before any solve.

    Raises :class:`InputError` if a zone's ``tolerance`` exceeds
    :data:`ZONE_TOLERANCE_CELLS` times the smallest cell side, :class:`EmptyZoneError` if
    a zone holds no mesh node, and :class:`BilateralZoneError` if a node lies in zones on
    both sides of the plate (a bilateral support there, not an obstacle).

    Args:
        msh: The mesh.
        obstacles: One obstacle or several.
        size: Plate size (scales the zones' default tolerance).
        labels: How the problem file names each obstacle (default "obstacle" or
            "obstacles[k]").

    Note:
        Collective.
    """
    found = _as_tuple(obstacles)
    _check_tolerances(msh, found, labels)
    x = msh.geometry.x
    n_owned = msh.geometry.index_map().size_local
    points = x[:n_owned].T
    inside = [o.contains(points, size) for o in found]
    for k, (o, mask) in enumerate(zip(found, inside, strict=True)):
        if msh.comm.allreduce(int(np.count_nonzero(mask)), op=MPI.SUM) == 0:
            raise EmptyZoneError(
                f"{_label(found, k, labels)}.{o.zone_key} {o.describe(None)} holds no free mesh "
                f"node: none of the {msh.geometry.index_map().size_global} mesh nodes lies in it; "
                "enlarge the zone or refine the mesh"
            )
    above = np.zeros(n_owned, dtype=bool)
    below = np.zeros(n_owned, dtype=bool)
    for o, mask in zip(found, inside, strict=True):
        if o.side == "above":
            above |= mask
        elif o.side == "below":
            below |= mask
    both = np.flatnonzero(above & below)
    local = x[both[0], :2].tolist() if both.size else None
    shared = [p for p in msh.comm.allgather(local) if p is not None]
    if shared:
        names = [_label(found, k, labels) for k in range(len(found))]
        (px, py), metres = in_file(shared[0], "m")
        raise BilateralZoneError(
            f"obstacle zones on both sides of the plate share mesh nodes, e.g. "
            f"({px:.6g}, {py:.6g}) {metres} ({', '.join(names)}: "
            f"{', '.join(f'{o.describe(None)} ({o.side})' for o in found)}): "
            + (
                'a foundation on both sides is one zone with side = "both" (a bilateral '
                "foundation); make the zones disjoint"
                if any(o.kind == "tensionless" for o in found)
                else "a node held on both sides is a bilateral support (w = 0), not an "
                "obstacle; give an edge its [edges.NAME] support, or make the zones disjoint"
            )
        )


def smallest_cell_side(msh: dolfinx.mesh.Mesh) -> float:
    """The shortest cell edge of the mesh (m).

    Note:
        Collective.
    """
    msh.topology.create_entities(1)
    edges = np.arange(msh.topology.index_map(1).size_local, dtype=np.int32)
    local = float(msh.h(1, edges).min()) if edges.size else np.inf
    return float(msh.comm.allreduce(local, op=MPI.MIN))


def _check_tolerances(
    msh: dolfinx.mesh.Mesh, found: tuple[ObstacleSpec, ...], labels: Sequence[str] | None
) -> None:
    """Refuse a zone ``tolerance`` above :data:`ZONE_TOLERANCE_CELLS` of the smallest cell."""
    given = [(k, o) for k, o in enumerate(found) if o.tolerance is not None]
    if not given:
        return
    h = smallest_cell_side(msh)
    bound = ZONE_TOLERANCE_CELLS * h
    for k, o in given:
        if o.tolerance is not None and o.tolerance > bound:
            (tol, high, cell), name = in_file([o.tolerance, bound, h], "m")
            raise InputError(
                f"{_label(found, k, labels)}.tolerance = {tol:g} {name} must lie in [0, "
                f"{high:.3g}] {name} (a tenth of the smallest cell side, {cell:.3g} {name}): "
                "the tolerance only catches nodes on the zone's edge up to rounding; a "
                "larger one would widen the zone by whole rows of nodes. To widen the "
                f"zone, enlarge {_label(found, k, labels)}.{o.zone_key}"
            )


def orientation(
    values: npt.NDArray[np.float64],
    forces: npt.NDArray[np.float64],
    active: npt.NDArray[np.int64],
    tau: float,
) -> float:
    r"""Sign (+1 or -1) that puts a reduced mode on the admissible side of the obstacle.

    A mode's sign is free; the admissible side has :math:`s u_k \le \tau` on
    :math:`I \setminus Z`. If only one side is admissible it is chosen; if neither,
    the side with the smaller violation (for reporting); if both (the mode vanishes on
    :math:`I \setminus Z`, e.g. Z = I), the side on which the obstacle pushes
    (:math:`s r_k \le \tau` on Z), + when both push or both pull.

    Args:
        values: Mode at the constrained nodes, relative to max |w| (unoriented).
        forces: :math:`r = Au - \lambda Bu` at the constrained nodes, relative to
            :math:`\|Au\|_\infty`, of the same (unoriented) mode.
        active: The contact set Z (node numbers).
        tau: Feasibility tolerance.

    Returns:
        The sign to apply to the mode.
    """
    free = np.ones(values.size, dtype=bool)
    free[active] = False
    up = float(values[free].max()) if free.any() else -np.inf
    down = float(-values[free].min()) if free.any() else -np.inf
    if up <= tau and down <= tau:
        pull = float(forces[~free].max()) if (~free).any() else -np.inf
        push = float(-forces[~free].min()) if (~free).any() else -np.inf
        return -1.0 if pull > tau and push < pull else 1.0
    if up <= tau:
        return 1.0
    if down <= tau:
        return -1.0
    return 1.0 if up <= down else -1.0


@dataclass(frozen=True)
class _Owned:
    positions: npt.NDArray[np.int64]  # position k in 0..i-1 of each owned constrained node
    local_dofs: npt.NDArray[np.int32]  # W local dof of each
    global_dofs: npt.NDArray[np.int64]  # W global dof of each


def tributary_areas(model: NodalDofs, obstacle: ObstacleSpec | None = None) -> dolfinx.la.Vector:
    r"""Lumped areas :math:`\int_{\omega_h} \varphi_k\,dx` of the w-space's nodes.

    The row sums of the Q1 mass matrix restricted to :math:`\omega_h`: a lumped Winkler
    foundation puts the spring :math:`k_f \int_{\omega_h} \varphi_k\,dx` at node k. With
    an ``obstacle``, :math:`\omega_h` is its *discrete zone*, the cells whose nodes all lie
    in the closed zone (:mod:`~unibuckle_fenicsx.model.zones`), so a node on the zone's
    boundary carries only the covered part of its area (half on a straight edge, a quarter
    at a convex corner); without one, the whole plate. Owned nodes and ghosts.

    Raises:
        EmptyZoneError: The obstacle's discrete zone holds no cell (a foundation acts on
            an area; a zone thinner than a cell has none on this mesh).

    Note:
        Collective.
    """
    v = ufl.TestFunction(model.Vw)
    if obstacle is None or obstacle.zone == "all":
        dx = ufl.dx(domain=model.mesh)
    else:
        dx = ufl.Measure(
            "dx", domain=model.mesh, subdomain_data=zone_cells(model, obstacle), subdomain_id=1
        )
    areas = dolfinx.fem.assemble_vector(dolfinx.fem.form(v * dx))
    areas.scatter_reverse(dolfinx.la.InsertMode.add)
    areas.scatter_forward()
    if obstacle is not None:
        n_owned = model.Vw.dofmap.index_map.size_local
        total = model.mesh.comm.allreduce(float(areas.array[:n_owned].sum()), op=MPI.SUM)
        if total <= 0.0:
            raise EmptyZoneError(
                f"obstacle.{obstacle.zone_key} {obstacle.describe(None)} of a foundation "
                "(foundation_stiffness) covers no cell of the mesh: its springs act on the "
                "cells whose nodes all lie in the zone; widen the zone to at least one cell, "
                'refine the mesh, or give a line or point of springs as [[points]] kind = "spring"'
            )
    return areas


def zone_cells(model: NodalDofs, obstacle: ObstacleSpec) -> dolfinx.mesh.MeshTags:
    """Cell tags (value 1) of the obstacle's discrete zone: cells with every node in the zone.

    Not collective.
    """
    msh = model.mesh
    whole, _ = discrete_zone(msh, obstacle, model.extent)
    cells = np.flatnonzero(whole).astype(np.int32)  # owned cells: those the form integrates
    return dolfinx.mesh.meshtags(msh, msh.topology.dim, cells, np.ones(cells.size, np.int32))


def _zone_dofs(
    model: NodalDofs, obstacle: ObstacleSpec, size: float
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]:
    """(W dofs, Vw dofs) of the w-DOFs of the zone's nodes, ghosts included (not collective)."""
    dofs_W, dofs_Vw = dolfinx.fem.locate_dofs_geometrical(
        (model.w_subspace, model.Vw), lambda x: obstacle.contains(x, size)
    )
    return np.asarray(dofs_W, dtype=np.int32), np.asarray(dofs_Vw, dtype=np.int32)


def foundation_springs(
    model: NodalDofs, foundations: Sequence[ObstacleSpec]
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    r"""Global W rows owned by this rank and lumped spring stiffnesses of ``foundations``.

    Node k of a zone gets :math:`k_f \int_{\omega_h} \varphi_k\,dx` (N/m) over the zone's
    discrete zone :math:`\omega_h` (:func:`tributary_areas`), summed over the zones holding
    it; nodes held by supports (edges, bilateral points) are left out.

    Note:
        Collective.
    """
    size = model.extent
    springs: dict[int, float] = {}
    for o in foundations:
        if o.foundation_stiffness is None:
            raise RuntimeError(
                "foundation_springs: expected o.foundation_stiffness is not None (an internal "
                "invariant)"
            )
        areas = tributary_areas(model, o).array
        dofs_W, dofs_Vw = _zone_dofs(model, o, size)
        for dw, dv in zip(dofs_W.tolist(), dofs_Vw.tolist(), strict=True):
            springs[dw] = springs.get(dw, 0.0) + o.foundation_stiffness * float(areas[dv])
    local = np.array(sorted(springs), dtype=np.int32)
    keep = (local < model.num_owned_dofs) & ~np.isin(local, model.bc_dofs)
    local = local[keep]
    values = np.array([springs[d] for d in local.tolist()], dtype=float)
    return model.global_dofs(local), values


def _merge_zones(
    model: NodalDofs,
    obstacles: tuple[ObstacleSpec, ...],
    zones: list[tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]],
    tensionless: bool,
) -> tuple[
    npt.NDArray[np.int32],
    npt.NDArray[np.int32],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    bool,
]:
    """The zones' nodes united (this process's): W and Vw dofs, signs, gaps, springs.

    A node in several zones takes the smallest gap and the sum of its zones' springs
    (each zone's on its own discrete zone); the last item says whether zones on both
    sides share one of this process's nodes. ``zones``: each obstacle's (W dofs, Vw dofs)
    (:func:`_zone_dofs`).
    """
    # Every zone's nodes in the obstacles' order; a node in several zones appears once
    # per zone, and its entries are merged below in that order.
    all_W = np.concatenate([dofs_W for dofs_W, _ in zones])
    all_Vw = np.concatenate([dofs_Vw for _, dofs_Vw in zones])
    counts = [len(dofs_W) for dofs_W, _ in zones]

    def per_node(value: Callable[[ObstacleSpec], float]) -> npt.NDArray[np.float64]:
        values = [value(o) for o in obstacles]
        return np.repeat(np.asarray(values, dtype=float), counts)

    order_W, first, node = np.unique(all_W, return_index=True, return_inverse=True)
    dofs_W = order_W.astype(np.int32)
    dofs_Vw = all_Vw[first].astype(np.int32)  # a W dof has one Vw dof
    all_signs = per_node(lambda o: o.sign)
    signs = np.full(len(order_W), np.inf)
    np.minimum.at(signs, node, all_signs)
    highest = np.full(len(order_W), -np.inf)
    np.maximum.at(highest, node, all_signs)
    conflict = bool(np.any(signs != highest))
    gaps = np.full(len(order_W), np.inf)
    np.minimum.at(gaps, node, per_node(lambda o: o.gap))
    springs = np.zeros(len(order_W))
    if tensionless:
        if any(o.foundation_stiffness is None for o in obstacles):
            raise RuntimeError(
                "_merge_zones: expected o.foundation_stiffness is not None (an internal invariant)"
            )
        # Each zone's springs on its own discrete zone (the same weights as a bilateral
        # foundation's), summed zone by zone from 0.0 in the obstacles' order
        # (np.add.at is unbuffered).
        weights = np.concatenate(
            [
                float(o.foundation_stiffness or 0.0) * tributary_areas(model, o).array[dofs_Vw_k]
                for o, (_, dofs_Vw_k) in zip(obstacles, zones, strict=True)
            ]
        )
        np.add.at(springs, node, weights)
    return dofs_W, dofs_Vw, signs, gaps, springs, conflict


class ContactSetManager:
    r"""Constrained w-DOFs of the obstacle zones, and candidate sets as removed DOFs.

    The manager works in *oriented* values :math:`z_k = s_k w_k`, with :math:`s_k = +1`
    at the nodes of an obstacle above the plate and -1 below, so that every constraint
    reads :math:`z_k \le 0` and every algorithm sees one kind of obstacle:
    :meth:`values` returns z, :meth:`scatter` takes z.

    Args:
        model: The plate model (the assembled pencil, or any :class:`NodalDofs`).
        obstacles: One obstacle or several (their zones' nodes are united; a node in
            zones on both sides raises :class:`BilateralZoneError`).

    Attributes:
        coordinates: (i, 2) coordinates of the constrained nodes, same on all ranks.
        signs: (i,) :math:`s_k`, same on all ranks.
        stiffness: (i,) lumped spring stiffness (N/m) of each node, same on all ranks,
            for tensionless foundations (:func:`foundation_springs`); None for rigid
            obstacles.
        num_edge_fixed: Nodes of the zones already fixed (w = 0) by edge supports.
        gaps: (i,) the obstacle's gap g (m) at each node (the constraint is
            :math:`s_k w_k \le g_k`), same on all ranks; zero but in the nonlinear
            analysis (the linear problem leaves obstacles with a gap out).
        symmetries: Permutations ``perm`` of the constrained nodes (node k to
            ``perm[k]``) under which the whole problem is invariant, so that a contact
            set and its image have the same KKT points' loads: empty for a plate; a
            square box's quarter turns, a tube's turns about its axis
            (:class:`~unibuckle_fenicsx.model.shell.problem.SectionContact`).

    Note:
        Construction is collective. Raises :class:`EmptyZoneError` if the zones hold no
        free mesh node.
    """

    symmetries: tuple[npt.NDArray[np.int64], ...] = ()

    def __init__(self, model: NodalDofs, obstacles: ObstacleLike) -> None:
        self.model = model
        self.obstacles = _as_tuple(obstacles)
        if not self.obstacles:
            raise InputError("ContactSetManager needs at least one obstacle")
        kinds = {o.kind for o in self.obstacles}
        if "bilateral" in kinds or len(kinds) != 1:
            raise InputError(
                "ContactSetManager takes one-sided obstacles of one kind: all rigid or all "
                f"tensionless foundations, got {sorted(kinds)}"
            )
        comm = model.mesh.comm
        Vw = model.Vw
        size = model.extent
        tensionless = kinds == {"tensionless"}
        zones = [_zone_dofs(model, o, size) for o in self.obstacles]
        dofs_W, dofs_Vw, signs, gaps, springs, conflict = _merge_zones(
            model, self.obstacles, zones, tensionless
        )
        if comm.allreduce(conflict, op=MPI.LOR):
            raise BilateralZoneError(
                "obstacle zones on both sides of the plate share a mesh node: a bilateral "
                "support (w = 0), not an obstacle; give an edge its [edges.NAME] support, "
                "or make the zones disjoint"
            )
        n_owned = model.num_owned_dofs
        keep = dofs_W < n_owned
        fixed = np.isin(dofs_W, model.bc_dofs)
        self.num_edge_fixed = int(comm.allreduce(int((fixed & keep).sum()), op=MPI.SUM))
        keep &= ~fixed
        if tensionless:  # a zone node on no cell of the discrete zone has no foundation
            keep &= springs > 0.0
        dofs_W, dofs_Vw, signs, springs = dofs_W[keep], dofs_Vw[keep], signs[keep], springs[keep]
        gaps = gaps[keep]
        xy = Vw.tabulate_dof_coordinates()[dofs_Vw, :2]

        gathered = comm.allgather(xy)
        # Round away partition-dependent last bits (0.0 vs 9e-19), and -0.0.
        all_xy = np.round(np.vstack(gathered), 12) + 0.0
        # Quantise before sorting: equal nodes must sort alike on every partition.
        keys = np.round(all_xy / (GEOMETRY_RTOL * size)).astype(np.int64)
        order = np.lexsort((keys[:, 0], keys[:, 1]))
        self.coordinates: npt.NDArray[np.float64] = all_xy[order]
        self.signs: npt.NDArray[np.float64] = np.concatenate(comm.allgather(signs))[order]
        self.gaps: npt.NDArray[np.float64] = np.concatenate(comm.allgather(gaps))[order]
        self.stiffness: npt.NDArray[np.float64] | None = (
            np.concatenate(comm.allgather(springs))[order] if tensionless else None
        )
        if self.coordinates.shape[0] == 0:
            raise self._empty_zone()
        offset = int(sum(len(g) for g in gathered[: comm.rank]))
        rank_pos = np.empty(len(order), dtype=np.int64)
        rank_pos[order] = np.arange(len(order), dtype=np.int64)
        positions = rank_pos[offset : offset + len(dofs_W)]
        self._owned = _Owned(positions, dofs_W.astype(np.int32), model.global_dofs(dofs_W))

    @property
    def obstacle(self) -> ObstacleSpec:
        """The first obstacle (the only one for a problem with one ``[obstacle]``)."""
        return self.obstacles[0]

    def _empty_zone(self) -> EmptyZoneError:
        """The error for zones that hold no free mesh node (collective: the cell size)."""
        nx = self.model.mesh.topology.index_map(0).size_global
        zones = "; ".join(o.describe(None) for o in self.obstacles)
        spacing, metres = in_file(self._spacing(), "m")
        named = "/".join(dict.fromkeys(o.zone_key for o in self.obstacles))
        return EmptyZoneError(
            f"obstacle.{named} {zones} holds no free mesh node ({self.num_edge_fixed} "
            f"zone nodes are held by supports: edges or bilateral points; the mesh has "
            f"{nx} vertices, cells "
            f"up to {spacing:.3g} {metres} across their diagonal): enlarge the zone or "
            "refine the mesh"
        )

    def _spacing(self) -> float:
        msh = self.model.mesh
        h = msh.h(msh.topology.dim, np.arange(msh.topology.index_map(2).size_local, dtype=np.int32))
        return float(msh.comm.allreduce(h.max() if h.size else 0.0, op=MPI.MAX))

    @property
    def size(self) -> int:
        """Number i of constrained nodes."""
        return int(self.coordinates.shape[0])

    @property
    def owned_positions(self) -> npt.NDArray[np.int64]:
        """Node numbers (0..i-1) of the constrained nodes owned by this rank."""
        return self._owned.positions

    @property
    def owned_local_dofs(self) -> npt.NDArray[np.int32]:
        """Local W DOF of each owned constrained node (order of :attr:`owned_positions`)."""
        return self._owned.local_dofs

    @property
    def owned_signs(self) -> npt.NDArray[np.float64]:
        """:math:`s_k` of each owned constrained node (order of :attr:`owned_positions`)."""
        return self.signs[self._owned.positions]

    def removed_rows(self, active: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        """Global W rows owned by this rank of the nodes ``active`` (node numbers)."""
        mask = np.isin(self._owned.positions, active)
        return self._owned.global_dofs[mask]

    def node_rows(
        self, active: npt.NDArray[np.int64]
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """(global W rows, node numbers) owned by this rank of the nodes ``active``."""
        mask = np.isin(self._owned.positions, active)
        return self._owned.global_dofs[mask], self._owned.positions[mask]

    def values(self, u: PETSc.Vec) -> npt.NDArray[np.float64]:
        """Oriented entries :math:`s_k u_k` of the W-vector ``u`` at the constrained nodes.

        (i,), same on all ranks.

        Note:
            Collective.
        """
        local = np.zeros(self.size)
        local[self._owned.positions] = u.array_r[self._owned.local_dofs]
        self.model.mesh.comm.Allreduce(MPI.IN_PLACE, local, op=MPI.SUM)
        return self.signs * local

    def scatter(self, values: npt.NDArray[np.float64], u: PETSc.Vec) -> PETSc.Vec:
        r"""Set ``u`` to :math:`s_k` times ``values`` at the constrained nodes, zero elsewhere.

        The inverse of :meth:`values` for a vector supported on I. Not collective.
        """
        u.zeroEntries()
        positions = self._owned.positions
        u.array[self._owned.local_dofs] = self.signs[positions] * values[positions]
        return u

    def global_rows(self) -> npt.NDArray[np.int64]:
        """Global W row of every constrained node, (i,), same on all ranks (collective)."""
        comm = self.model.mesh.comm
        positions = np.concatenate(comm.allgather(self._owned.positions))
        dofs = np.concatenate(comm.allgather(self._owned.global_dofs))
        rows = np.empty(self.size, dtype=np.int64)
        rows[positions] = dofs
        return rows

    def indicator(self) -> dolfinx.fem.Function:
        """Function on the w-space: 1 at the constrained nodes, 0 elsewhere (for output)."""
        return self.node_function(np.arange(self.size, dtype=np.int64), "obstacle_zone")

    def node_function(
        self,
        active: npt.NDArray[np.int64],
        name: str = "contact",
        values: npt.NDArray[np.float64] | None = None,
    ) -> dolfinx.fem.Function:
        """Function on the w-space: ``values`` (default 1) at the nodes ``active``, 0 elsewhere.

        ``values`` holds one number per node of ``active``, in its order.
        """
        f = dolfinx.fem.Function(self.model.Vw, name=name)
        inverse = np.full(self.model.num_owned_dofs, -1, dtype=np.int64)
        n_owned_w = self.model.Vw.dofmap.index_map.size_local
        inverse[self.model.w_dofs[:n_owned_w]] = np.arange(n_owned_w)
        active = np.asarray(active, dtype=np.int64)
        by_node = np.zeros(self.size)
        by_node[active] = 1.0 if values is None else np.asarray(values, dtype=float)
        owned = self._owned.positions
        mask = np.isin(owned, active)
        f.x.array[inverse[self._owned.local_dofs[mask]]] = by_node[owned[mask]]
        f.x.scatter_forward()
        return f
