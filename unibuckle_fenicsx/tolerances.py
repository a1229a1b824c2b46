"""Every numerical tolerance of the package, each with what it bounds and why its value.

Relative tolerances compare computed loads (Pa) or nodal values with each other; the
eigen solver's default relative tolerance (``solver.eps_tol``, 1e-10) is the accuracy of a
computed load, so no two loads are told apart below it. On thin plates that is not so:
double precision fixes a load only to its ``load_resolution``
(:meth:`~unibuckle_fenicsx.model.problem.Problem.load_resolution`, 1e-9 to 1e-8
at t/b = 1e-3), and two solves of one contact set at different shifts differ by that.
The tolerances below were not raised to it: where a comparison of loads from different
solves decides (the empty set against the free load), the same pair is reused instead
(:meth:`~unibuckle_fenicsx.model.problem.UnilateralProblem.evaluate`); where a feasible
non-KKT mode would replace the active set's KKT point, it must lie lower by more than the
KKT point's resolution; elsewhere such a comparison can at worst deny "proven" or a tie
that lies within rounding. The problem
file's own tolerances (``solver.tau``, ``solver.eps_tol``) are inputs, documented with
the solver options, not here.
"""

from __future__ import annotations

__all__ = [
    "ARC_RTOL",
    "BRACKET_GAP",
    "DIVISION_FLOOR",
    "ENERGY_TIE_RTOL",
    "EXHAUSTED_NORM",
    "FREE_CHECK_RESOLUTION",
    "GEOMETRY_RTOL",
    "KNEE_RTOL",
    "LOAD_TIE_RTOL",
    "MERIT_RTOL",
    "NONLINEAR_ATOL",
    "NULL_GEOMETRIC_STIFFNESS",
    "PRESSING_RTOL",
    "PROOF_GAP",
    "PROOF_RTOL",
    "RESIDUAL_ROUNDING",
    "ROUNDING_RTOL",
    "SAME_DIRECTION",
    "SMALLEST_RTOL_FACTOR",
    "TWIN_RTOL",
    "ZERO_STEP",
]

# -- loads compared by the algorithms ---------------------------------------------------

#: Loads within this relative distance of the smallest tie in the enumeration, which then
#: picks the lexicographically smallest set: the eigen solver's tolerance, below which two
#: computed loads cannot be told apart.
LOAD_TIE_RTOL = 1e-10
#: An algorithm's lower bound within this relative distance of its load closes the
#: bracket (the global optimum is proven): the eigen solver's tolerance, for the same reason.
PROOF_RTOL = 1e-10
#: KKT points whose loads agree within this relative distance are equal-load twins (mirror
#: images, or the same point reached from two seeds): a hundred times the eigen solver's
#: tolerance, since two solves from different starts differ by a few of its units.
TWIN_RTOL = 1e-8
#: A strict comparison of two computed values ignores relative differences below this:
#: nodes within it of the largest value count as the largest (a symmetric mode's mirror
#: nodes differ by rounding only), a load must drop by more than it to count as lower, a
#: gap within it of a bound is that bound; ten times the eigen tolerance.
ROUNDING_RTOL = 1e-9

# -- the penalty method ------------------------------------------------------------------

#: The two orientations' penetration energies tie within this relative distance: the free
#: mode of a symmetric problem ties exactly, and computed with an eigen tolerance of 1e-10
#: its two energies differ by about that, so 1e-6 leaves four orders of margin either way.
ENERGY_TIE_RTOL = 1e-6

# -- the monotone arc methods (feasible descent, foundation) ----------------------------

#: A direction d within this angle of the iterate u is u: an eigenvector is accurate to
#: about the eigen tolerance over the spectral gap, and a smaller threshold would make
#: round-off a step.
SAME_DIRECTION = 1e-8
#: A blocking angle below this fraction of the step's full angle is a zero step: the node
#: is at the obstacle up to round-off of the angle.
ZERO_STEP = 1e-9
#: The foundation's arc descent stops when a step lowers the quotient by less than this,
#: relatively: a few units of the double precision of a quotient of two assembled forms.
ARC_RTOL = 1e-12
#: A node presses the tensionless foundation when it moves towards it by more than this
#: fraction of max|w|. An eigenvector's nodal values carry rounding of some 1e-10 of
#: max|w|, so with 0 a node lying on the foundation (a node of an edge line, a nodal line of
#: the mode) presses or not with the number of ranks (:doc:`/verification/tuning`).
PRESSING_RTOL = ROUNDING_RTOL

# -- the interior point ------------------------------------------------------------------

#: The rounding level of the interior point's residual :math:`F_u` is this many units of
#: double precision of :math:`(|A| + \lambda|B|)|u|`: the matrix-vector products sum
#: tens of terms per row, each rounded, with margin.
RESIDUAL_ROUNDING = 100.0
#: A line search accepts a barrier objective that rises by at most this fraction of its
#: value (the objective's own rounding: a sum over the zone's nodes of logarithms).
MERIT_RTOL = 1e-10
#: The interior point bounds a step's change of the load by a multiple of the load
#: divided by the predicted change, never by less than this (no division by zero).
DIVISION_FLOOR = 1e-300
#: A Krylov vector whose metric norm falls below this fraction of its norm before the
#: orthogonalisation is rounding only: the space is exhausted.
EXHAUSTED_NORM = 1e-20

# -- the certificate ---------------------------------------------------------------------

#: The certificate's verified relative gap (upper - lower) / upper at most this proves the
#: global optimum: the copositivity bounds are tried down to 1e-9 below the load, so 1e-6
#: is reached whenever the pencil's gap allows and is far below any engineering use.
PROOF_GAP = 1e-6
#: A verified relative gap at most this is reported as "bracketed" (the load is known to
#: that accuracy, 0.1 %); above it the result is a KKT point only.
BRACKET_GAP = 1e-3
#: The smallest-eigenvalue check looks below lambda (1 - SMALLEST_RTOL_FACTOR eps_tol):
#: a thousand eigen tolerances keep the computed load itself out of the count.
SMALLEST_RTOL_FACTOR = 1e3
#: The smallest-eigenvalue check refuses a free load that double precision fixes more
#: loosely than this (its ``load_resolution``, relative): below the load by less than the
#: rounding, the inertia count says nothing, and its margin widened to the rounding would
#: prove the load the smallest only more loosely than the bracket the certificate still
#: calls "bracketed". Below it the margin is widened to twice the resolution (the computed
#: load and the factorised pencil are each off by up to one).
FREE_CHECK_RESOLUTION = BRACKET_GAP

# -- the problem's set-up ---------------------------------------------------------------

#: A geometric stiffness B whose largest row sum is at most this fraction of the largest
#: membrane force |N0| is round-off: B's entries are of the order of |N0| (a Q1 stiffness
#: integral is O(1)), and a sum of such terms that cancels leaves some 1e-16 of it.
NULL_GEOMETRIC_STIFFNESS = 1e-10

# -- geometry and the nonlinear path ----------------------------------------------------

#: Points whose coordinates agree within this fraction of the plate's size are one point
#: (mesh nodes, mirror images, section rows): coordinates from gmsh and from arithmetic on
#: the corners differ by rounding, some 1e-15 relative, and mesh cells are far above 1e-9.
GEOMETRY_RTOL = 1e-9
#: SNES absolute tolerance of the von Kármán path, relative to the load vector at the
#: reference load: the residual of a converged state in double precision, with margin.
NONLINEAR_ATOL = 1e-11
#: A load read off the nonlinear path (Southwell, inflection) agrees with a linear load
#: within this: the knee of the imperfect plate lies within O(delta) of the critical load
#: (the paper's plate's distances: docs/methods/nonlinear.md); 1 % leaves a margin for
#: other plates and larger imperfections and still refuses a load that is another
#: buckling load (the next mode, the free load beside the unilateral one).
KNEE_RTOL = 1e-2
