"""Vectorised element kernels: geometry (bars, hinge fold angles with exact derivatives),
constitutive laws, and a slow per-element reference used by the tests."""
