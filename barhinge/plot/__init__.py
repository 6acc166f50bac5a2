"""Pictures: 3-D renders (pyvista, off-screen; ``render``), charts (matplotlib; ``charts``),
crease-pattern drawings (``pattern``) and DOF pictures (``dof``).

Nothing here is imported by ``import barhinge``; rendering libraries load on first use.
The standard pictures of a run are written by :func:`barhinge.output.pictures.write_pictures`.
"""
