"""The package version: one ground module every layer reads (never the package face)."""

__version__ = "0.1.0"
