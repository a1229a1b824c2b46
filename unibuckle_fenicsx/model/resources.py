"""The memory a solve will need, against what the machine has: refused before any mesh.

Hand-written: the estimate is the package's own (a peak per DOF from its solves), and the
machine's free memory is Linux's ``MemAvailable`` (the standard library has no portable
call for it; without /proc/meminfo no check is made).
"""

from __future__ import annotations

from mpi4py import MPI

from unibuckle_fenicsx.errors import InputError
from unibuckle_fenicsx.spec import ProblemSpec
from unibuckle_fenicsx.spec.base import in_file

__all__ = [
    "BYTES_PER_DOF",
    "BYTES_PER_SECTION_DOF",
    "available_memory",
    "check_memory",
    "check_section_memory",
]

#: Peak memory per (w, theta) DOF of a solve with MUMPS on one rank, rounded up from the
#: 5.8-7.8 kB of :doc:`/verification/tuning`.
BYTES_PER_DOF = 8000
#: Peak memory per DOF (six per node) of a section's solve on one rank: a hollow box's
#: free solve peaked at 15.1 and 14.9 kB per DOF on 87 120 and 347 040 DOFs, a tube's at
#: 13.7 kB on 96 696 (the process's whole resident memory); a core's search needs more
#: (about 1.3 to 1.6 times on 22 000 DOFs): rounded down, the least any section needs.
BYTES_PER_SECTION_DOF = 13_000


def available_memory() -> int | None:
    """Bytes of memory available to new processes (Linux ``MemAvailable``), or None."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def check_memory(spec: ProblemSpec, comm: MPI.Comm) -> None:
    """Refuse a mesh whose estimated memory exceeds what the machine has (collective).

    A plate meshed by gmsh is estimated at 3 DOFs per h^2 of its area (a file: not).

    Raises:
        InputError: The estimate exceeds the smallest available memory of the ranks.
    """
    plate = spec.plate
    if plate.file is not None:
        return
    if plate.meshed_by_gmsh:
        if spec.mesh.size is None:
            raise RuntimeError(
                "check_memory: expected spec.mesh.size is not None (an internal invariant)"
            )
        dofs = int(3 * plate.area / spec.mesh.size**2)
        (size, metres), (area, square) = in_file(spec.mesh.size, "m"), in_file(plate.area, "m^2")
        what = f"mesh.size = {size:g} {metres} on {area:.3g} {square} gives about"
    else:
        dofs = spec.mesh.num_dofs
        what = f"mesh.nx x mesh.ny = {spec.mesh.nx} x {spec.mesh.ny} gives"
    _check_bytes(dofs, BYTES_PER_DOF, what, "use a coarser mesh", comm)


def check_section_memory(dofs: int, size: float, comm: MPI.Comm) -> None:
    """Refuse a section whose ``dofs`` (estimated before meshing) need more memory than there is.

    ``size``: its ``mesh.size`` (m), named in the message in the file's units. Collective.

    Raises:
        InputError: :data:`BYTES_PER_SECTION_DOF` times ``dofs`` exceeds the smallest
            available memory of the ranks.
    """
    h, unit = in_file(size, "m")
    what = f"mesh.size = {h:g} {unit} gives about"
    _check_bytes(dofs, BYTES_PER_SECTION_DOF, what, "use a coarser mesh.size", comm)


def _check_bytes(dofs: int, per_dof: int, what: str, fix: str, comm: MPI.Comm) -> None:
    """Refuse ``dofs`` of ``per_dof`` bytes each beyond the ranks' smallest free memory."""
    need = per_dof * dofs
    free = available_memory()
    have = comm.allreduce(free if free is not None else -1, op=MPI.MIN)
    if have > 0 and need > have:
        raise InputError(
            f"{what} {dofs:,} DOFs, which need about {need / 1e9:.3g} GB "
            f"({per_dof / 1000:.0f} kB per DOF), more than the {have / 1e9:.3g} GB "
            f"available: {fix} or more machines"
        )
