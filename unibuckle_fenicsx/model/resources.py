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

__all__ = ["BYTES_PER_DOF", "available_memory", "check_memory"]

#: Peak memory per (w, theta) DOF of a solve with MUMPS on one rank, rounded up from the
#: 5.8-7.8 kB of :doc:`/verification/tuning`.
BYTES_PER_DOF = 8000


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
    need = BYTES_PER_DOF * dofs
    free = available_memory()
    have = comm.allreduce(free if free is not None else -1, op=MPI.MIN)
    if have > 0 and need > have:
        raise InputError(
            f"{what} {dofs:,} DOFs, which need about {need / 1e9:.3g} GB "
            f"({BYTES_PER_DOF / 1000:.0f} kB per DOF), more than the {have / 1e9:.3g} GB "
            "available: use a coarser mesh or more machines"
        )
