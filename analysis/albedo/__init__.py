"""Directional and hemispherical albedo of any BRDF, with an honest error estimate.

The directional albedo for a fixed viewing direction wo is

    rho(wo) = integral over the upper hemisphere of f_r(wi, wo) cos(theta_i) dwi,

the radiance seen from wo when the surface sits in a uniform white environment of unit
radiance (the *white furnace*). With the roles swapped (``swap=True``) it is

    rho'(wi) = integral of f_r(wi, wo) cos(theta_o) dwo,

the fraction of the energy arriving from wi that leaves the surface: energy conservation in
the strict sense is rho'(wi) <= 1. For a reciprocal BRDF the two are equal.

Two quadratures are used.

* ``"threads"`` (used when the BRDF has ``eval_threads``, e.g. a microcylinder fabric):
  each thread's share of f_r is integrated separately in that thread's own coordinates. For
  a thread with in-plane tangent t0 and b = n x t0, a direction is written
  w = cos(beta) b + sin(beta) (cos(chi) n + sin(chi) t0), beta in [0, pi] the angle from
  b, chi in [-pi/2, pi/2] the angle about b measured from n toward t0; the upper hemisphere is
  exactly that rectangle and dw = sin(beta) dbeta dchi. Every tangent sample of the thread
  lies in the (t0, n) plane, so its azimuth psi equals chi + alpha, its masking and
  reweighting kinks sit on lines of constant chi, and its specular cone runs along lines of
  nearly constant chi: a product rule (composite Gauss-Legendre in both angles) resolves
  the narrow lobes (gamma_s = 2.5 degrees) with a few thousand points. Summing the thread
  integrals is exact, since the integral of a sum is the sum of the integrals.
* ``"sphere"`` (any BRDF): composite Gauss-Legendre in mu = cos(theta) on [0, 1] times the
  trapezoid rule in phi (periodic, hence spectrally accurate for smooth integrands). It is
  exact for a Lambertian BRDF at every resolution.

Error estimate: the rule is evaluated at two resolutions, the finer having twice as many
panels along each angle; ``value`` is the finer result and ``error`` the absolute
difference |fine - coarse|, which for a convergent rule bounds the error of the finer one
(the coarse error is larger by a factor of 4 or more for the kinks of the masking terms,
much more on smooth parts). Resolution doubles until ``error <= tol`` or ``max_level``.
Alternatively ``method="rqmc"`` averages independent Owen-scrambled Sobol estimates
(scipy.stats.qmc) over the same parametrisations and reports the half-width of a 99 %
Student-t interval.

Modules: :mod:`~analysis.albedo.results` (the result classes), :mod:`~analysis.albedo.quadrature`
(the rules and their weighted sums of f_r), :mod:`~analysis.albedo.directional` (:func:`albedo`,
refined per direction), :mod:`~analysis.albedo.sweep` (:func:`albedo_curve`,
:func:`albedo_hemispherical` and :func:`run_tasks`, in parallel processes).
"""

from analysis.albedo.directional import albedo
from analysis.albedo.quadrature import thread_axes
from analysis.albedo.results import AlbedoCurve, AlbedoResult, HemisphericalAlbedo
from analysis.albedo.sweep import albedo_curve, albedo_hemispherical, run_tasks

__all__ = [
    "AlbedoResult",
    "AlbedoCurve",
    "HemisphericalAlbedo",
    "albedo",
    "albedo_curve",
    "albedo_hemispherical",
    "thread_axes",
    "run_tasks",
]
