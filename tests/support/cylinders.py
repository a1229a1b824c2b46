r"""An independent reference for a cylinder under axial load (numpy and scipy only).

The classical critical stress of a simply supported cylinder (w = v = 0,
:math:`N_x = M_x = 0` at the ends) in m axial half-waves and n circumferential waves,
:math:`u = A\cos\alpha x\cos n\theta`, :math:`v = B\sin\alpha x\sin n\theta`,
:math:`w = C\sin\alpha x\cos n\theta`, :math:`\alpha = m\pi/L`, minimised over
(m, n): the 3 × 3 characteristic determinant of the strain energy of Sanders'
first-order shell theory (J. L. Sanders, NASA TR R-24, 1959; Brush & Almroth, *Buckling
of Bars, Plates and Shells*, 1975, chapter 5), w outward:
:math:`\varepsilon_x = u_x`, :math:`\varepsilon_\theta = (v_\theta + w)/R`,
:math:`\gamma = u_\theta/R + v_x`, :math:`\kappa_x = -w_{xx}`,
:math:`\kappa_\theta = (v_\theta - w_{\theta\theta})/R^2`,
:math:`2\kappa_{x\theta} = (-2w_{x\theta} + \tfrac32 v_x - \tfrac12 u_\theta/R)/R`
(zero on the six rigid motions), against the axial stress's work
:math:`\sigma t\,(u_x^2 + v_x^2 + w_x^2)/2`, the full Green-Lagrange term (Sanders'
moderate-rotation term :math:`w_x^2 + \varphi^2`, :math:`\varphi = (v_x - u_\theta/R)/2`,
gives 0.8 to 2 % more on modes of 2 to 7 waves at R/t = 50 to 100; Flügge's
:math:`v_x^2 + w_x^2` lies between). With ``donnell``: Donnell's shallow-shell
curvatures (no v) and load term :math:`w_x^2`, whose minimum is the classical
:math:`E t/(R\sqrt{3(1-\nu^2)})`. Each strain is one trigonometric term, so the
energy is a quadratic form in (A, B, C) and the load its generalised eigenvalue.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg


def sanders_stress(
    R: float, T: float, length: float, E: float, NU: float, *, donnell: bool = False,
    modes: int = 60,
) -> tuple[float, int]:  # fmt: skip
    """The critical stress (Pa) and its n, minimised over m < ``modes``, n < ``modes``/2.

    R: mid-surface radius (m); T: thickness (m); length between the simply supported
    ends (m); E (Pa), NU. ``donnell``: Donnell's strains and load term instead.
    """
    C, D = E * T / (1.0 - NU**2), E * T**3 / (12.0 * (1.0 - NU**2))
    best = (math.inf, -1)
    for m in range(1, modes):
        a = m * math.pi / length
        for n in range(modes // 2):
            # Coefficients of (A, B, C) in each strain's one trigonometric term.
            ex, et, g = np.array([-a, 0, 0]), np.array([0, n / R, 1 / R]), np.array([-n / R, a, 0])
            kx = np.array([0, 0, a * a])
            if donnell:
                kt, tw = np.array([0, 0, n * n / R**2]), np.array([0, 0, 2 * a * n / R])
            else:
                kt = np.array([0, n / R**2, n * n / R**2])
                tw = np.array([0.5 * n / R**2, 1.5 * a / R, 2 * a * n / R])
            membrane = np.outer(ex, ex) + np.outer(et, et) + (1 - NU) / 2 * np.outer(g, g)
            bending = np.outer(kx, kx) + np.outer(kt, kt) + (1 - NU) / 2 * np.outer(tw, tw)
            K = C * (membrane + NU * (np.outer(ex, et) + np.outer(et, ex)))
            K += D * (bending + NU * (np.outer(kx, kt) + np.outer(kt, kx)))
            G = T * a * a * (np.diag([0.0, 0.0, 1.0]) if donnell else np.eye(3))
            w = scipy.linalg.eigvals(K, G)
            w = w[np.isfinite(w)].real
            w = w[w > 0]
            if w.size and w.min() < best[0]:
                best = (float(w.min()), n)
    return best
