"""The version of barhinge (imported by the package and by the result-folder manifest)."""

__version__ = "0.1.0"
