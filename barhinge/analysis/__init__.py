"""Analyses of fold paths: stiffness (tangent, effective, modes), Poisson's ratios, and
Gaussian curvature (global form and angle defect).

Import the submodules directly (``barhinge.analysis.curvature`` ...); the public functions
are also re-exported lazily from :mod:`barhinge` (``bh.gaussian_curvature``,
``bh.tangent_stiffness``).
"""
