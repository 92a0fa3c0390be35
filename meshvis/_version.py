"""The version of meshvis, in one place (imported by the package and by reports)."""

__version__ = "0.1.0"
