r"""Point restraints on the mesh: bolts, tie bars and studs at points of the plate.

Each point of a :class:`~unibuckle_fenicsx.spec.PointSpec` acts on the deflection DOF
of the mesh node nearest to it; the distance from the point to that node (the *snap
distance*) is reported. A point that is not a node could be held exactly by a
multi-point constraint on the w-DOFs of its cell (w(p) as the bilinear combination of
four nodes); that would change the contact set's unit from a node to a combination of
nodes, which every algorithm and the certificate take as a DOF, so it is not done: the
points snap, and a mesh with nodes at the points (a spacing that is a multiple of the
cell size) has a snap distance of zero.

- "bilateral": w = 0 at the node, a zero Dirichlet condition (A diagonal 1, B 0);
- "spring": :math:`k_p` (N/m) added to A's diagonal at the node's w-DOF;
- "one-sided": the node joins the constrained set of the obstacle's cone (w <= 0 for a
  point above, w >= 0 below), through an obstacle whose zone is exactly these nodes.

Ties (a point equidistant from two nodes) go to the node with the smaller (y, x), so
the choice does not depend on the partition.

A point whose node is held already restrains nothing: on an edge whose support holds w
(a mistyped coordinate, or the edge points of a grid), or, for a spring or a one-sided
point, on a bilateral point's node. :func:`mark_held` finds them; the result's JSON
(``details.point_restraints[k].restraining_nothing``) and its summary list them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

from mpi4py import MPI

import dolfinx

import numpy as np
import numpy.typing as npt

from unibuckle_fenicsx.spec import ObstacleSpec, PlateSpec, PointSpec
from unibuckle_fenicsx.tolerances import GEOMETRY_RTOL

__all__ = [
    "SnappedPoints",
    "mark_held",
    "one_sided_conflicts",
    "point_bcs",
    "point_obstacles",
    "point_springs",
    "snap_points",
]


@dataclass(frozen=True)
class SnappedPoints:
    """The points of one :class:`~unibuckle_fenicsx.spec.PointSpec` on the mesh.

    Attributes:
        spec: The restraint.
        points: The requested points (n, 2) (m).
        nodes: The mesh node each acts on (n, 2) (m), same on all ranks.
        distances: The snap distances (n,) (m).
        held: Per point, whether its node is held already (:func:`mark_held`): the point
            restrains nothing; all False until marked.
    """

    spec: PointSpec
    points: npt.NDArray[np.float64]
    nodes: npt.NDArray[np.float64]
    distances: npt.NDArray[np.float64]
    held: npt.NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))

    @property
    def idle_points(self) -> npt.NDArray[np.float64]:
        """The requested points (k, 2) (m) whose node is held already: they restrain nothing."""
        if self.held.size != len(self.points):
            return np.empty((0, 2))
        return self.points[self.held]

    @property
    def unique_nodes(self) -> npt.NDArray[np.float64]:
        """The distinct nodes (m, 2)."""
        return np.unique(self.nodes, axis=0)

    def report(self) -> dict[str, object]:
        """JSON-ready summary: what, how many points and nodes, the largest snap distance."""
        return {
            "restraint": self.spec.describe(),
            "kind": self.spec.kind,
            "points": len(self.points),
            "nodes": len(self.unique_nodes),
            "max_snap_distance_m": float(self.distances.max()),
            "restraining_nothing": self.idle_points.tolist(),
        }

    def matches(self, x: npt.NDArray[np.float64], tol: float) -> npt.NDArray[np.bool_]:
        """Mask of the coordinates ``x`` (3, n) lying on one of the nodes (within ``tol``)."""
        nodes = self.unique_nodes
        d = np.abs(x[:2].T[:, None, :] - nodes[None, :, :]).max(axis=2)
        return np.asarray((d <= tol).any(axis=1))


def snap_points(
    Vw: dolfinx.fem.FunctionSpace, plate: PlateSpec, points: Sequence[PointSpec]
) -> list[SnappedPoints]:
    """The nearest mesh node of every point of ``points`` (collective; same on all ranks)."""
    comm = Vw.mesh.comm
    size = max(plate.length, plate.width)
    n_owned = Vw.dofmap.index_map.size_local
    xy = Vw.tabulate_dof_coordinates()[:n_owned, :2]
    out = []
    for spec in points:
        wanted = spec.locations(plate)
        best: list[tuple[float, float, float, float]] = []
        for p in wanted:
            if len(xy):
                d = np.hypot(xy[:, 0] - p[0], xy[:, 1] - p[1])
                # Distance quantised far below any cell size; ties by (y, x).
                quantised = np.round(d / (GEOMETRY_RTOL * size))
                k = int(np.lexsort((xy[:, 0], xy[:, 1], quantised))[0])
                best.append((float(quantised[k]), float(xy[k, 1]), float(xy[k, 0]), float(d[k])))
            else:
                best.append((np.inf, np.inf, np.inf, np.inf))
        gathered = comm.allgather(best)
        chosen = [min(candidates) for candidates in zip(*gathered, strict=True)]
        nodes = np.array([[c[2], c[1]] for c in chosen], dtype=float).reshape(-1, 2)
        distances = np.array([c[3] for c in chosen], dtype=float)
        distances[distances <= GEOMETRY_RTOL * size] = 0.0  # rounding of coordinates, not a snap
        out.append(SnappedPoints(spec, wanted, nodes, distances))
    return out


def mark_held(
    Vw: dolfinx.fem.FunctionSpace,
    w_dofs: npt.NDArray[np.int32],
    edge_dofs: npt.NDArray[np.int32],
    snapped: Sequence[SnappedPoints],
    plate: PlateSpec,
) -> list[SnappedPoints]:
    """``snapped`` with ``SnappedPoints.held`` set: the points that restrain nothing.

    A point's node is held when an edge support holds its w (``edge_dofs``: the local W
    DOFs of the edge conditions; ``w_dofs`` maps Vw's local DOFs to W's); a spring's or a
    one-sided point's also when a bilateral point holds it (w = 0 there already).
    Collective; the same on every rank.
    """
    comm = Vw.mesh.comm
    tol = node_tolerance(plate)
    n_owned = Vw.dofmap.index_map.size_local
    xy = Vw.tabulate_dof_coordinates()[:n_owned, :2]
    held_xy = xy[np.isin(w_dofs[:n_owned], edge_dofs)]
    bilateral = [g.unique_nodes for g in snapped if g.spec.kind == "bilateral"]
    tied = np.concatenate(bilateral) if bilateral else np.empty((0, 2))
    out = []
    for g in snapped:
        on_edge = np.zeros(len(g.nodes), dtype=np.int8)
        if len(held_xy):
            d = np.abs(g.nodes[:, None, :] - held_xy[None, :, :]).max(axis=2)
            on_edge[:] = (d <= tol).any(axis=1)
        comm.Allreduce(MPI.IN_PLACE, on_edge, op=MPI.MAX)
        held = on_edge.astype(bool)
        if g.spec.kind != "bilateral" and len(tied):
            held |= (np.abs(g.nodes[:, None, :] - tied[None, :, :]).max(axis=2) <= tol).any(axis=1)
        out.append(replace(g, held=held))
    return out


def one_sided_conflicts(
    snapped: Sequence[SnappedPoints], obstacles: Sequence[ObstacleSpec], plate: PlateSpec
) -> list[int]:
    """Indices of the one-sided points with a node held from the other side too.

    The other side: an obstacle zone of the other ``side``, or a one-sided point of the
    other side on the same node (together they hold w = 0 there). Serial (the snapped
    nodes are the same on every rank).
    """
    tol = node_tolerance(plate)
    size = max(plate.length, plate.width)
    out = []
    for k, g in enumerate(snapped):
        if g.spec.kind != "one-sided":
            continue
        nodes = g.unique_nodes
        x = np.vstack([nodes.T, np.zeros(len(nodes))])
        clash = any(
            o.side not in (g.spec.side, "both") and o.contains(x, size).any() for o in obstacles
        )
        for other in snapped:
            if other.spec.kind == "one-sided" and other.spec.side != g.spec.side:
                clash = clash or bool(other.matches(x, tol).any())
        if clash:
            out.append(k)
    return out


def node_tolerance(plate: PlateSpec) -> float:
    """Tolerance for a dof coordinate to equal a snapped node (m)."""
    (x0, y0), (x1, y1) = plate.corners
    size = max(plate.length, plate.width)
    return 1e-10 * size + 64 * np.finfo(float).eps * max(abs(x0), abs(x1), abs(y0), abs(y1))


def point_obstacles(snapped: Sequence[SnappedPoints], plate: PlateSpec) -> list[ObstacleSpec]:
    """One obstacle per side whose zone is exactly the one-sided points' nodes."""
    tol = node_tolerance(plate)
    out = []
    for side in ("above", "below"):
        groups = [s for s in snapped if s.spec.kind == "one-sided" and s.spec.side == side]
        if not groups:
            continue

        def zone(
            x: npt.NDArray[np.float64], groups: list[SnappedPoints] = groups
        ) -> npt.NDArray[np.bool_]:
            mask = np.zeros(x.shape[1], dtype=bool)
            for g in groups:
                mask |= g.matches(x, tol)
            return mask

        zone.__name__ = f"one-sided points ({side})"
        out.append(ObstacleSpec(zone=zone, side=side))
    return out


def point_bcs(
    W: dolfinx.fem.FunctionSpace,
    Vw: dolfinx.fem.FunctionSpace,
    snapped: Sequence[SnappedPoints],
    plate: PlateSpec,
    *,
    w_sub: int = 0,
) -> list[dolfinx.fem.DirichletBC]:
    """Zero Dirichlet conditions on w at the nodes of the bilateral points (collective)."""
    groups = [s for s in snapped if s.spec.kind == "bilateral"]
    if not groups:
        return []
    tol = node_tolerance(plate)

    def on_nodes(x: npt.NDArray[np.float64]) -> npt.NDArray[np.bool_]:
        mask = np.zeros(x.shape[1], dtype=bool)
        for g in groups:
            mask |= g.matches(x, tol)
        return mask

    dofs = dolfinx.fem.locate_dofs_geometrical((W.sub(w_sub), Vw), on_nodes)
    return [dolfinx.fem.dirichletbc(0.0, dofs[0], W.sub(w_sub))]


def point_springs(
    Vw: dolfinx.fem.FunctionSpace,
    w_dofs: npt.NDArray[np.int32],
    snapped: Sequence[SnappedPoints],
    plate: PlateSpec,
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.float64]]:
    """Local W dofs (owned) of the spring points' nodes and their stiffness (N/m).

    Points on the same node add up.
    """
    tol = node_tolerance(plate)
    n_owned = Vw.dofmap.index_map.size_local
    xy = Vw.tabulate_dof_coordinates()[:n_owned].T
    stiffness = np.zeros(n_owned)
    for g in snapped:
        if g.spec.kind != "spring":
            continue
        if g.spec.stiffness is None:
            raise RuntimeError(
                "point_springs: expected g.spec.stiffness is not None (an internal invariant)"
            )
        for node in g.nodes:
            d = np.abs(xy[:2].T - node).max(axis=1) if n_owned else np.empty(0)
            stiffness[d <= tol] += g.spec.stiffness
    local = np.flatnonzero(stiffness)
    return w_dofs[local].astype(np.int32), stiffness[local]
